// Templated core of the statics solvers (statics.h), shared by the double API and by the
// calibration's cost functions (scalar = ceres::Jet). Equations: statics.h and
// docs/model.md.
//
// For a Jet scalar the iterations run in double (SolveStatics) and the result is then
// replayed in Jet arithmetic from the converged double values:
//   aas, aas-refined: the same explicit sequence of steps, each inner catenary solve
//                     differentiated implicitly (catenary.h);
//   exact:            one reduced Newton step from the converged point, whose derivative
//                     is the implicit-function derivative of the solution.
#ifndef FASTCAL_INTERNAL_STATICS_CORE_H_
#define FASTCAL_INTERNAL_STATICS_CORE_H_

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "fastcal/cable.h"
#include "fastcal/cable_robot.h"
#include "fastcal/catenary.h"
#include "fastcal/catenary_chain.h"
#include "fastcal/pose.h"
#include "fastcal/scalar.h"

namespace fastcal {

template <typename T>
using Vector3T = Eigen::Matrix<T, 3, 1>;

// The statics model's parameters per cable, in scalar T (anchors repeated per cable).
template <typename T>
struct StaticsParameters {
  std::array<Vector3T<T>, kNumCables> tower_top_m;     // global frame
  std::array<Vector3T<T>, kNumCables> anchor_cabin_m;  // cabin frame
  std::array<T, kNumCables> ea_n;
  std::array<T, kNumCables> linear_density_kg_per_m;
  // Each cable's attachments (catenary_chain.h); empty for a uniform cable.
  std::array<CatenaryChain<T>, kNumCables> chain;
  T cabin_mass_kg;
  // The cabin's mass centre: with moving parts, its value with every joint at zero (c0 of
  // moving_parts.h eq. (1)) until AtJoints moves it to a sample's joint values.
  Vector3T<T> mass_centre_cabin_m;
  // The moving parts' unknowns of eq. (1): each part's first moment Q_k and mass m_k;
  // num_parts = 0 for a rigid cabin.
  int num_parts = 0;
  std::array<Vector3T<T>, kMaxMovingParts> part_first_moment_kg_m;
  std::array<T, kMaxMovingParts> part_mass_kg;
  double gravity_m_per_s2 = -9.8;
  // Only checked against (in double), never differentiated; none unless set.
  std::optional<Reflector> reflector;
};

StaticsParameters<double> MakeStaticsParameters(const CableRobot& robot);

template <typename T>
StaticsParameters<double> ScalarParameters(const StaticsParameters<T>& p) {
  StaticsParameters<double> d;
  for (int i = 0; i < kNumCables; ++i) {
    for (int j = 0; j < 3; ++j) {
      d.tower_top_m[i][j] = ScalarValue(p.tower_top_m[i][j]);
      d.anchor_cabin_m[i][j] = ScalarValue(p.anchor_cabin_m[i][j]);
    }
    d.ea_n[i] = ScalarValue(p.ea_n[i]);
    d.linear_density_kg_per_m[i] = ScalarValue(p.linear_density_kg_per_m[i]);
    d.chain[i] = ScalarChain(p.chain[i]);
  }
  d.cabin_mass_kg = ScalarValue(p.cabin_mass_kg);
  for (int j = 0; j < 3; ++j) d.mass_centre_cabin_m[j] = ScalarValue(p.mass_centre_cabin_m[j]);
  d.num_parts = p.num_parts;
  for (int k = 0; k < p.num_parts; ++k) {
    for (int j = 0; j < 3; ++j)
      d.part_first_moment_kg_m[k][j] = ScalarValue(p.part_first_moment_kg_m[k][j]);
    d.part_mass_kg[k] = ScalarValue(p.part_mass_kg[k]);
  }
  d.gravity_m_per_s2 = p.gravity_m_per_s2;
  d.reflector = p.reflector;
  return d;
}

// The other way: `d` in scalar T (constants, no derivative), into *p. The reflector, only
// ever checked in double, is not copied (the Jet path solves with ScalarParameters of *p).
template <typename T>
void CastParametersInto(const StaticsParameters<double>& d, StaticsParameters<T>* p) {
  for (int i = 0; i < kNumCables; ++i) {
    p->tower_top_m[i] = d.tower_top_m[i].cast<T>();
    p->anchor_cabin_m[i] = d.anchor_cabin_m[i].cast<T>();
    p->ea_n[i] = T(d.ea_n[i]);
    p->linear_density_kg_per_m[i] = T(d.linear_density_kg_per_m[i]);
    const CatenaryChain<double>& chain = d.chain[i];
    p->chain[i].num_cuts = chain.num_cuts;
    p->chain[i].num_attachments = chain.num_attachments;
    p->chain[i].cuts = chain.cuts;
    for (int j = 0; j < chain.num_attachments; ++j) p->chain[i].value[j] = T(chain.value[j]);
  }
  p->cabin_mass_kg = T(d.cabin_mass_kg);
  p->mass_centre_cabin_m = d.mass_centre_cabin_m.cast<T>();
  p->num_parts = d.num_parts;
  for (int k = 0; k < d.num_parts; ++k) {
    p->part_first_moment_kg_m[k] = d.part_first_moment_kg_m[k].cast<T>();
    p->part_mass_kg[k] = T(d.part_mass_kg[k]);
  }
  p->gravity_m_per_s2 = d.gravity_m_per_s2;
}

// The mass centre at a sample's joint values, eq. (1) of moving_parts.h:
//   c(q) = c0 + sum_k (A_k Q_k + b_k m_k) / M,
// with `shifts` (A_k, b_k) from MovingParts::ShiftsAt.
template <typename T>
Vector3T<T> MassCentreAt(const StaticsParameters<T>& p, const PartShifts& shifts) {
  Vector3T<T> sum = Vector3T<T>::Zero();
  for (int k = 0; k < p.num_parts; ++k) {
    sum += shifts[k].rotation_minus_identity.cast<T>() * p.part_first_moment_kg_m[k] +
           shifts[k].translation_m.cast<T>() * p.part_mass_kg[k];
  }
  return p.mass_centre_cabin_m + sum / p.cabin_mass_kg;
}

// `p` with its mass centre moved to the joint values of `shifts` (a copy: ~2.5 kB, a
// tenth of a solve, paid only by a model with moving parts).
template <typename T>
StaticsParameters<T> AtJoints(const StaticsParameters<T>& p, const PartShifts& shifts) {
  StaticsParameters<T> out = p;
  out.mass_centre_cabin_m = MassCentreAt(p, shifts);
  return out;
}

namespace internal {

// The end point of cable i at (Fl, Fz, s0) with weight per length w: the uniform
// catenary's (catenary.h) or, where the cable carries attachments, the chain's
// (catenary_chain.h). A uniform cable pays one predictable branch.
template <typename T>
FASTCAL_ALWAYS_INLINE CatenaryEnd<T> CableEndpoint(const StaticsParameters<T>& p, int i,
                                                   const T& fl_n, const T& fz_n, const T& s0_m,
                                                   const T& w_n_per_m) {
  return Cable::EndOf(fl_n, fz_n, s0_m, p.ea_n[i], w_n_per_m, p.chain[i], p.gravity_m_per_s2);
}

// Cable chords and lever arms at one pose.
template <typename T>
struct PoseGeometry {
  std::array<Vector3T<T>, kNumCables> r;  // R a_i, global axes, from O'
  std::array<T, kNumCables> span, rise, chord, ux, uy, w;
  Vector3T<T> e;  // R r_e
  T weight_n;     // m g (negative)
  // double only (ComputeGeometry): three of the six equilibrium rows (0, 1, 5: the
  // horizontal forces and the moment about z) hold no Fz, so they are the same for every
  // solve at this pose: the Fl that meet them are null_basis * c, c in R^3
  // (EquilibriumNullBasis), and its solved block's reciprocal condition squared (det^2
  // over Hadamard's bound squared), for the singularity test.
  Eigen::Matrix<double, 6, 3> null_basis;
  double basis_reciprocal_condition2 = 0.0;
};

// The adjugate of a 3x3 matrix (its inverse times the determinant) and the determinant,
// and Hadamard's bound on that (the product of the rows' lengths, squared), whose ratio
// to det^2 serves as the reciprocal condition: no division, no branch.
struct Adjugate3 {
  Eigen::Matrix3d adjugate;
  double det, hadamard2;
  explicit Adjugate3(const Eigen::Matrix3d& m) {
    auto col = [&m](int a, int b) {  // row a x row b, as a column
      return Eigen::Vector3d(m(a, 1) * m(b, 2) - m(a, 2) * m(b, 1),
                             m(a, 2) * m(b, 0) - m(a, 0) * m(b, 2),
                             m(a, 0) * m(b, 1) - m(a, 1) * m(b, 0));
    };
    adjugate.col(0) = col(1, 2);
    adjugate.col(1) = col(2, 0);
    adjugate.col(2) = col(0, 1);
    det = m.row(0).dot(adjugate.col(0).transpose());
    hadamard2 = m.row(0).squaredNorm() * m.row(1).squaredNorm() * m.row(2).squaredNorm();
  }
  // |det| >= ratio times Hadamard's bound.
  bool ConditionedBetterThan(double ratio) const { return det * det >= ratio * ratio * hadamard2; }
};

// The null space of the equilibrium rows without Fz (rows 0, 1, 5 of SolveEquilibrium's
// matrix, H: ux_i, uy_i, r_y,i ux_i - r_x,i uy_i): three columns of H are solved for
// (H_p X = -H_f, by the adjugate), the other three are free (identity). First with
// cables 1, 3, 5, one per anchor and 120 deg apart on FAST, which makes H_p well
// conditioned without a search; only if it is not (reciprocal condition, as Hadamard's
// ratio, below kWellConditioned), with the columns of complete pivoting.
inline void EquilibriumNullBasis(PoseGeometry<double>* g) {
  constexpr double kWellConditioned = 1e-3;
  double h[3][kNumCables];
  for (int i = 0; i < kNumCables; ++i) {
    h[0][i] = g->ux[i];
    h[1][i] = g->uy[i];
    h[2][i] = g->r[i][1] * g->ux[i] - g->r[i][0] * g->uy[i];
  }
  auto solve_for = [&](const int* pivots, const int* free) {
    Eigen::Matrix3d hp, hf;
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 3; ++k) {
        hp(r, k) = h[r][pivots[k]];
        hf(r, k) = h[r][free[k]];
      }
    }
    const Adjugate3 a(hp);
    const Eigen::Matrix3d x = -(a.adjugate / a.det) * hf;
    g->null_basis.setZero();
    for (int k = 0; k < 3; ++k) {
      g->null_basis.row(pivots[k]) = x.row(k);
      g->null_basis(free[k], k) = 1.0;
    }
    g->basis_reciprocal_condition2 = a.det * a.det / a.hadamard2;
    return a.ConditionedBetterThan(kWellConditioned);
  };
  const int odd[3] = {0, 2, 4}, even[3] = {1, 3, 5};
  if (solve_for(odd, even)) return;
  // Complete pivoting on a copy, for its choice of columns only.
  double e[3][kNumCables];
  std::copy(&h[0][0], &h[0][0] + 3 * kNumCables, &e[0][0]);
  int col[kNumCables] = {0, 1, 2, 3, 4, 5};
  for (int k = 0; k < 3; ++k) {
    int pr = k, pc = k;
    for (int r = k; r < 3; ++r) {
      for (int c = k; c < kNumCables; ++c) {
        if (std::abs(e[r][col[c]]) > std::abs(e[pr][col[pc]])) {
          pr = r;
          pc = c;
        }
      }
    }
    for (int c = 0; c < kNumCables; ++c) std::swap(e[k][c], e[pr][c]);
    std::swap(col[k], col[pc]);
    const double pivot = e[k][col[k]];
    if (!(std::abs(pivot) > 0.0)) break;  // rank < 3: the ratio below says singular
    for (int r = k + 1; r < 3; ++r) {
      const double f = e[r][col[k]] / pivot;
      for (int c = 0; c < kNumCables; ++c) e[r][c] -= f * e[k][c];
    }
  }
  solve_for(col, col + 3);
}

