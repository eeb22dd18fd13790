// The double-precision statics solvers (equations and methods: statics.h): AAS, refined
// AAS and exact, the continuation from the home pose that exact falls back on where its
// start fails, and the checks every solution passes before it is ok (docs/model.md,
// "Checking every solution"):
//   end conditions   g_i = (L, Z)(Fl_i, Fz_i, s0_i) - (L_i, Z_i)   (eqs. 14-16, m)
//   error estimate   the Newton step they imply: per cable the Fz miss at its Fl,
//                    d_i = -(n . g_i)/(n . dg/dFz) (ds0 eliminated by n), moved through the
//                    equilibrium, M dFl = -(0, 0, sum d, sum r_y d, sum r_x d, 0), with M
//                    the last 6x6 matrix (statics.h), dFz_i = a_i dFl_i + d_i; the estimate is
//                    max_i |dT_i| / T_i, dT = (Fl dFl + Fz dFz)/T (first order in the error;
//                    for aas, d_i is exactly its Fz minus the curve's at its Fl)
//   equilibrium      sum(-F_i) + W and sum r_i x (-F_i) + e x W of the returned forces
//   model range      strain, s0/k, and each cable's clearance from the reflector.
#include "fastcal/statics.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include "fastcal/internal/forward_statics.h"

namespace fastcal {
namespace {

using internal::CableLinearisation;
using internal::CableState;
using internal::EquilibriumResponse;
using internal::HomePose;
using Geometry = internal::PoseGeometry<double>;
using State = std::array<CableState<double>, kNumCables>;

// Equilibrium residuals above this fraction of the largest force (N), or of it times the
// largest lever arm (N m), mean the 6x6 solve failed: it meets them to rounding, ~1e-14.
constexpr double kMaxRelativeEquilibriumResidual = 1e-9;
// Whether the error estimate after a Newton step of relative size `step` can be trusted:
// it uses the partials from before the step (CheckAfterStep), so only after a small step
// (after larger ones, where a cable sags, it was measured 100 times too small), and only
// while Newton is seen to converge, the error left a tenth of the step or less (or at the
// rounding floor): aas-refined can stall near a fold of the equations with a small step
// and a small residual 27% from the solution, where its steps then diverge.
bool Contracting(double step, double estimate) {
  constexpr double kTrustedStep = 1e-2;
  constexpr double kMaxContraction = 0.1;
  constexpr double kRoundingFloor = 1e-12;
  return step <= kTrustedStep && (estimate <= kMaxContraction * step || estimate <= kRoundingFloor);
}
// A point of exact's continuation counts as solved once its Newton step is below this
// fraction of the forces: it only starts the next point (the last one is then polished to
// exact_relative_tolerance), and at 1e-6 the next point's start is as good as exact.
constexpr double kPathPointTolerance = 1e-6;
// Newton iterations per path point before the step along the path is halved: from the
// previous point extrapolated, a point 1/8 of the way on takes 2-3 where the path is easy.
constexpr int kPathPointIterations = 6;
// The continuation's first step, as a fraction of the path; successful steps double.
constexpr double kFirstPathStep = 0.5;
// A step along the path halved below this fraction means the equilibrium ends before the
// pose (a fold of the solution path, or a cable's Fl reaching 0): no equilibrium. Over
// the seeded 10,000-pose sweep (tests/statics_test.cc) no pose that has an in-range
// equilibrium needed steps below 1e-2.
constexpr double kMinPathStep = 1e-3;

bool ParametersUsable(const StaticsParameters<double>& p) {
  for (int i = 0; i < kNumCables; ++i) {
    if (!p.tower_top_m[i].allFinite() || !p.anchor_cabin_m[i].allFinite()) return false;
    if (!(p.ea_n[i] > 0.0) || !std::isfinite(p.ea_n[i])) return false;
    if (!(p.linear_density_kg_per_m[i] > 0.0) || !std::isfinite(p.linear_density_kg_per_m[i])) {
      return false;
    }
    for (int j = 0; j < p.chain[i].num_attachments; ++j) {
      if (!(p.chain[i].value[j] >= 0.0) || !std::isfinite(p.chain[i].value[j])) return false;
    }
    for (int k = 0; k < p.chain[i].num_cuts; ++k) {
      if (!(p.chain[i].cuts[k].s_m >= 0.0) || !std::isfinite(p.chain[i].cuts[k].s_m)) return false;
    }
  }
  return p.cabin_mass_kg > 0.0 && std::isfinite(p.cabin_mass_kg) &&
         p.mass_centre_cabin_m.allFinite() && p.gravity_m_per_s2 < 0.0 &&
         std::isfinite(p.gravity_m_per_s2);
}

// What the checks found at a solution, with its end tensions (T0, T1 of eqs. 6, computed
// by the same evaluation).
struct Check {
  std::array<double, kNumCables> end_residual_m{}, lower_n{}, upper_n{};
  double error_estimate = 0.0;
};

// Evaluates every cable's end point at `st` (values only): the end residuals and tensions
// into *check and, through `lin` (the linearisation of the last step, whose partials are
// good to first order here), each cable's Fz miss through its normal n,
// d = -(n . g)/(n . dg/dFz), into *miss.
void EvaluateEnds(const StaticsParameters<double>& p, const Geometry& g, const State& st,
                  const CableLinearisation<double>& lin, std::array<double, kNumCables>* miss,
                  Check* check) {
  for (int i = 0; i < kNumCables; ++i) {
    const CatenaryEnd<double> e =
        internal::CableEndpoint(p, i, st[i].fl, st[i].fz, st[i].s0, g.w[i]);
    const double g0 = e.span_m - g.span[i], g1 = e.rise_m - g.rise[i];
    check->end_residual_m[i] = std::sqrt(g0 * g0 + g1 * g1);
    check->lower_n[i] = e.lower_tension_n;
    check->upper_n[i] = e.upper_tension_n;
    const CatenaryEnd<double>& d = lin.ends[i];
    (*miss)[i] = -(d.drise[2] * g0 - d.dspan[2] * g1) * lin.inv_qq[i];
  }
}

// max_i |dT_i| / T_i for the correction of each cable's Fz by `miss` at its Fl, moved
// through the equilibrium with `response` (the file comment's error estimate).
double EstimateError(const Geometry& g, const State& st,
                     const std::array<double, kNumCables>& slope,
                     const std::array<double, kNumCables>& miss,
                     const EquilibriumResponse& response) {
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();  // rows 2, 3, 4
  for (int i = 0; i < kNumCables; ++i) {
    rhs[0] -= miss[i];
    rhs[1] -= g.r[i][1] * miss[i];
    rhs[2] -= g.r[i][0] * miss[i];
  }
  const Eigen::Matrix<double, 6, 1> dfl = g.null_basis * (response * rhs);
  // The largest |T dT| / T^2, compared as fractions: one division instead of six.
  double worst_num = 0.0, worst_den = 1.0;
  for (int i = 0; i < kNumCables; ++i) {
    const double dfz = slope[i] * dfl[i] + miss[i];
    const double num = std::abs(st[i].fl * dfl[i] + st[i].fz * dfz);
    const double den = st[i].fl * st[i].fl + st[i].fz * st[i].fz;
    if (!(num * worst_den <= worst_num * den)) {  // NaN propagates as the worst
      worst_num = num;
      worst_den = den;
    }
  }
  return worst_num / worst_den;
}

// The checks at `st` after a step from the linearisation `lin` whose equilibrium system
// had `response` (EvaluateEnds, then the error estimate).
Check CheckAfterStep(const StaticsParameters<double>& p, const Geometry& g, const State& st,
                     const CableLinearisation<double>& lin, const EquilibriumResponse& response) {
  Check c;
  std::array<double, kNumCables> miss;
  EvaluateEnds(p, g, st, lin, &miss, &c);
  c.error_estimate = EstimateError(g, st, lin.a, miss, response);
  return c;
}

// What a warm start takes from the solution before (StaticsOptions::warm_start): only
// this is copied, not the whole StaticsSolution, which the solve then overwrites.
struct PreviousSolve {
  std::array<CatenaryForces, kNumCables> low, high;     // AAS secants
  std::array<std::array<double, 3>, kNumCables> state;  // each cable's (Fl, Fz, s0)
  Pose pose;
  // Whether low and high were solved at `pose` by aas or aas-refined (StaticsSolution:
  // exact's carry older secants, or its AAS start's loose ones).
  bool secants_at_pose = false;
  // For the extrapolation along the path (PathFactor): the solve before that one.
  bool has_previous = false;
  Pose previous_pose;
  std::array<std::array<double, 3>, kNumCables> previous_state;
  std::array<CatenaryForces, kNumCables> previous_low, previous_high;