// `null_basis` (double only): also PoseGeometry::null_basis, which only the solvers use.
template <typename T>
StaticsStatus ComputeGeometry(const StaticsParameters<T>& p, const Pose& pose,
                              double vertical_span_fraction, PoseGeometry<T>* g, int* cable,
                              bool null_basis = true) {
  using std::sqrt;
  const Eigen::Matrix<T, 3, 3> rotation = pose.rotation.cast<T>();
  const Vector3T<T> position = pose.position_m.cast<T>();
  for (int i = 0; i < kNumCables; ++i) {
    g->r[i] = rotation * p.anchor_cabin_m[i];
    const Vector3T<T> c = p.tower_top_m[i] - (g->r[i] + position);
    g->span[i] = sqrt(c[0] * c[0] + c[1] * c[1]);
    g->rise[i] = c[2];
    g->chord[i] = sqrt(g->span[i] * g->span[i] + c[2] * c[2]);
    if (!(ScalarValue(g->span[i]) > vertical_span_fraction * ScalarValue(g->chord[i]))) {
      *cable = i;
      return StaticsStatus::kVerticalCable;
    }
    const T inv_span = T(1) / g->span[i];  // one division, not two
    g->ux[i] = c[0] * inv_span;
    g->uy[i] = c[1] * inv_span;
    g->w[i] = p.linear_density_kg_per_m[i] * p.gravity_m_per_s2;
  }
  g->e = rotation * p.mass_centre_cabin_m;
  g->weight_n = p.cabin_mass_kg * p.gravity_m_per_s2;
  if constexpr (kIsDouble<T>) {
    if (null_basis) EquilibriumNullBasis(g);
  }
  return StaticsStatus::kOk;
}

// How the solution Fl of the 6x6 equilibrium system moves when the right-hand sides of
// its vertical-force row and its two tilting-moment rows (rows 2, 3, 4; statics.h) move:
// dFl = null_basis * response * (d rhs2, d rhs3, d rhs4), with response = (V N)^-1, the
// inverse of SolveEquilibriumReduced's 3x3 system (PoseGeometry::null_basis: N). A
// cable's Fz off its curve by d shifts just those rows (by -d, -r_y d, -r_x d), so the
// error estimates need only this, not the matrix's factors; SolveEquilibrium keeps it
// alongside Fl (a copy: the product with N is left to the one use of each).
using EquilibriumResponse = Eigen::Matrix3d;

// Reciprocal condition below which the equilibrium system counts as singular.
inline constexpr double kMinEquilibriumReciprocalCondition = 1e-13;

// SolveEquilibrium for double: three unknowns through PoseGeometry::null_basis.
template <bool kResponse>
bool SolveEquilibriumReduced(const PoseGeometry<double>& g, const std::array<double, kNumCables>& a,
                             const std::array<double, kNumCables>& b,
                             std::array<double, kNumCables>* fl, EquilibriumResponse* response) {
  constexpr double kMinReciprocalCondition = kMinEquilibriumReciprocalCondition;
  // Fl = N c (PoseGeometry::null_basis) meets rows 0, 1, 5; rows 2, 3, 4 are then the
  // 3x3 system (V N) c = rhs, solved by its adjugate: one division and no branches,
  // where the 6x6 elimination's pivot search and six divisions made a long dependent
  // chain (the largest single cost of a solve). The response is then (V N)^-1.
  const Eigen::Matrix<double, 6, 3>& n = g.null_basis;
  Eigen::Matrix3d vn = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs(g.weight_n, g.e[1] * g.weight_n, g.e[0] * g.weight_n);
  for (int i = 0; i < kNumCables; ++i) {
    const Vector3T<double>& r = g.r[i];
    const Eigen::Vector3d v(a[i], r[1] * a[i] + r[2] * g.uy[i], r[0] * a[i] + r[2] * g.ux[i]);
    vn += v * n.row(i);
    rhs -= b[i] * Eigen::Vector3d(1.0, r[1], r[0]);
  }
  const Adjugate3 adj(vn);
  if (!adj.ConditionedBetterThan(kMinReciprocalCondition) ||
      !(g.basis_reciprocal_condition2 > kMinReciprocalCondition * kMinReciprocalCondition)) {
    return false;
  }
  const Eigen::Matrix3d inverse = adj.adjugate / adj.det;
  const Eigen::Matrix<double, 6, 1> x = n * (inverse * rhs);
  for (int i = 0; i < kNumCables; ++i) (*fl)[i] = x[i];
  if constexpr (kResponse) *response = inverse;
  return true;
}