  explicit PreviousSolve(const StaticsSolution& s)
      : pose(s.pose),
        secants_at_pose(s.method != StaticsMethod::kExact),
        has_previous(s.has_previous),
        previous_pose(s.previous_pose),
        previous_state(s.previous_state),
        previous_low(s.previous_secant_low),
        previous_high(s.previous_secant_high) {
    for (int i = 0; i < kNumCables; ++i) {
      const CableSolution& c = s.cables[i];
      low[i] = c.secant_low;
      high[i] = c.secant_high;
      state[i] = {c.horizontal_force_n, c.force_n[2], c.unstretched_length_m};
    }
  }
};

// Which equilibrium (docs/model.md, "Which equilibrium exact returns"). Where cables sag,
// several equilibria can hold one pose. In the reduced unknowns c (Fl = N c, N the null
// basis of the rows without Fz, PoseGeometry) the equilibrium is G(c) = 0 in three
// equations whose Jacobian J(a) = V(a) N depends on the state only through each cable's
// tangent slope a_i = dFz/dFl along its family of lengths, affinely and by rank one:
//   J(a) = J_t + sum_i (a_i - a_t,i) u_i n_i^T,   u_i = (1, r_y,i, r_x,i),  n_i = row i of N,
// with J_t = J(a_t) the straight cables' (a_t,i = -Z_i/L_i: the force along the chord).
// J(a) = J_t (I + E) is nonsingular, det J(a) of J_t's sign, wherever
//   sum_i |a_i - a_t,i| kappa_i < 1,   kappa_i = |J_t^-1 u_i|_inf |n_i|_1   (|E|_inf <= it).
// The taut-cable certificate of an equilibrium X is that sum at X. Two equilibria X, Y
// with certificates below 1/2 are one: on the convex set {c : Fl_i >= min(Fl_i(X),
// Fl_i(Y))} each |a_i - a_t,i| is at most its larger value at X or Y (it grows as a cable
// slackens: measured over FAST's chords, 2 to 60 kg/m, except for a wiggle where a cable
// is stretched nearly straight, below 0.003 of slope at 11.7 kg/m), so the sum stays
// below 1 there, and G, whose every average Jacobian along a segment there is then
// nonsingular, takes no value twice. So at most one equilibrium is certified
// (kCertified), whatever the start found it: the taut-cable equilibrium. Elsewhere the
// sign of det J(a) against det J_t tells the two sides of a fold apart: the continuation
// keeps it.
constexpr double kCertified = 0.5;
struct TautReference {
  Eigen::Matrix3d j_t;                   // J(a_t)
  std::array<double, kNumCables> slope;  // a_t
  std::array<double, kNumCables> kappa;  // |J_t^-1 u_i|_inf |n_i|_1; +inf when J_t is singular
  double det_t;                          // det J_t
};

// J(a) = V(a) N for slopes a (SolveEquilibriumReduced's 3x3 matrix).
Eigen::Matrix3d ReducedJacobian(const Geometry& g, const std::array<double, kNumCables>& a) {
  Eigen::Matrix3d j = Eigen::Matrix3d::Zero();
  for (int i = 0; i < kNumCables; ++i) {
    const Eigen::Vector3d& r = g.r[i];
    const Eigen::Vector3d v(a[i], r[1] * a[i] + r[2] * g.uy[i], r[0] * a[i] + r[2] * g.ux[i]);
    j += v * g.null_basis.row(i);
  }
  return j;
}

TautReference MakeTautReference(const Geometry& g) {
  TautReference t;
  for (int i = 0; i < kNumCables; ++i) t.slope[i] = -g.rise[i] / g.span[i];
  t.j_t = ReducedJacobian(g, t.slope);
  const internal::Adjugate3 adj(t.j_t);
  t.det_t = adj.det;
  const bool usable = adj.ConditionedBetterThan(internal::kMinEquilibriumReciprocalCondition);
  const double inv_det = 1.0 / std::abs(adj.det);
  for (int i = 0; i < kNumCables; ++i) {
    const Eigen::Vector3d y = adj.adjugate * Eigen::Vector3d(1.0, g.r[i][1], g.r[i][0]);
    t.kappa[i] = usable ? y.cwiseAbs().maxCoeff() * inv_det * g.null_basis.row(i).cwiseAbs().sum()
                        : std::numeric_limits<double>::infinity();
  }
  return t;
}

// A converged state's tangents: each cable's slope a_i and the inverse of J(a), the last
// Newton step's equilibrium response (the same linearisation).
struct Tangent {
  std::array<double, kNumCables> slope;
  EquilibriumResponse response;
};

// The taut-cable certificate of a converged state (kCertified), or an upper bound of it.
// First the bound from J(a)^-1, which the last step computed: with
// eps = sum_i |a_i - a_t,i| |J(a)^-1 u_i|_inf |n_i|_1 < 1,
// J_t^-1 = (I - J(a)^-1 sum_i (a_i - a_t,i) u_i n_i^T)^-1 J(a)^-1 bounds kappa_i by
// kappa'_i / (1 - eps), so the certificate is at most eps / (1 - eps): certified for
// eps < 1/3 (on FAST's workspace eps ~ 0.005). Otherwise J_t itself.
double TautCertificate(const Geometry& g, const Tangent& t) {
  constexpr double kBoundEnough = kCertified / (1.0 + kCertified);
  std::array<double, kNumCables> deviation;
  double eps = 0.0;
  for (int i = 0; i < kNumCables; ++i) {
    deviation[i] = std::abs(t.slope[i] + g.rise[i] / g.span[i]);
    const Eigen::Vector3d y = t.response * Eigen::Vector3d(1.0, g.r[i][1], g.r[i][0]);
    eps += deviation[i] * y.cwiseAbs().maxCoeff() * g.null_basis.row(i).cwiseAbs().sum();
  }
  if (eps < kBoundEnough) return eps / (1.0 - eps);
  const TautReference taut = MakeTautReference(g);
  double sum = 0.0;
  for (int i = 0; i < kNumCables; ++i) sum += deviation[i] * taut.kappa[i];
  return sum;
}

// Whether slopes `a` lie on the straight cables' side of every fold: det J(a) has J_t's sign.
bool OnTautSide(const Geometry& g, const TautReference& t,
                const std::array<double, kNumCables>& a) {
  return internal::Adjugate3(ReducedJacobian(g, a)).det * t.det_t > 0.0;
}

// Shared by the stages of one solve.
struct Context {
  const StaticsParameters<double>& p;
  const StaticsOptions& o;
  StaticsSolution* sol;
  std::array<CatenaryForces, kNumCables> low{}, high{};  // AAS secants (warm starts)
};

// AAS at the pose of `g`: the secant lines, the 6x6 solve (its response kept), Fl and Fz on
// the lines; *slope receives the lines' slopes. kNoEquilibrium (cable set) when AAS gives
// a cable Fl <= 0: AAS then says nothing about the pose.
StaticsStatus AasStart(Context* c, const Geometry& g, bool use_guess, State* st,
                       std::array<double, kNumCables>* slope, EquilibriumResponse* response,
                       double (*secant_jacobians)[4] = nullptr) {
  std::array<double, kNumCables> b, fl;
  int* cable = &c->sol->cable;
  const StaticsStatus status =
      internal::AasLines(c->p, g, c->o, use_guess, &c->low, &c->high, slope, &b, cable,
                         &c->sol->catenary_iterations, secant_jacobians);
  if (status != StaticsStatus::kOk) return status;
  // Cables with attachments (exact's start only: aas refuses them): the uniform cable's
  // line, moved by the share of the attachments' weight its lower end carries.
  for (int i = 0; i < kNumCables; ++i) {
    if (!c->p.chain[i].empty()) {
      b[i] += CatenaryChainLowerShareN(c->p.chain[i], g.chord[i], c->p.gravity_m_per_s2);
    }
  }
  const bool solved = response != nullptr
                          ? internal::SolveEquilibrium<double, true>(g, *slope, b, &fl, response)
                          : internal::SolveEquilibrium(g, *slope, b, &fl);
  if (!solved) return StaticsStatus::kSingular;
  for (int i = 0; i < kNumCables; ++i) {
    if (!(fl[i] > 0.0)) {
      *cable = i;
      return StaticsStatus::kNoEquilibrium;
    }
    (*st)[i] = {fl[i], (*slope)[i] * fl[i] + b[i], 0.0};
  }
  return StaticsStatus::kOk;
}

// Each cable on its Fz(Fl) curve at its Fl: *projected gets Fz and s0. The start is the
// secant data's model-corrected CurveGuess, or with `from_state` the state's own Fz and s0.
// `jacobians` (may be null): each solve's last d(L, Z)/d(Fz, s0) (ProjectOnCurves).
StaticsStatus Project(Context* c, const Geometry& g, const State& st, bool from_state,
                      State* projected, double (*jacobians)[4] = nullptr) {
  std::array<CatenaryCurvePoint, kNumCables> guess;
  for (int i = 0; i < kNumCables; ++i) {
    guess[i] = from_state ? CatenaryCurvePoint{st[i].fz, st[i].s0}
                          : internal::CurveGuess(st[i].fl, g, i, c->p.ea_n[i], c->low[i],
                                                 c->high[i], c->o, /*model_corrected=*/true);
  }
  *projected = st;
  return internal::ProjectOnCurves(c->p, g, internal::AasLengthStageOptions(c->o), guess, projected,
                                   &c->sol->cable, &c->sol->catenary_iterations, jacobians);
}

// exact's start at the pose of `g`: AAS's Fl and each cable's Fz and s0 from the secant
// data's model-corrected guess of its curve point there (internal::CurveGuess, ~1e-5
// off), as good as solving for the point, since the AAS Fl is itself ~1e-3 off.
StaticsStatus ExactStart(Context* c, const Geometry& g, State* st) {
  std::array<double, kNumCables> slope;
  const StaticsStatus status = AasStart(c, g, /*use_guess=*/false, st, &slope, nullptr);
  if (status != StaticsStatus::kOk) return status;
  for (int i = 0; i < kNumCables; ++i) {
    const CatenaryCurvePoint guess =
        internal::CurveGuess((*st)[i].fl, g, i, c->p.ea_n[i], c->low[i], c->high[i], c->o, true);
    // A cable with attachments: the uniform cable's point, Fz moved as in AasStart.
    (*st)[i].fz =
        guess.fz_n + (c->p.chain[i].empty() ? 0.0
                                            : CatenaryChainLowerShareN(c->p.chain[i], g.chord[i],
                                                                       c->p.gravity_m_per_s2));
    (*st)[i].s0 = guess.s0_m;
  }
  return StaticsStatus::kOk;
}

// aas's curve points: each cable's curve point at its AAS Fl, solved (one Newton step from
// the model-corrected guess): s0 into *st and the Fz miss d, the curve's Fz minus AAS's,
// into *miss. At the same Fl and s0 AAS's end point misses the tower by d(L, Z)/dFz d, to
// first order (the second order is d/T, below 1% of it where aas is ok): the end
// residual without another evaluation.
StaticsStatus AasCurvePointsSolved(Context* c, const Geometry& g, State* st,
                                   std::array<double, kNumCables>* miss, Check* check) {
  State projected;
  double jacobians[kNumCables][4] = {};  // written where the solves are ok
  const StaticsStatus status = Project(c, g, *st, /*from_state=*/false, &projected, jacobians);
  if (status != StaticsStatus::kOk) return status;
  for (int i = 0; i < kNumCables; ++i) {
    (*st)[i].s0 = projected[i].s0;
    (*miss)[i] = projected[i].fz - (*st)[i].fz;
    const double* j = jacobians[i];  // rows: span, rise; columns: Fz, s0
    check->end_residual_m[i] = std::abs((*miss)[i]) * std::sqrt(j[0] * j[0] + j[2] * j[2]);
  }
  return StaticsStatus::kOk;
}

// The same for forces only (StaticsOptions::compute_unstretched_lengths off), without a
// catenary evaluation: the curve point is the model-corrected guess, and d(L, Z)/dFz is
// interpolated in Fl between the secant solves' (columns Fz of `secant_jacobians`), as
// the guess is.
void AasCurvePointsGuessed(Context* c, const Geometry& g, const double (*secant_jacobians)[4],
                           State* st, std::array<double, kNumCables>* miss, Check* check) {
  for (int i = 0; i < kNumCables; ++i) {
    CableState<double>& x = (*st)[i];
    const CatenaryForces &low = c->low[i], &high = c->high[i];
    const CatenaryCurvePoint guess =
        internal::CurveGuess(x.fl, g, i, c->p.ea_n[i], low, high, c->o, /*model_corrected=*/true);
    x.s0 = guess.s0_m;
    (*miss)[i] = guess.fz_n - x.fz;
    const double t = (x.fl - low.fl_n) / (high.fl_n - low.fl_n);
    const double* jl = secant_jacobians[i];  // rows: span, rise; columns: Fl, Fz
    const double* jh = secant_jacobians[i + kNumCables];
    const double dspan = jl[1] + t * (jh[1] - jl[1]), drise = jl[3] + t * (jh[3] - jl[3]);
    check->end_residual_m[i] = std::abs((*miss)[i]) * std::sqrt(dspan * dspan + drise * drise);
  }
}

// The paper's AAS, with s0 from the curves at its Fl and the checks (the curve points
// above, the tensions, the error estimate through AAS's own equilibrium response).
StaticsStatus SolveAas(Context* c, const Geometry& g, bool warm, State* st, Check* check) {
  const bool solve_points = c->o.compute_unstretched_lengths;
  std::array<double, kNumCables> slope;
  EquilibriumResponse response;
  double secant_jacobians[2 * kNumCables][4] = {};  // written where the solves are ok
  StaticsStatus status =
      AasStart(c, g, warm, st, &slope, &response, solve_points ? nullptr : secant_jacobians);
  if (status == StaticsStatus::kNoEquilibrium) return StaticsStatus::kInaccurate;
  if (status != StaticsStatus::kOk) return status;
  std::array<double, kNumCables> miss;
  if (solve_points) {
    status = AasCurvePointsSolved(c, g, st, &miss, check);
    if (status != StaticsStatus::kOk) return status;
  } else {
    AasCurvePointsGuessed(c, g, secant_jacobians, st, &miss, check);
  }
  for (int i = 0; i < kNumCables; ++i) {
    const CableState<double>& x = (*st)[i];
    check->lower_n[i] = std::sqrt(x.fl * x.fl + x.fz * x.fz);
    check->upper_n[i] = CatenaryTension(x.fl, x.fz, x.s0, g.w[i]);
  }
  check->error_estimate = EstimateError(g, *st, slope, miss, response);
  if (!(check->error_estimate <= c->o.aas_max_relative_error)) {
    c->sol->limit_value = check->error_estimate;
    c->sol->limit = c->o.aas_max_relative_error;
    return StaticsStatus::kInaccurate;
  }
  return StaticsStatus::kOk;
}

// AAS, then steps (each: onto the curves, tangent step, checks) until the error estimate
// is below refined_relative_tolerance.
StaticsStatus SolveAasRefined(Context* c, const Geometry& g, bool warm, State* st, Check* check) {
  std::array<double, kNumCables> slope;
  StaticsStatus status = AasStart(c, g, warm, st, &slope, nullptr);
  if (status == StaticsStatus::kNoEquilibrium) return StaticsStatus::kNotConverged;
  if (status != StaticsStatus::kOk) return status;
  for (int step = 0; step < c->o.max_refinement_steps; ++step) {
    status = Project(c, g, *st, /*from_state=*/step > 0, st);
    if (status == StaticsStatus::kNoEquilibrium) return StaticsStatus::kNotConverged;
    if (status != StaticsStatus::kOk) return status;
    CableLinearisation<double> lin;
    internal::LineariseCables(c->p, g, *st, &lin);
    EquilibriumResponse response;
    double relative_step = 0.0;
    status = internal::StepFromLinearisation(g, lin, st, &c->sol->cable, &relative_step, &response);
    ++c->sol->outer_iterations;
    // A step that leaves Fl > 0 or meets a singular system (near a fold, where cables
    // sag): aas-refined cannot go on, which says nothing about the pose.
    if (status == StaticsStatus::kSingular) c->sol->cable = -1;
    if (status == StaticsStatus::kNoEquilibrium || status == StaticsStatus::kSingular) {
      return StaticsStatus::kNotConverged;
    }
    if (status != StaticsStatus::kOk) return status;
    *check = CheckAfterStep(c->p, g, *st, lin, response);
    if (check->error_estimate <= c->o.refined_relative_tolerance &&
        Contracting(relative_step, check->error_estimate)) {
      return StaticsStatus::kOk;
    }
  }
  c->sol->cable = -1;
  c->sol->limit_value = check->error_estimate;
  c->sol->limit = c->o.refined_relative_tolerance;
  return StaticsStatus::kNotConverged;
}

// Newton on the reduced system from *st at the pose of `g`, at most max_steps steps, until
// the error estimate is <= tolerance; then *check holds the checks of *st and *tangent (if
// not null) the last linearisation's slopes and response. Otherwise
// kNotConverged, or a step's failure (kNoEquilibrium: a step left Fl > 0 or s0 > 0;
// kSingular), with *st the last iterate.
StaticsStatus Newton(Context* c, const Geometry& g, int max_steps, double tolerance, State* st,
                     Check* check, Tangent* tangent = nullptr) {
  // Newton's error after a step of relative size d is ~C d^2, C ~ 1 where the cables are
  // taut (0.06-1.2 measured; larger where they sag): the new iterate is checked once d^2
  // is below the tolerance. A check that cannot pass would cost six catenary evaluations
  // for nothing, one that could have passed a step.
  //
  // The check's estimate uses the equilibrium response of the step before it. Computing
  // it costs half a 6x6 solve, so a step computes it only if it may be the last: the
  // first when the start's end residual is below kFirstStepKeepResidual (a start next to
  // the solution: a warm start in a calibration), a later one when the step before it
  // was small enough that this one may pass the check (d_next >= 0.05 d^2 in practice, so
  // d^4 <= 400 tolerance). A check without it solves the step's system again.
  constexpr double kFirstStepKeepResidual = 1e-7;
  constexpr double kSmallestContraction = 5e-2;
  CableLinearisation<double> lin;
  EquilibriumResponse response;
  internal::LineariseCables(c->p, g, *st, &lin);
  double previous_step = std::numeric_limits<double>::infinity();
  for (int step = 0; step < max_steps; ++step) {
    const double predicted = kSmallestContraction * previous_step * previous_step;
    const bool keep = step == 0 ? lin.max_relative_residual <= kFirstStepKeepResidual
                                : predicted * predicted <= tolerance;
    double relative_step = 0.0;
    const StaticsStatus status = internal::StepFromLinearisation(
        g, lin, st, &c->sol->cable, &relative_step, keep ? &response : nullptr);
    ++c->sol->outer_iterations;
    if (status != StaticsStatus::kOk) return status;
    if (relative_step * relative_step <= tolerance) {
      if (!keep) {
        std::array<double, kNumCables> unused;
        internal::SolveEquilibrium<double, true>(g, lin.a, lin.b, &unused, &response);
      }
      *check = CheckAfterStep(c->p, g, *st, lin, response);
      if (check->error_estimate <= tolerance) {
        if (tangent != nullptr) *tangent = {lin.a, response};  // to the step's size
        return StaticsStatus::kOk;
      }
    }
    internal::LineariseCables(c->p, g, *st, &lin);
    previous_step = relative_step;
  }
  return StaticsStatus::kNotConverged;
}

// Whether two converged states are the same equilibrium (both to ~1e-12: 1e-8 of the
// largest horizontal force apart at most).
bool SameEquilibrium(const State& a, const State& b) {
  constexpr double kSameRelative = 1e-8;
  double largest = 0.0, apart = 0.0;
  for (int i = 0; i < kNumCables; ++i) {
    largest = std::max(largest, std::abs(a[i].fl));
    apart = std::max(apart, std::max(std::abs(a[i].fl - b[i].fl), std::abs(a[i].fz - b[i].fz)));
  }
  return apart <= kSameRelative * largest;
}

Pose PoseOnPath(const Pose& from, const Pose& to, double t) {
  Pose p;
  p.position_m = (1.0 - t) * from.position_m + t * to.position_m;
  p.rotation = Eigen::Quaterniond(from.rotation)
                   .slerp(t, Eigen::Quaterniond(to.rotation))
                   .toRotationMatrix();
  return p;
}

// The largest s0/k of a state and its cable.
double LargestLengthRatio(const Geometry& g, const State& st, int* cable) {
  double worst = 0.0;
  for (int i = 0; i < kNumCables; ++i) {
    if (st[i].s0 / g.chord[i] > worst) {
      worst = st[i].s0 / g.chord[i];
      *cable = i;
    }
  }
  return worst;
}

// Newton at one point of the continuation's path, accepted only on the straight cables'
// side of every fold (OnTautSide): when a step of the path jumps a fold, Newton from the
// extrapolated start can land beyond it, on another equilibrium.
bool SolvePathPoint(Context* c, const Geometry& g, int max_steps, State* st) {
  Check check;
  Tangent tangent;
  return Newton(c, g, max_steps, kPathPointTolerance, st, &check, &tangent) == StaticsStatus::kOk &&
         OnTautSide(g, MakeTautReference(g), tangent.slope);
}

// exact's fallback: the equilibrium followed from the home pose to `pose` in steps along
// a straight path (position, and attitude by slerp), each point solved by Newton from
// the previous ones extrapolated (SolvePathPoint: on the home pose's side of every fold);
// a failed step is halved, a good one doubled. kOk with *st solved (to
// kPathPointTolerance) at `pose`; kNoEquilibrium when the steps shrink below kMinPathStep
// (sol->cable: the slackest cable there, limit_value its s0/k); kNotConverged when
// *budget Newton steps run out or the home pose has no solution.
StaticsStatus FollowFromHome(Context* c, const Pose& pose, int* budget, State* st) {
  const Pose home = HomePose(c->p);
  Geometry g;
  int* cable = &c->sol->cable;
  const int start_iterations = c->sol->outer_iterations;
  if (internal::ComputeGeometry(c->p, home, c->o.catenary.vertical_span_fraction, &g, cable) !=
          StaticsStatus::kOk ||
      ExactStart(c, g, st) != StaticsStatus::kOk ||
      !SolvePathPoint(c, g, kPathPointIterations, st)) {
    return StaticsStatus::kNotConverged;
  }
  int used = c->sol->outer_iterations - start_iterations;
  State previous = *st;
  double t = 0.0, t_previous = -1.0, dt = kFirstPathStep;
  while (t < 1.0) {
    if (used >= *budget) {
      c->sol->cable = -1;
      return StaticsStatus::kNotConverged;
    }
    const double t_next = std::min(1.0, t + dt);
    State trial = *st;
    if (t_previous >= 0.0) {
      const double f = (t_next - t) / (t - t_previous);
      for (int i = 0; i < kNumCables; ++i) {
        const CableState<double> x = {(*st)[i].fl + f * ((*st)[i].fl - previous[i].fl),
                                      (*st)[i].fz + f * ((*st)[i].fz - previous[i].fz),
                                      (*st)[i].s0 + f * ((*st)[i].s0 - previous[i].s0)};
        if (x.fl > 0.0 && x.s0 > 0.0) trial[i] = x;
      }
    }
    const int before = c->sol->outer_iterations;
    const bool solved =
        internal::ComputeGeometry(c->p, PoseOnPath(home, pose, t_next),
                                  c->o.catenary.vertical_span_fraction, &g,
                                  cable) == StaticsStatus::kOk &&
        SolvePathPoint(c, g, std::min(kPathPointIterations, *budget - used), &trial);
    used += c->sol->outer_iterations - before;
    if (solved) {
      previous = *st;
      *st = trial;
      t_previous = t;
      t = t_next;
      dt *= 2.0;
    } else if ((dt *= 0.5) < kMinPathStep) {
      internal::ComputeGeometry(c->p, PoseOnPath(home, pose, t),
                                c->o.catenary.vertical_span_fraction, &g, cable);
      c->sol->limit_value = LargestLengthRatio(g, *st, cable);
      *budget -= used;
      return StaticsStatus::kNoEquilibrium;
    }
  }
  *budget -= used;
  return StaticsStatus::kOk;
}

// The clearance of cable i from the reflector: the sphere's radius minus the largest
// distance from its centre of a cable point over the reflector (below the centre, within
// the aperture's circle); negative: the cable passes through it. +infinity without a
// reflector, or for a cable that cannot reach it: one rising from its cabin anchor
// (Fz <= 0) where that lies above the rim's plane stays above the plane, and every point
// over the aperture above the rim's plane is inside the sphere. Others (only cables that
// dip below their anchor, in practice) are sampled at kSamples points, the best refined by
// golden section: eqs. 11-13 give the points. rim2: the rim's radius squared, rim_z: its
// height.
double CableReflectorClearanceM(const StaticsParameters<double>& p, const Geometry& g,
                                const State& st, int i, double rim2, double rim_z) {
  constexpr int kSamples = 32;
  constexpr int kRefinements = 30;  // brackets shrink to 1e-6 of s0 / kSamples
  const Reflector& r = *p.reflector;
  const double anchor_z = p.tower_top_m[i].z() - g.rise[i];
  if (st[i].fz <= 0.0 && anchor_z >= rim_z) return std::numeric_limits<double>::infinity();
  const Eigen::Vector3d anchor =
      p.tower_top_m[i] - Eigen::Vector3d(g.ux[i] * g.span[i], g.uy[i] * g.span[i], g.rise[i]);
  auto distance2 = [&](double s_m) {  // -1 where the point is not over the reflector
    const CatenaryEnd<double> e = internal::CableEndpoint(p, i, st[i].fl, st[i].fz, s_m, g.w[i]);
    const Eigen::Vector3d d =
        anchor + Eigen::Vector3d(g.ux[i] * e.span_m, g.uy[i] * e.span_m, e.rise_m) - r.centre_m;
    return d.z() > 0.0 || d.head<2>().squaredNorm() > rim2 ? -1.0 : d.squaredNorm();
  };
  const double ds = st[i].s0 / kSamples;
  int best = 0;
  double best2 = (anchor - r.centre_m).squaredNorm();
  for (int k = 1; k <= kSamples; ++k) {
    const double d2 = distance2(k * ds);
    if (d2 > best2) {
      best2 = d2;
      best = k;
    }
  }
  const double kGolden = 0.5 * (std::sqrt(5.0) - 1.0);
  double lo = std::max(0.0, (best - 1) * ds), hi = std::min(st[i].s0, (best + 1) * ds);
  for (int it = 0; it < kRefinements; ++it) {
    const double a = hi - kGolden * (hi - lo), b = lo + kGolden * (hi - lo);
    const double da = distance2(a), db = distance2(b);
    best2 = std::max(best2, std::max(da, db));
    if (da > db) {
      hi = b;
    } else {
      lo = a;
    }
  }
  return r.radius_m - std::sqrt(best2);
}

// The smallest clearance from the reflector over the cables (CableReflectorClearanceM).
double ReflectorClearanceM(const StaticsParameters<double>& p, const Geometry& g, const State& st,
                           int* cable) {
  double smallest = std::numeric_limits<double>::infinity();
  if (!p.reflector.has_value()) return smallest;
  const Reflector& r = *p.reflector;
  const double rim2 = 0.25 * r.aperture_m * r.aperture_m;
  const double rim_z = r.centre_m.z() - std::sqrt(r.radius_m * r.radius_m - rim2);
  for (int i = 0; i < kNumCables; ++i) {
    const double clearance_m = CableReflectorClearanceM(p, g, st, i, rim2, rim_z);
    if (clearance_m < smallest) {
      smallest = clearance_m;
      *cable = i;
    }
  }
  return smallest;
}

// The model-range limits of StaticsOptions on a solution, the worst cable of the first
// limit broken, in this order: an attachment that starts beyond its cable's unstretched
// length (kAttachmentBeyondCable, the first such cable), s0 <= 0 or strain over max_strain
// (kOverstretchedCable), s0/k over max_length_ratio (kSaggingCable), a lowest point closer to the
// reflector than min_reflector_clearance_m (kReflectorContact). Writes the smallest clearance
// whatever the outcome.
StaticsStatus CheckModelRange(Context* c, const Geometry& g, const State& st, const Check& check) {
  StaticsSolution* sol = c->sol;
  const StaticsOptions& o = c->o;
  int too_short = -1, stretched = -1, sagging = -1, nearest = -1;
  double strain = 0.0, ratio = 0.0;
  for (int i = 0; i < kNumCables; ++i) {
    // Divisions only where a limit is broken: this runs on every solution.
    const double highest_n = std::max(check.lower_n[i], check.upper_n[i]);
    if (!(st[i].s0 > 0.0)) {
      too_short = i;
    } else if (!(highest_n <= o.max_strain * c->p.ea_n[i]) && highest_n / c->p.ea_n[i] > strain) {
      stretched = i;
      strain = highest_n / c->p.ea_n[i];
    }
    if (st[i].s0 > o.max_length_ratio * g.chord[i] && st[i].s0 / g.chord[i] > ratio) {
      sagging = i;
      ratio = st[i].s0 / g.chord[i];
    }
  }
  sol->reflector_clearance_m = ReflectorClearanceM(c->p, g, st, &nearest);
  for (int i = 0; i < kNumCables; ++i) {
    double start_m = 0.0;
    if (!c->p.chain[i].empty() && st[i].s0 > 0.0 &&
        CatenaryChainBeyond(c->p.chain[i], st[i].s0, &start_m) >= 0) {
      sol->cable = i;
      sol->limit_value = start_m;
      sol->limit = st[i].s0;
      return StaticsStatus::kAttachmentBeyondCable;
    }
  }
  if (too_short >= 0 || stretched >= 0) {
    sol->cable = too_short >= 0 ? too_short : stretched;
    sol->limit_value = too_short >= 0 ? st[too_short].s0 / g.chord[too_short] : strain;
    sol->limit = too_short >= 0 ? 0.0 : o.max_strain;
    return StaticsStatus::kOverstretchedCable;
  }
  if (sagging >= 0) {
    sol->cable = sagging;
    sol->limit_value = ratio;
    sol->limit = o.max_length_ratio;
    return StaticsStatus::kSaggingCable;
  }
  if (sol->reflector_clearance_m < o.min_reflector_clearance_m) {
    sol->cable = nearest;
    sol->limit_value = sol->reflector_clearance_m;
    sol->limit = o.min_reflector_clearance_m;
    return StaticsStatus::kReflectorContact;
  }
  return StaticsStatus::kOk;
}

// Writes a checked solution into *sol; kSingular if its equilibrium residuals show that
// the 6x6 solve failed (kMaxRelativeEquilibriumResidual).
StaticsStatus FillSolution(Context* c, const Geometry& g, const State& st, const Check& check) {
  StaticsSolution* sol = c->sol;
  Eigen::Vector3d force_sum = Eigen::Vector3d::Zero(), moment_sum = Eigen::Vector3d::Zero();
  double force_scale = std::abs(g.weight_n), lever2_m2 = 1.0, end_residual_m = 0.0;
  for (int i = 0; i < kNumCables; ++i) {
    CableSolution& cs = sol->cables[i];
    cs.horizontal_force_n = st[i].fl;
    // The sums below use this local, not cs.force_n read back: a load spanning the
    // stores just made of it cannot be forwarded and stalled each cable (~15 cycles).
    const Eigen::Vector3d force_n(-g.ux[i] * st[i].fl, -g.uy[i] * st[i].fl, st[i].fz);
    cs.force_n = force_n;
    cs.lower_tension_n = check.lower_n[i];
    cs.unstretched_length_m = st[i].s0;
    cs.upper_tension_n = check.upper_n[i];
    cs.chord_length_m = g.chord[i];
    cs.end_residual_m = check.end_residual_m[i];
    cs.secant_low = c->low[i];
    cs.secant_high = c->high[i];
    end_residual_m = std::max(end_residual_m, check.end_residual_m[i]);
    force_sum -= force_n;
    moment_sum -= g.r[i].cross(force_n);
    force_scale = std::max(force_scale, check.lower_n[i]);
    lever2_m2 = std::max(lever2_m2, g.r[i].squaredNorm());
  }
  sol->end_residual_m = end_residual_m;
  const Eigen::Vector3d weight(0.0, 0.0, g.weight_n);
  force_sum += weight;
  moment_sum += g.e.cross(weight);
  sol->force_residual_n = force_sum.norm();
  sol->moment_residual_nm = moment_sum.norm();
  sol->error_estimate = check.error_estimate;
  const double tolerance_n = kMaxRelativeEquilibriumResidual * force_scale;
  if (!(sol->force_residual_n <= tolerance_n) ||
      !(sol->moment_residual_nm <= tolerance_n * std::sqrt(lever2_m2))) {
    return StaticsStatus::kSingular;
  }
  return StaticsStatus::kOk;
}

// A solution that passed the method's checks: the model range, then FillSolution.
StaticsStatus Finish(Context* c, const Geometry& g, const State& st, const Check& check) {
  const StaticsStatus status = CheckModelRange(c, g, st, check);
  if (status != StaticsStatus::kOk) return status;
  return FillSolution(c, g, st, check);
}

// How far apart two poses are, as a vector: the position and the rotation matrix's change
// scaled by the cabin's size (an anchor's move), so that turning counts like moving.
Eigen::Matrix<double, 12, 1> PoseStep(const Pose& from, const Pose& to, double size_m) {
  Eigen::Matrix<double, 12, 1> d;
  d.head<3>() = to.position_m - from.position_m;
  d.tail<9>() = size_m * (to.rotation - from.rotation).reshaped();
  return d;
}

// How far to extrapolate a warm start from the previous solution along the poses' path:
// f with next step = f * last step, when the previous solution was itself warm-started
// and the poses go on in about the same direction; else 0 (start from the previous
// solution as it is).
double PathFactor(const StaticsParameters<double>& p, const PreviousSolve& previous,
                  const Pose& pose) {
  // Accept the extrapolation only while the new step is this close to the last one's line.
  constexpr double kMaxOffLine = 0.5;
  // and stretches it by at most this (a stop and go, or a jump, are no path).
  constexpr double kMaxStretch = 2.0;
  if (!previous.has_previous) return 0.0;
  double size_m = 0.0;
  for (const Eigen::Vector3d& a : p.anchor_cabin_m) size_m = std::max(size_m, a.norm());
  const Eigen::Matrix<double, 12, 1> last = PoseStep(previous.previous_pose, previous.pose, size_m);
  const Eigen::Matrix<double, 12, 1> next = PoseStep(previous.pose, pose, size_m);
  if (!(last.squaredNorm() > 0.0)) return 0.0;
  const double f = next.dot(last) / last.squaredNorm();
  if (!(f > 0.0 && f <= kMaxStretch) || (next - f * last).norm() > kMaxOffLine * next.norm()) {
    return 0.0;
  }
  return f;
}

// The starts of aas's secant solves at `pose`: the previous solution's secants,
// extrapolated along the path as PathFactor says where both it and the one before solved
// theirs at their poses (before.fl_n > 0: StaticsSolution::previous_secant_low), and
// where that keeps Fl > 0.
void WarmSecants(const StaticsParameters<double>& p, const PreviousSolve& previous,
                 const Pose& pose, Context* c) {
  c->low = previous.low;
  c->high = previous.high;
  const double f = previous.secants_at_pose ? PathFactor(p, previous, pose) : 0.0;
  if (!(f > 0.0)) return;
  auto extrapolate = [f](const CatenaryForces& now, const CatenaryForces& before,
                         CatenaryForces* start) {
    if (!(before.fl_n > 0.0)) return;
    const CatenaryForces x{now.fl_n + f * (now.fl_n - before.fl_n),
                           now.fz_n + f * (now.fz_n - before.fz_n)};
    if (x.fl_n > 0.0) *start = x;
  };
  for (int i = 0; i < kNumCables; ++i) {
    extrapolate(previous.low[i], previous.previous_low[i], &c->low[i]);
    extrapolate(previous.high[i], previous.previous_high[i], &c->high[i]);
  }
}

// exact's warm start at `pose` from the previous solution: its state, extrapolated
// linearly along the path (PathFactor).
void WarmStart(const StaticsParameters<double>& p, const PreviousSolve& previous, const Pose& pose,
               State* st) {
  for (int i = 0; i < kNumCables; ++i) {
    const std::array<double, 3>& c = previous.state[i];
    (*st)[i] = {c[0], c[1], c[2]};
  }
  const double f = PathFactor(p, previous, pose);
  if (!(f > 0.0)) return;
  for (int i = 0; i < kNumCables; ++i) {
    const std::array<double, 3>& b = previous.previous_state[i];
    const CableState<double> x = {(*st)[i].fl + f * ((*st)[i].fl - b[0]),
                                  (*st)[i].fz + f * ((*st)[i].fz - b[1]),
                                  (*st)[i].s0 + f * ((*st)[i].s0 - b[2])};
    if (x.fl > 0.0 && x.s0 > 0.0) (*st)[i] = x;
  }
}

// exact: Newton from the previous solution (warm) or from AAS. An equilibrium found there
// is the answer when it is certified taut (TautReference: the only one that taut), its
// model range the status. Otherwise, and where the start fails, the continuation from
// the home pose decides (only when `may_follow`: a warm attempt leaves it to the cold one).
StaticsStatus SolveExact(Context* c, const Geometry& g, const Pose& pose,
                         const PreviousSolve* previous, bool may_follow) {
  const StaticsOptions& o = c->o;
  StaticsSolution* sol = c->sol;
  State st;
  Check check;
  Tangent tangent;
  StaticsStatus status = StaticsStatus::kOk;
  if (previous != nullptr) {
    WarmStart(c->p, *previous, pose, &st);
  } else {
    status = ExactStart(c, g, &st);
  }
  if (status == StaticsStatus::kOk) {
    status =
        Newton(c, g, o.exact_max_iterations, o.exact_relative_tolerance, &st, &check, &tangent);
  }
  const bool converged = status == StaticsStatus::kOk;
  if (converged) {
    // Certified taut (kCertified): the only such equilibrium, the answer whatever the start,
    // and its model range the status.
    sol->taut_certificate = TautCertificate(g, tangent);
    if (sol->taut_certificate < kCertified) {
      sol->branch = EquilibriumBranch::kTaut;
      return Finish(c, g, st, check);
    }
  }
  // A warm start's uncertified equilibrium may be another than the cold solve's: the cold
  // solve (the caller's retry) decides, so that the answer does not depend on the start.
  if (!may_follow) return StaticsStatus::kNotConverged;
  const State direct = st;
  sol->continuation = true;
  sol->cable = -1;
  sol->limit_value = sol->limit = 0.0;
  int budget = o.exact_max_continuation_iterations;
  status = FollowFromHome(c, pose, &budget, &st);
  if (status == StaticsStatus::kOk) {
    status = Newton(c, g, std::min(o.exact_max_iterations, std::max(budget, 1)),
                    o.exact_relative_tolerance, &st, &check, &tangent);
    if (status == StaticsStatus::kOk) {
      sol->taut_certificate = TautCertificate(g, tangent);
      sol->branch = sol->taut_certificate < kCertified ? EquilibriumBranch::kTaut
                                                       : EquilibriumBranch::kFromHome;
      sol->other_equilibrium = converged && !SameEquilibrium(direct, st);
      return Finish(c, g, st, check);
    }
    if (status == StaticsStatus::kNoEquilibrium) status = StaticsStatus::kNotConverged;
  }
  // The home pose's branch does not reach the pose (or the budget ran out), but AAS's
  // start found an equilibrium: one the cabin reaches only through a fold, a jump of the
  // cable lengths. Not the answer; the status says that it exists.
  sol->other_equilibrium = converged;
  return status;
}

StaticsStatus Attempt(const StaticsParameters<double>& p, const Pose& pose, const StaticsOptions& o,
                      const PreviousSolve* previous, bool may_follow, StaticsSolution* sol) {
  // sol->cables is left as it is: FillSolution writes all of it on success, and
  // SolveStaticsWithParameters zeroes it on failure.
  sol->method = o.method;
  sol->cable = -1;
  sol->outer_iterations = 0;
  sol->catenary_iterations = 0;
  sol->continuation = false;
  sol->branch = EquilibriumBranch::kNone;
  sol->taut_certificate = 0.0;
  sol->other_equilibrium = false;
  sol->force_residual_n = 0.0;
  sol->moment_residual_nm = 0.0;
  sol->end_residual_m = 0.0;
  sol->error_estimate = 0.0;
  sol->limit_value = sol->limit = 0.0;
  sol->reflector_clearance_m = std::numeric_limits<double>::infinity();
  if (!IsFinite(pose) || !ParametersUsable(p)) return StaticsStatus::kInvalidInput;

  Geometry g;
  StaticsStatus status =
      internal::ComputeGeometry(p, pose, o.catenary.vertical_span_fraction, &g, &sol->cable);
  if (status != StaticsStatus::kOk) return status;

  if (o.method != StaticsMethod::kExact) {
    for (int i = 0; i < kNumCables; ++i) {
      if (!p.chain[i].empty()) {
        sol->cable = i;
        return StaticsStatus::kUnsupportedModel;
      }
    }
  }

  Context c{p, o, sol};
  if (previous != nullptr) {
    if (o.method == StaticsMethod::kExact) {
      c.low = previous->low;  // only kept: exact's Newton starts from the state
      c.high = previous->high;
    } else {
      WarmSecants(p, *previous, pose, &c);
    }
  }
  if (o.method == StaticsMethod::kExact) return SolveExact(&c, g, pose, previous, may_follow);
  State st;
  Check check;
  status = o.method == StaticsMethod::kAas
               ? SolveAas(&c, g, previous != nullptr, &st, &check)
               : SolveAasRefined(&c, g, previous != nullptr, &st, &check);
  if (status != StaticsStatus::kOk) return status;
  return Finish(&c, g, st, check);
}
}  // namespace

const char* StaticsMethodName(StaticsMethod method) {
  switch (method) {
    case StaticsMethod::kAas:
      return "aas";
    case StaticsMethod::kAasRefined:
      return "aas-refined";
    case StaticsMethod::kExact:
      return "exact";
  }
  return "unknown";
}

bool ParseStaticsMethod(const std::string& name, StaticsMethod* method) {
  for (StaticsMethod m : {StaticsMethod::kAas, StaticsMethod::kAasRefined, StaticsMethod::kExact}) {
    if (name == StaticsMethodName(m)) {
      *method = m;
      return true;
    }
  }
  return false;
}

const char* StaticsStatusName(StaticsStatus status) {
  switch (status) {
    case StaticsStatus::kOk:
      return "ok";
    case StaticsStatus::kInvalidInput:
      return "invalid_input";
    case StaticsStatus::kVerticalCable:
      return "vertical_cable";
    case StaticsStatus::kNoEquilibrium:
      return "no_equilibrium";
    case StaticsStatus::kSaggingCable:
      return "sagging_cable";
    case StaticsStatus::kOverstretchedCable:
      return "overstretched_cable";
    case StaticsStatus::kReflectorContact:
      return "reflector_contact";
    case StaticsStatus::kSingular:
      return "singular";
    case StaticsStatus::kCatenaryFailed:
      return "catenary_failed";
    case StaticsStatus::kNotConverged:
      return "not_converged";
    case StaticsStatus::kInaccurate:
      return "inaccurate";
    case StaticsStatus::kAttachmentBeyondCable:
      return "attachment_beyond_cable";
    case StaticsStatus::kUnsupportedModel:
      return "unsupported_model";
  }
  return "unknown";
}

const char* EquilibriumCode(const StaticsSolution& solution) {
  if (solution.other_equilibrium) {
    return solution.branch == EquilibriumBranch::kNone ? "unreachable" : "several";
  }
  switch (solution.branch) {
    case EquilibriumBranch::kTaut:
      return "taut";
    case EquilibriumBranch::kFromHome:
      return "home";
    case EquilibriumBranch::kNone:
      break;
  }
  return "";
}

namespace {

// Which rule of StaticsOptions::IsValid `o` breaks first (kNone: none). Separate from the
// message so that SolveStatics can check without allocating.
enum class OptionsRule {
  kNone,
  kSecants,
  kRefinement,
  kAasMaxError,
  kExactTolerance,
  kStartTolerance,
  kModelRange,
  kReflectorClearance,
  kExactIterations,
  kCatenary
};

OptionsRule BrokenRule(const StaticsOptions& o) {
  if (!(o.secant_low_fraction > 0.0) || !(o.secant_high_fraction > o.secant_low_fraction) ||
      !std::isfinite(o.secant_high_fraction)) {
    return OptionsRule::kSecants;
  }
  if (o.max_refinement_steps < 1 || !(o.refined_relative_tolerance > 0.0)) {
    return OptionsRule::kRefinement;
  }
  if (!(o.aas_max_relative_error > 0.0)) return OptionsRule::kAasMaxError;
  if (!(o.exact_relative_tolerance > 0.0)) return OptionsRule::kExactTolerance;
  if (!(o.exact_start_catenary_tolerance > 0.0) || !(o.aas_secant_tolerance > 0.0) ||
      !(o.aas_length_tolerance > 0.0)) {
    return OptionsRule::kStartTolerance;
  }
  if (!(o.max_strain > 0.0) || !(o.max_length_ratio > 1.0)) return OptionsRule::kModelRange;
  if (!std::isfinite(o.min_reflector_clearance_m)) return OptionsRule::kReflectorClearance;
  if (o.exact_max_iterations < 1 || o.exact_max_continuation_iterations < 1) {
    return OptionsRule::kExactIterations;
  }
  if (!(o.catenary.relative_tolerance > 0.0) || o.catenary.max_iterations < 1) {
    return OptionsRule::kCatenary;
  }
  return OptionsRule::kNone;
}

}  // namespace

bool StaticsOptions::IsValid(std::string* error) const {
  const OptionsRule rule = BrokenRule(*this);
  if (rule == OptionsRule::kNone) return true;
  if (error == nullptr) return false;
  std::ostringstream e;
  switch (rule) {
    case OptionsRule::kNone:
      break;
    case OptionsRule::kSecants:
      e << "secant fractions must satisfy 0 < low < high (got " << secant_low_fraction << ", "
        << secant_high_fraction << ")";
      break;
    case OptionsRule::kRefinement:
      e << "max_refinement_steps must be >= 1 and refined_relative_tolerance > 0 (got "
        << max_refinement_steps << ", " << refined_relative_tolerance << ")";
      break;
    case OptionsRule::kAasMaxError:
      e << "aas_max_relative_error must be > 0 (got " << aas_max_relative_error << ")";
      break;
    case OptionsRule::kExactTolerance:
      e << "exact_relative_tolerance must be > 0 (got " << exact_relative_tolerance << ")";
      break;
    case OptionsRule::kStartTolerance:
      e << "exact_start_catenary_tolerance, aas_secant_tolerance and aas_length_tolerance "
           "must be > 0 (got "
        << exact_start_catenary_tolerance << ", " << aas_secant_tolerance << ", "
        << aas_length_tolerance << ")";
      break;
    case OptionsRule::kModelRange:
      e << "max_strain must be > 0 and max_length_ratio > 1 (got " << max_strain << ", "
        << max_length_ratio << ")";
      break;
    case OptionsRule::kReflectorClearance:
      e << "min_reflector_clearance_m must be finite (got " << min_reflector_clearance_m << ")";
      break;
    case OptionsRule::kExactIterations:
      e << "exact_max_iterations and exact_max_continuation_iterations must be >= 1 (got "
        << exact_max_iterations << ", " << exact_max_continuation_iterations << ")";
      break;
    case OptionsRule::kCatenary:
      e << "catenary solver options must have relative_tolerance > 0 and max_iterations >= 1";
      break;
  }
  *error = e.str();
  return false;
}

StaticsOptions ModelFitStaticsOptions(StaticsMethod method) {
  StaticsOptions o;
  o.method = method;
  o.aas_secant_tolerance = o.catenary.relative_tolerance;
  o.aas_length_tolerance = o.catenary.relative_tolerance;
  o.aas_max_relative_error = std::numeric_limits<double>::infinity();
  o.compute_unstretched_lengths = false;
  return o;
}

StaticsParameters<double> MakeStaticsParameters(const CableRobot& robot) {
  StaticsParameters<double> p;
  for (int i = 0; i < kNumCables; ++i) {
    p.tower_top_m[i] = robot.cables[i].tower_top_m;
    p.anchor_cabin_m[i] = robot.AnchorOfCable(i);
    p.ea_n[i] = robot.cables[i].ea_n;
    p.linear_density_kg_per_m[i] = robot.cables[i].linear_density_kg_per_m;
    p.chain[i] = MakeCatenaryChain(robot.cables[i].attachments);
  }
  p.cabin_mass_kg = robot.cabin_mass_kg;
  p.mass_centre_cabin_m = robot.mass_centre_cabin_m;
  p.num_parts = static_cast<int>(robot.moving_parts.parts.size());
  for (int k = 0; k < p.num_parts; ++k) {
    p.part_first_moment_kg_m[k] = robot.moving_parts.parts[k].first_moment_kg_m;
    p.part_mass_kg[k] = robot.moving_parts.parts[k].mass_kg;
  }
  p.gravity_m_per_s2 = robot.gravity_m_per_s2;
  p.reflector = robot.reflector;
  return p;
}

StaticsStatus SolveStaticsWithParameters(const StaticsParameters<double>& parameters,
                                         const Pose& pose, const StaticsOptions& options,
                                         StaticsSolution* solution) {
  if (BrokenRule(options) != OptionsRule::kNone) {
    // Invalid options are invalid input (StaticsOptions::IsValid says which).
    const StaticsStatus status = solution->status = StaticsStatus::kInvalidInput;
    solution->method = options.method;
    solution->cables = {};
    solution->cable = -1;
    return status;
  }
  const bool warm = options.warm_start && solution->status == StaticsStatus::kOk;
  // Constructed only when warm: a cold solve at 1.4 us would spend 1-2% on it.
  std::optional<PreviousSolve> previous;
  if (warm) previous.emplace(*solution);
  // A warm attempt that fails is retried cold; only the cold one may take exact's
  // continuation, so that it runs at most once.
  StaticsStatus status = Attempt(parameters, pose, options, warm ? &*previous : nullptr,
                                 /*may_follow=*/!warm, solution);
  const bool warm_worked = warm && status == StaticsStatus::kOk;
  if (status != StaticsStatus::kOk && warm) {
    status = Attempt(parameters, pose, options, nullptr, /*may_follow=*/true, solution);
  }
  solution->pose = pose;
  solution->has_previous = warm_worked;
  if (solution->has_previous) {
    solution->previous_pose = previous->pose;
    solution->previous_state = previous->state;
    if (previous->secants_at_pose) {
      solution->previous_secant_low = previous->low;
      solution->previous_secant_high = previous->high;
    } else {
      solution->previous_secant_low = {};  // none to extrapolate from (statics.h)
      solution->previous_secant_high = {};
    }
  }
  if (status != StaticsStatus::kOk) {
    // No numbers where an error belongs: only the failure's own (cable, limit_value,
    // limit) and the iteration counts stay.
    solution->cables = {};
    solution->force_residual_n = solution->moment_residual_nm = 0.0;
    solution->end_residual_m = solution->error_estimate = 0.0;
  }
  solution->status = status;
  return status;
}

StaticsStatus SolveStaticsWithParameters(const StaticsParameters<double>& parameters,
                                         const MovingParts& parts, const JointValues& joints,
                                         const Pose& pose, const StaticsOptions& options,
                                         StaticsSolution* solution) {
  if (parameters.num_parts == 0 || parts.empty()) {
    return SolveStaticsWithParameters(parameters, pose, options, solution);
  }
  PartShifts shifts;
  parts.ShiftsAt(joints, &shifts);
  return SolveStaticsWithParameters(AtJoints(parameters, shifts), pose, options, solution);
}

StaticsStatus SolveStatics(const CableRobot& robot, const Pose& pose, const StaticsOptions& options,
                           StaticsSolution* solution) {
  return SolveStatics(robot, pose, JointValues{}, options, solution);
}

StaticsStatus SolveStatics(const CableRobot& robot, const Pose& pose, const JointValues& joints,
                           const StaticsOptions& options, StaticsSolution* solution) {
  // MakeStaticsParameters indexes the anchors: a robot without them (default-constructed)
  // is invalid input, not a crash.
  for (const CableProperties& c : robot.cables) {
    if (c.anchor_index < 0 ||
        c.anchor_index >= static_cast<int>(robot.anchor_points_cabin_m.size())) {
      solution->cables = {};
      solution->cable = -1;
      return solution->status = StaticsStatus::kInvalidInput;
    }
  }
  StaticsParameters<double> p = MakeStaticsParameters(robot);
  // All joints at zero (a robot without moving parts: always) leave c0 as it is.
  if (!robot.moving_parts.empty()) p.mass_centre_cabin_m = robot.MassCentreAt(joints);
  return SolveStaticsWithParameters(p, pose, options, solution);
}

namespace {

// `value` with `digits` significant digits, for messages.
std::string Sig(double value, int digits = 3) {
  std::ostringstream s;
  s.precision(digits);
  s << value;
  return s.str();
}

std::string DescribeNotConverged(const StaticsSolution& solution) {
  const int c = solution.cable + 1;
  if (solution.method == StaticsMethod::kExact) {
    return "the exact solver did not converge within its iteration limits "
           "(StaticsOptions::exact_max_iterations, exact_max_continuation_iterations)";
  }
  if (solution.limit > 0.0) {
    return "aas-refined did not reach its tolerance: error estimate " + Sig(solution.limit_value) +
           " > " + Sig(solution.limit) +
           " (StaticsOptions::refined_relative_tolerance) after max_refinement_steps steps; "
           "use exact";
  }
  if (solution.cable < 0) {
    return "aas-refined: a step met a singular equilibrium system, so it cannot go on; use "
           "exact, which also says whether the pose can be held";
  }
  return "aas-refined: its AAS start or a step gives cable " + std::to_string(c) +
         " a horizontal force or length <= 0, so it cannot go on; use exact, which also says "
         "whether the pose can be held";
}

std::string DescribeModelRange(const StaticsSolution& solution) {
  const int c = solution.cable + 1;
  std::ostringstream s;
  switch (solution.status) {
    case StaticsStatus::kSaggingCable:
      s << "cable " << c << " hangs beyond the model's range: s0/k = " << Sig(solution.limit_value)
        << " > " << Sig(solution.limit)
        << " (StaticsOptions::max_length_ratio); the equilibrium has it in a deep loop";
      if (solution.reflector_clearance_m < 0.0) {
        s << ", and a cable would pass " << Sig(-solution.reflector_clearance_m)
          << " m below the reflector's surface";
      }
      break;
    case StaticsStatus::kOverstretchedCable:
      if (solution.limit > 0.0) {
        s << "cable " << c << " would be stretched beyond the model's elastic range: strain "
          << Sig(100.0 * solution.limit_value) << "% > " << Sig(100.0 * solution.limit)
          << "% (StaticsOptions::max_strain): the pose cannot be held as modelled";
      } else {
        s << "cable " << c
          << "'s equilibrium has an unstretched length <= 0 (s0/k = " << Sig(solution.limit_value)
          << "): no physical cable";
      }
      break;
    case StaticsStatus::kReflectorContact:
      if (solution.limit_value < 0.0) {
        s << "cable " << c << " would pass through the reflector: its loop reaches "
          << Sig(-solution.limit_value) << " m below the reflector's surface";
      } else {
        s << "cable " << c << " would come within " << Sig(solution.limit_value)
          << " m of the reflector's surface, closer than "
             "StaticsOptions::min_reflector_clearance_m = "
          << Sig(solution.limit) << " m";
      }
      break;
    default:
      break;
  }
  return s.str();
}

}  // namespace

std::string DescribeStatus(const StaticsSolution& solution) {
  std::ostringstream s;
  const int c = solution.cable + 1;
  switch (solution.status) {
    case StaticsStatus::kOk:
      s << "ok";
      break;
    case StaticsStatus::kInvalidInput:
      s << "invalid input: the pose or the model has a non-finite or non-physical value, or "
           "the options are invalid (StaticsOptions::IsValid says which)";
      break;
    case StaticsStatus::kVerticalCable:
      s << "cable " << c << " is vertical: its horizontal force direction is undefined";
      break;
    case StaticsStatus::kNoEquilibrium:
      // Not "the cables cannot hold the cabin here": with sagging cables another
      // equilibrium, beyond a fold, may (docs/model.md, "Which equilibrium exact returns").
      s << "no equilibrium with positive cable forces reached from the home pose: followed "
           "from there, the equilibrium ends before this pose";
      if (solution.cable >= 0 && solution.limit_value > 1.05) {
        s << " (cable " << c << " then hung in a loop, s0/k = " << Sig(solution.limit_value) << ")";
      }
      break;
    case StaticsStatus::kSaggingCable:
    case StaticsStatus::kOverstretchedCable:
    case StaticsStatus::kReflectorContact:
      s << DescribeModelRange(solution);
      break;
    case StaticsStatus::kSingular:
      s << "the equilibrium equations are singular at this pose";
      break;
    case StaticsStatus::kCatenaryFailed:
      s << "the catenary of cable " << c << " did not converge";
      break;
    case StaticsStatus::kNotConverged:
      s << DescribeNotConverged(solution);
      break;
    case StaticsStatus::kInaccurate:
      if (solution.limit > 0.0) {
        s << "aas's error estimate "
          << (solution.limit_value > 1.0 ? "is over 100%"
                                         : Sig(100.0 * solution.limit_value) + "% exceeds")
          << " its limit " << Sig(100.0 * solution.limit)
          << "% (StaticsOptions::aas_max_relative_error): its secant lines are far from the "
             "catenaries here; use exact";
      } else {
        s << "aas gives cable " << c
          << " a horizontal force <= 0: its secant lines are far from the catenaries here, "
             "which says nothing about whether the pose can be held; use exact";
      }
      break;
    case StaticsStatus::kAttachmentBeyondCable:
      s << "an attachment of cable " << c << " starts " << Sig(solution.limit_value, 6)
        << " m from its lower end, at or beyond the cable's unstretched length here ("
        << Sig(solution.limit, 6) << " m): it is not on the cable (check the model's "
        << "cables[" << solution.cable << "].attachments)";
      break;
    case StaticsStatus::kUnsupportedModel:
      s << "cable " << c << " carries attachments (sensors, hung lines), which aas and "
        << "aas-refined do not model (their secant lines are the uniform cable's); use exact";
      break;
  }
  if (solution.other_equilibrium) {
    s << (solution.branch == EquilibriumBranch::kNone
              ? "; another equilibrium holds this pose, reached only through a fold (a jump of "
                "the cable lengths), not the home pose's (docs/model.md, \"Which equilibrium "
                "exact returns\")"
              : "; several equilibria hold this pose: this is the one followed from the home "
                "pose (docs/model.md, \"Which equilibrium exact returns\")");
  }
  return s.str();
}

// A state from outside (the forward statics, locate.h), checked as exact's own solutions
// are: its error estimate at most exact_relative_tolerance (kNotConverged otherwise), the
// equilibrium residuals, the model range and the reflector (statics_core.h).
StaticsStatus CheckStaticsState(const StaticsParameters<double>& p, const Pose& pose,
                                const std::array<internal::CableState<double>, kNumCables>& state,
                                const StaticsOptions& options, StaticsSolution* solution) {
  StaticsSolution* sol = solution;
  sol->method = StaticsMethod::kExact;
  sol->cable = -1;
  sol->outer_iterations = sol->catenary_iterations = 0;
  sol->continuation = sol->has_previous = false;
  sol->force_residual_n = sol->moment_residual_nm = 0.0;
  sol->end_residual_m = sol->error_estimate = 0.0;
  sol->limit_value = sol->limit = 0.0;
  sol->reflector_clearance_m = std::numeric_limits<double>::infinity();
  sol->pose = pose;
  StaticsStatus status = StaticsStatus::kInvalidInput;
  Geometry g;
  bool usable = BrokenRule(options) == OptionsRule::kNone && IsFinite(pose) && ParametersUsable(p);
  for (const CableState<double>& c : state) usable = usable && c.fl > 0.0 && c.s0 > 0.0;
  if (usable) {
    status = internal::ComputeGeometry(p, pose, options.catenary.vertical_span_fraction, &g,
                                       &sol->cable);
  }
  if (status == StaticsStatus::kOk) {
    Context c{p, options, sol};
    CableLinearisation<double> lin;
    internal::LineariseCables(p, g, state, &lin);
    EquilibriumResponse response;
    std::array<double, kNumCables> unused;
    if (!internal::SolveEquilibrium<double, true>(g, lin.a, lin.b, &unused, &response)) {
      status = StaticsStatus::kSingular;
    } else {
      const Check check = CheckAfterStep(p, g, state, lin, response);
      if (!(check.error_estimate <= options.exact_relative_tolerance)) {
        sol->limit_value = check.error_estimate;
        sol->limit = options.exact_relative_tolerance;
        status = StaticsStatus::kNotConverged;
      } else {
        status = Finish(&c, g, state, check);
      }
    }
  }
  if (status != StaticsStatus::kOk) {
    sol->cables = {};  // no numbers where an error belongs (SolveStaticsWithParameters)
    sol->force_residual_n = sol->moment_residual_nm = 0.0;
    sol->end_residual_m = sol->error_estimate = 0.0;
  }
  return sol->status = status;
}

}  // namespace fastcal