// SolveEquilibrium for a Jet (the calibration's derivatives): the whole 6x6 system.
template <typename T>
bool SolveEquilibrium6x6(const PoseGeometry<T>& g, const std::array<T, kNumCables>& a,
                         const std::array<T, kNumCables>& b, std::array<T, kNumCables>* fl) {
  constexpr double kMinReciprocalCondition = kMinEquilibriumReciprocalCondition;
  // Gaussian elimination with partial pivoting written out (several times faster than
  // Eigen's blocked PartialPivLU plus its rcond() estimate), the pivot ratio as the
  // singularity test (columns are scaled alike: forces in N). The Jets keep the full
  // system: the null basis is built for double only, and this path's speed is the
  // calibration's, measured by calibration_bench.
  Eigen::Matrix<T, 6, 6, Eigen::RowMajor> m;
  Eigen::Matrix<T, 6, 1> rhs;
  rhs << T(0), T(0), g.weight_n, g.e[1] * g.weight_n, g.e[0] * g.weight_n, T(0);
  for (int i = 0; i < kNumCables; ++i) {
    const Vector3T<T>& r = g.r[i];
    m(0, i) = g.ux[i];
    m(1, i) = g.uy[i];
    m(2, i) = a[i];
    m(3, i) = r[1] * a[i] + r[2] * g.uy[i];
    m(4, i) = r[0] * a[i] + r[2] * g.ux[i];
    m(5, i) = r[1] * g.ux[i] - r[0] * g.uy[i];
    rhs[2] -= b[i];
    rhs[3] -= r[1] * b[i];
    rhs[4] -= r[0] * b[i];
  }
  using std::abs;
  double max_pivot = 0.0, min_pivot = std::numeric_limits<double>::infinity();
  std::array<T, 6> inv_pivot;
  for (int c = 0; c < 6; ++c) {
    int p = c;
    for (int r = c + 1; r < 6; ++r) {
      if (abs(ScalarValue(m(r, c))) > abs(ScalarValue(m(p, c)))) p = r;
    }
    if (p != c) {
      m.row(p).swap(m.row(c));
      std::swap(rhs[p], rhs[c]);
    }
    const double pivot = abs(ScalarValue(m(c, c)));
    max_pivot = std::max(max_pivot, pivot);
    min_pivot = std::min(min_pivot, pivot);
    if (!(pivot > 0.0)) return false;
    inv_pivot[c] = T(1) / m(c, c);
    for (int r = c + 1; r < 6; ++r) {
      const T f = m(r, c) * inv_pivot[c];
      for (int k = c + 1; k < 6; ++k) m(r, k) -= f * m(c, k);
      rhs[r] -= f * rhs[c];
    }
  }
  if (!(min_pivot > kMinReciprocalCondition * max_pivot)) return false;
  Eigen::Matrix<T, 6, 1> x;
  for (int r = 5; r >= 0; --r) {
    T acc = rhs[r];
    for (int k = r + 1; k < 6; ++k) acc -= m(r, k) * x[k];
    x[r] = acc * inv_pivot[r];
  }
  for (int i = 0; i < kNumCables; ++i) (*fl)[i] = x[i];
  return true;
}

// Solves the six equilibrium rows for Fl given Fz_i = a_i Fl_i + b_i (statics.h).
// Returns false when the matrix is singular to working precision. With kResponse (double
// only) *response receives the system's EquilibriumResponse.
template <typename T, bool kResponse = false>
bool SolveEquilibrium(const PoseGeometry<T>& g, const std::array<T, kNumCables>& a,
                      const std::array<T, kNumCables>& b, std::array<T, kNumCables>* fl,
                      EquilibriumResponse* response = nullptr) {
  static_assert(!kResponse || kIsDouble<T>, "the response is kept for double only");
  if constexpr (kIsDouble<T>) {
    return SolveEquilibriumReduced<kResponse>(g, a, b, fl, response);
  } else {
    return SolveEquilibrium6x6(g, a, b, fl);
  }
}

template <typename T>
struct CableState {
  T fl, fz, s0;
};

// The per-cable solver options of AAS's secants: catenary.relative_tolerance loosened to
// aas_secant_tolerance, or for kExact's start to exact_start_catenary_tolerance.
inline CatenarySolverOptions AasSecantSolverOptions(const StaticsOptions& o) {
  CatenarySolverOptions c = o.catenary;
  c.relative_tolerance = std::max(c.relative_tolerance, o.method == StaticsMethod::kExact
                                                            ? o.exact_start_catenary_tolerance
                                                            : o.aas_secant_tolerance);
  return c;
}

// The options of the s0 solves at the AAS forces (ProjectOnCurves): catenary's tolerance
// loosened to aas_length_tolerance, or for kExact's start to
// exact_start_catenary_tolerance.
inline StaticsOptions AasLengthStageOptions(const StaticsOptions& o) {
  StaticsOptions so = o;
  so.catenary.relative_tolerance =
      std::max(o.catenary.relative_tolerance, o.method == StaticsMethod::kExact
                                                  ? o.exact_start_catenary_tolerance
                                                  : o.aas_length_tolerance);
  return so;
}

// AAS secant lines Fz = a Fl + b. `low`, `high` in/out: double solutions used as guesses
// when `use_guess` and written back. For double, `jacobians` (may be null) receives each
// secant solve's last d(L, Z)/d(Fl, Fz) (SolveCatenaryForcesBatch's; low lengths at i,
// high at i + kNumCables).
template <typename T>
StaticsStatus AasLines(const StaticsParameters<T>& p, const PoseGeometry<T>& g,
                       const StaticsOptions& o, bool use_guess,
                       std::array<CatenaryForces, kNumCables>* low,
                       std::array<CatenaryForces, kNumCables>* high, std::array<T, kNumCables>* a,
                       std::array<T, kNumCables>* b, int* cable, int* iterations,
                       double (*jacobians)[4] = nullptr) {
  const CatenarySolverOptions secant_options = AasSecantSolverOptions(o);
  if constexpr (kIsDouble<T>) {
    // All twelve solves at once (low lengths, then high): same results, overlapped.
    CatenaryProblem problems[2 * kNumCables];
    CatenaryForces solved[2 * kNumCables];
    CatenaryStatus statuses[2 * kNumCables];
    int its[2 * kNumCables];
    for (int i = 0; i < kNumCables; ++i) {
      for (int h = 0; h < 2; ++h) {
        CatenaryProblem& c = problems[i + h * kNumCables];
        c.span_m = g.span[i];
        c.rise_m = g.rise[i];
        c.s0_m = (h == 0 ? o.secant_low_fraction : o.secant_high_fraction) * g.chord[i];
        c.ea_n = p.ea_n[i];
        c.w_n_per_m = g.w[i];
        c.guess = use_guess ? (h == 0 ? &(*low)[i] : &(*high)[i]) : nullptr;
      }
    }
    SolveCatenaryForcesBatch(2 * kNumCables, problems, secant_options, solved, statuses, its,
                             jacobians);
    for (int i = 0; i < kNumCables; ++i) {
      *iterations += its[i] + its[i + kNumCables];
      for (CatenaryStatus s : {statuses[i], statuses[i + kNumCables]}) {
        if (s != CatenaryStatus::kOk) {
          *cable = i;
          return s == CatenaryStatus::kVerticalChord ? StaticsStatus::kVerticalCable
                                                     : StaticsStatus::kCatenaryFailed;
        }
      }
      const CatenaryForces &f1 = solved[i], &f2 = solved[i + kNumCables];
      (*a)[i] = (f2.fz_n - f1.fz_n) / (f2.fl_n - f1.fl_n);
      (*b)[i] = f1.fz_n - (*a)[i] * f1.fl_n;
      (*low)[i] = f1;
      (*high)[i] = f2;
    }
    return StaticsStatus::kOk;
  }
  for (int i = 0; i < kNumCables; ++i) {
    T fl1, fz1, fl2, fz2;
    int it1 = 0, it2 = 0;
    const CatenaryForces guess_low = (*low)[i], guess_high = (*high)[i];
    const T s_low = T(o.secant_low_fraction) * g.chord[i];
    const T s_high = T(o.secant_high_fraction) * g.chord[i];
    CatenaryStatus s =
        SolveCatenaryForces(g.span[i], g.rise[i], s_low, p.ea_n[i], g.w[i], secant_options,
                            use_guess ? &guess_low : nullptr, &fl1, &fz1, &it1);
    if (s == CatenaryStatus::kOk) {
      s = SolveCatenaryForces(g.span[i], g.rise[i], s_high, p.ea_n[i], g.w[i], secant_options,
                              use_guess ? &guess_high : nullptr, &fl2, &fz2, &it2);
    }
    *iterations += it1 + it2;
    if (s != CatenaryStatus::kOk) {
      *cable = i;
      return s == CatenaryStatus::kVerticalChord ? StaticsStatus::kVerticalCable
                                                 : StaticsStatus::kCatenaryFailed;
    }
    (*a)[i] = (fz2 - fz1) / (fl2 - fl1);
    (*b)[i] = fz1 - (*a)[i] * fl1;
    (*low)[i] = CatenaryForces{ScalarValue(fl1), ScalarValue(fz1)};
    (*high)[i] = CatenaryForces{ScalarValue(fl2), ScalarValue(fz2)};
  }
  return StaticsStatus::kOk;
}

// Puts each cable on its exact Fz(Fl) curve at the current Fl (solves Fz, s0). `guess`
// (double) starts each solve. kNoEquilibrium when a cable has Fl <= 0. For double,
// `jacobians` (may be null) as SolveCatenaryLengthBatch's.
template <typename T>
StaticsStatus ProjectOnCurves(const StaticsParameters<T>& p, const PoseGeometry<T>& g,
                              const StaticsOptions& o,
                              const std::array<CatenaryCurvePoint, kNumCables>& guess,
                              std::array<CableState<T>, kNumCables>* state, int* cable,
                              int* iterations, double (*jacobians)[4] = nullptr) {
  for (int i = 0; i < kNumCables; ++i) {
    if (!(ScalarValue((*state)[i].fl) > 0.0)) {
      *cable = i;
      return StaticsStatus::kNoEquilibrium;
    }
  }
  if constexpr (kIsDouble<T>) {
    // The six solves at once: same results, overlapped (catenary.h).
    CatenaryLengthProblem problems[kNumCables];
    CatenaryCurvePoint points[kNumCables];
    CatenaryStatus statuses[kNumCables];
    int its[kNumCables];
    for (int i = 0; i < kNumCables; ++i) {
      problems[i] = {g.span[i], g.rise[i], (*state)[i].fl, p.ea_n[i], g.w[i], &guess[i]};
    }
    SolveCatenaryLengthBatch(kNumCables, problems, o.catenary, points, statuses, its, jacobians);
    for (int i = 0; i < kNumCables; ++i) {
      *iterations += its[i];
      if (statuses[i] != CatenaryStatus::kOk) {
        *cable = i;
        return StaticsStatus::kCatenaryFailed;
      }
      (*state)[i].fz = points[i].fz_n;
      (*state)[i].s0 = points[i].s0_m;
    }
    return StaticsStatus::kOk;
  }
  for (int i = 0; i < kNumCables; ++i) {
    CableState<T>& c = (*state)[i];
    int it = 0;
    const CatenaryStatus s = SolveCatenaryLength(g.span[i], g.rise[i], c.fl, p.ea_n[i], g.w[i],
                                                 o.catenary, &guess[i], &c.fz, &c.s0, &it);
    *iterations += it;
    if (s != CatenaryStatus::kOk) {
      *cable = i;
      return StaticsStatus::kCatenaryFailed;
    }
  }
  return StaticsStatus::kOk;
}

// Each cable linearised at its state (Fl, Fz, s0): the end conditions' residual and,
// with ds0 eliminated by the normal n = (dZ/ds0, -dL/ds0), the line Fz = a Fl + b on
// which the linearised end conditions hold. Where the state meets them, a is the tangent
// of the cable's Fz(Fl) curve; b - (Fz - a Fl) is how far its Fz misses the curve.
template <typename T>
struct CableLinearisation {
  std::array<T, kNumCables> a, b;
  std::array<T, kNumCables> inv_qq;  // 1 / (n . d(L, Z)/dFz): a miss in Fz per residual
  std::array<T, kNumCables> g0, g1;  // end residuals: span, rise (m)
  std::array<CatenaryEnd<T>, kNumCables> ends;
  double max_relative_residual = 0.0;  // largest |g0|, |g1| relative to the chord
};

template <typename T>
void LineariseCables(const StaticsParameters<T>& p, const PoseGeometry<T>& g,
                     const std::array<CableState<T>, kNumCables>& state,
                     CableLinearisation<T>* lin) {
  double max_residual = 0.0;
  for (int i = 0; i < kNumCables; ++i) {
    const CableState<T>& c = state[i];
    const CatenaryEnd<T> e = CableEndpoint(p, i, c.fl, c.fz, c.s0, g.w[i]);
    const T g0 = e.span_m - g.span[i];
    const T g1 = e.rise_m - g.rise[i];
    const double chord = ScalarValue(g.chord[i]);
    max_residual = std::max(max_residual,
                            std::max(std::abs(ScalarValue(g0)), std::abs(ScalarValue(g1))) / chord);
    const T n0 = e.drise[2], n1 = -e.dspan[2];
    const T cc = n0 * g0 + n1 * g1;
    const T pp = n0 * e.dspan[0] + n1 * e.drise[0];
    const T inv_qq = T(1) / (n0 * e.dspan[1] + n1 * e.drise[1]);  // one division, not two
    lin->a[i] = -pp * inv_qq;
    lin->b[i] = c.fz - cc * inv_qq - lin->a[i] * c.fl;
    lin->inv_qq[i] = inv_qq;
    lin->g0[i] = g0;
    lin->g1[i] = g1;
    lin->ends[i] = e;
  }
  lin->max_relative_residual = max_residual;
}

// The Newton step from a linearisation: the 6x6 equilibrium solve for Fl, then Fz on each
// cable's line and ds0 from its linearisation. Writes the largest |dFl| relative to the
// largest Fl when relative_step is not null, and for double the system's
// EquilibriumResponse when `response` is not null. Returns kNoEquilibrium when the step
// leaves a cable with Fl <= 0 or s0 <= 0 (the caller says what that means for its method).
template <typename T>
StaticsStatus StepFromLinearisation(const PoseGeometry<T>& g, const CableLinearisation<T>& lin,
                                    std::array<CableState<T>, kNumCables>* state, int* cable,
                                    double* relative_step,
                                    EquilibriumResponse* response = nullptr) {
  std::array<T, kNumCables> fl_new;
  bool solved;
  if constexpr (kIsDouble<T>) {
    solved = response != nullptr ? SolveEquilibrium<T, true>(g, lin.a, lin.b, &fl_new, response)
                                 : SolveEquilibrium(g, lin.a, lin.b, &fl_new);
  } else {
    solved = SolveEquilibrium(g, lin.a, lin.b, &fl_new);
  }
  if (!solved) return StaticsStatus::kSingular;
  double max_fl = 0.0, max_step = 0.0;
  for (int i = 0; i < kNumCables; ++i) {
    CableState<T>& c = (*state)[i];
    const CatenaryEnd<T>& e = lin.ends[i];
    const T dfl = fl_new[i] - c.fl;
    const T fz_new = lin.a[i] * fl_new[i] + lin.b[i];
    const T dfz = fz_new - c.fz;
    const T res0 = lin.g0[i] + e.dspan[0] * dfl + e.dspan[1] * dfz;
    const T res1 = lin.g1[i] + e.drise[0] * dfl + e.drise[1] * dfz;
    const T ds = -(e.dspan[2] * res0 + e.drise[2] * res1) /
                 (e.dspan[2] * e.dspan[2] + e.drise[2] * e.drise[2]);
    max_step = std::max(max_step, std::abs(ScalarValue(dfl)));
    max_fl = std::max(max_fl, std::abs(ScalarValue(fl_new[i])));
    c.fl = fl_new[i];
    c.fz = fz_new;
    c.s0 = c.s0 + ds;
  }
  for (int i = 0; i < kNumCables; ++i) {
    if (!(ScalarValue((*state)[i].fl) > 0.0) || !(ScalarValue((*state)[i].s0) > 0.0)) {
      *cable = i;
      return StaticsStatus::kNoEquilibrium;
    }
  }
  if (relative_step != nullptr) *relative_step = max_step / max_fl;
  return StaticsStatus::kOk;
}

// One Newton step on all 18 unknowns (LineariseCables, then StepFromLinearisation).
// Writes the largest end-point residual relative to the chord before the step when
// relative_residual is not null.
template <typename T>
StaticsStatus ReducedNewtonStep(const StaticsParameters<T>& p, const PoseGeometry<T>& g,
                                std::array<CableState<T>, kNumCables>* state, int* cable,
                                double* relative_step, double* relative_residual) {
  CableLinearisation<T> lin;
  LineariseCables(p, g, *state, &lin);
  if (relative_residual != nullptr) *relative_residual = lin.max_relative_residual;
  return StepFromLinearisation(g, lin, state, cable, relative_step);
}

// Guess for cable i's curve point at Fl from its secant data. Linear: s0 interpolated
// linearly in Fl between the two secant lengths, Fz on the secant line (5.8e-3 off in
// s0 over the workspace cap). Model-corrected: the parabolic model's point
// (ParabolicCatenaryModel) corrected by the model's error at the two secant points,
// interpolated linearly in Fl (6.7e-5 in s0, 1.4e-5 of the tension in Fz).
inline CatenaryCurvePoint CurveGuess(double fl, const PoseGeometry<double>& g, int i, double ea_n,
                                     const CatenaryForces& low, const CatenaryForces& high,
                                     const StaticsOptions& o, bool model_corrected) {
  const double t = (fl - low.fl_n) / (high.fl_n - low.fl_n);
  const double s_low = o.secant_low_fraction * g.chord[i];
  const double s_high = o.secant_high_fraction * g.chord[i];
  CatenaryCurvePoint c;
  if (model_corrected) {
    const ParabolicCatenaryModel model(g.span[i], g.rise[i], g.chord[i], ea_n, g.w[i]);
    const CatenaryCurvePoint m = model.AtHorizontalForce(fl);
    const CatenaryCurvePoint m_low = model.AtHorizontalForce(low.fl_n);
    const CatenaryCurvePoint m_high = model.AtHorizontalForce(high.fl_n);
    c.s0_m = m.s0_m + (1 - t) * (s_low - m_low.s0_m) + t * (s_high - m_high.s0_m);
    c.fz_n = m.fz_n + (1 - t) * (low.fz_n - m_low.fz_n) + t * (high.fz_n - m_high.fz_n);
  } else {
    c.s0_m = s_low + t * (s_high - s_low);
    c.fz_n = low.fz_n + t * (high.fz_n - low.fz_n);
  }
  c.s0_m = std::max(c.s0_m, 0.5 * s_low);
  return c;
}

}  // namespace internal

// Lower-end tensions |F_i| of the model at `pose`, in scalar T, for the calibration's
// residuals. For a Jet the derivatives are those of the chosen method's solution (see
// the file comment). `solution` (may be null) receives the double solution; `length_m`
// (may be null) the unstretched lengths s0_i, exact's with their derivatives (the other
// methods' without: a fit with lengths uses exact).
template <typename T>
StaticsStatus ModelLowerTensions(const StaticsParameters<T>& p, const Pose& pose,
                                 const StaticsOptions& options,
                                 std::array<T, kNumCables>* tension_n,
                                 StaticsSolution* solution = nullptr,
                                 std::array<T, kNumCables>* length_m = nullptr);

}  // namespace fastcal

#include "fastcal/internal/statics_jet.h"  // IWYU pragma: export

#endif  // FASTCAL_INTERNAL_STATICS_CORE_H_
