// The forward statics solver (locate.h; equations: fastcal/internal/forward_statics.h,
// docs/model.md "Forward statics"): damped Newton on the 24 unknowns, its warm start along
// the lengths' sensitivity, the continuation from the home pose, the stability of the
// answer (eigenvalues of the potential's Hessian, lengths held; Briot and Merlet), the
// search for other equilibria along its modes, and the checks.
//
// Continuation in the lengths, s0(t) = s0_home + t (s0 - s0_home), t from 0 to 1: each
// point is predicted along the path's tangent, dx/dt = -K^-1 G ds0/dt (forward_statics.h),
// then corrected by Newton; a point that fails halves the step along the path, one that
// converges doubles it (Allgower and Georg, "Introduction to Numerical Continuation
// Methods", ch. 2: predictor-corrector).
#include "fastcal/locate.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "fastcal/internal/forward_statics.h"
#include "fastcal/internal/number_text.h"

namespace fastcal {
namespace {

// The check's tolerance when it only asks whether an answer that failed on rounding lies
// outside the model's range (Finish).
constexpr double kLooseRelativeTolerance = 1e-8;

using internal::ForwardLinearisation;
using internal::ForwardScales;
using internal::ForwardState;
using internal::HomePose;
using internal::Lengths;
using internal::Matrix6d;
using internal::Vector6d;
using Forces = std::array<Eigen::Vector3d, kNumCables>;

// A step may shrink a cable's horizontal force (its projection on the old one) to no less
// than this fraction: a horizontal force through zero leaves the cable's plane undefined.
constexpr double kMinHorizontalForceFraction = 0.25;
// A step turns the cabin by at most this (rad), and moves it by at most this fraction of
// the shortest chord: Newton from a poor start would otherwise leap out of the workspace.
constexpr double kMaxTurnRad = 0.25;
constexpr double kMaxMoveFraction = 0.05;
// A step whose merit (ForwardLinearisation::merit) does not decrease is halved, at most
// this many times.
constexpr int kMaxHalvings = 12;
// Steps this small (m) are taken without the merit test (near the answer the merit sits at
// its rounding floor, where a correct Newton step need not decrease it), and only one this
// small may be the last, taken without evaluating the state after it.
constexpr double kLastStepM = 1e-6;
// Newton's error after a step of size d is about C d^2: C <= 1.3 per metre measured on the
// focal-sphere cap (warm and along the continuation), 2 used.
constexpr double kNewtonContractionPerM = 2.0;
// A point of the continuation is solved to this (m): it only starts the next point.
constexpr double kPathPointToleranceM = 1e-6;
// The continuation's first step along the path (the whole of it: the tangent predictor
// often reaches the lengths in one), the smallest before it gives up, and the Newton
// iterations per point before the step is halved.
constexpr double kFirstPathStep = 1.0;
constexpr double kMinPathStep = 1e-3;
constexpr int kPathPointIterations = 8;

// What the stages of one solve share.
struct Solver {
  const StaticsParameters<double>& p;
  ForwardScales scales;
  const LocateOptions& o;
  int* iterations;
  double shortest_chord_m = std::numeric_limits<double>::infinity();
};

// The largest fraction of a Newton step that keeps every cable's horizontal force on its
// side (kMinHorizontalForceFraction) and the move within kMaxTurnRad and kMaxMoveFraction.
double StepLimit(const Solver& s, const ForwardState& x, const Vector6d& dx, const Forces& df) {
  double fraction = 1.0;
  for (int i = 0; i < kNumCables; ++i) {
    const Eigen::Vector2d fh = x.force_n[i].head<2>();
    const double along = df[i].head<2>().dot(fh);
    if (along < 0.0) {
      fraction =
          std::min(fraction, (1.0 - kMinHorizontalForceFraction) * fh.squaredNorm() / -along);
    }
  }
  const double turn = dx.tail<3>().norm(), move = dx.head<3>().norm();
  if (turn > kMaxTurnRad) fraction = std::min(fraction, kMaxTurnRad / turn);
  const double max_move = kMaxMoveFraction * s.shortest_chord_m;
  if (move > max_move) fraction = std::min(fraction, max_move / move);
  return fraction;
}

// Damped Newton from *x for lengths s0, *lin the linearisation at *x (in) and at the last
// iterate before the answer (out: its stiffness and sensitivities are the answer's to
// within kLastStepM), until the error left, kNewtonContractionPerM d^2 after a step of size
// d, is at most tolerance_m (*estimate_m: that error); false after max_iterations steps, or
// where a step cannot be taken.
bool Newton(const Solver& s, const Lengths& s0, int max_iterations, double tolerance_m,
            ForwardState* x, ForwardLinearisation* lin, double* estimate_m) {
  ForwardLinearisation trial_lin;
  for (int it = 0;; ++it) {
    Vector6d dx;
    Forces df;
    if (!internal::ForwardNewtonStep(*lin, &dx, &df)) return false;
    const double step = internal::StepSizeM(dx, s.scales.size_m);
    const double left = kNewtonContractionPerM * step * step;
    if (step <= kLastStepM && left <= tolerance_m) {
      *x = internal::MoveState(*x, dx, df, 1.0);  // no evaluation after it: the check's
      *estimate_m = left;
      return true;
    }
    if (it >= max_iterations) return false;
    ++*s.iterations;
    double fraction = StepLimit(s, *x, dx, df);
    bool accepted = false;
    ForwardState trial;
    for (int h = 0; h <= kMaxHalvings && !accepted; ++h, fraction *= 0.5) {
      trial = internal::MoveState(*x, dx, df, fraction);
      accepted = internal::LineariseForward(s.p, s.scales, s0, trial, &trial_lin) &&
                 (fraction * step <= kLastStepM || trial_lin.merit < lin->merit);
    }
    if (!accepted) return false;
    *x = trial;
    *lin = trial_lin;
  }
}

// The answer moved by the lengths' change ds0 to first order (dx/ds0, dF/ds0).
ForwardState Predict(const ForwardState& x, const Matrix6d& pose_per_length,
                     const Eigen::Matrix<double, 3 * kNumCables, kNumCables>& force_per_length,
                     const Eigen::Matrix<double, kNumCables, 1>& ds0) {
  const Vector6d dx = pose_per_length * ds0;
  const Eigen::Matrix<double, 3 * kNumCables, 1> df = force_per_length * ds0;
  Forces dforce;
  for (int i = 0; i < kNumCables; ++i) dforce[i] = df.segment<3>(3 * i);
  return internal::MoveState(x, dx, dforce, 1.0);
}

Eigen::Matrix<double, kNumCables, 1> Difference(const Lengths& to, const Lengths& from) {
  Eigen::Matrix<double, kNumCables, 1> d;
  for (int i = 0; i < kNumCables; ++i) d[i] = to[i] - from[i];
  return d;
}

// The home pose's equilibrium and lengths (the inverse statics, its model range relaxed:
// the path only starts there).
bool HomeState(const Solver& s, ForwardState* x, Lengths* s0) {
  StaticsOptions o = s.o.statics;
  o.method = StaticsMethod::kExact;
  o.warm_start = false;
  o.max_strain = o.max_length_ratio = std::numeric_limits<double>::infinity();
  o.min_reflector_clearance_m = -std::numeric_limits<double>::max();
  StaticsSolution home;
  x->pose = HomePose(s.p);
  if (SolveStaticsWithParameters(s.p, x->pose, o, &home) != StaticsStatus::kOk) return false;
  for (int i = 0; i < kNumCables; ++i) {
    x->force_n[i] = home.cables[i].force_n;
    (*s0)[i] = home.cables[i].unstretched_length_m;
  }
  return true;
}

// The cable whose length is largest against its chord at a state, and that ratio: the
// slackest, named where the continuation ends.
int SlackestCable(const Lengths& s0, const ForwardLinearisation& lin, double* ratio) {
  int worst = 0;
  *ratio = 0.0;
  for (int i = 0; i < kNumCables; ++i) {
    if (s0[i] / lin.chord_m[i] > *ratio) {
      *ratio = s0[i] / lin.chord_m[i];
      worst = i;
    }
  }
  return worst;
}

// The continuation from the home pose to lengths `target` (file comment). kOk with *x
// and *lin at the answer (to tolerance_m, *estimate_m), kNoEquilibrium where the path ends
// (sol->statics.cable: the slackest cable there, limit_value its s0/k), kNotConverged when
// the iterations run out or the home pose has no equilibrium.
StaticsStatus FollowFromHome(const Solver& s, const Lengths& target, ForwardState* x,
                             ForwardLinearisation* lin, double* estimate_m, LocateSolution* sol) {
  Lengths home;
  if (!HomeState(s, x, &home) || !internal::LineariseForward(s.p, s.scales, home, *x, lin)) {
    return StaticsStatus::kNotConverged;
  }
  const int start = *s.iterations;
  auto lengths_at = [&](double t) {
    Lengths l;
    for (int i = 0; i < kNumCables; ++i) l[i] = home[i] + t * (target[i] - home[i]);
    return l;
  };
  double t = 0.0, dt = kFirstPathStep;
  ForwardLinearisation trial_lin;
  while (t < 1.0) {
    const int left = s.o.max_continuation_iterations - (*s.iterations - start);
    if (left <= 0) return StaticsStatus::kNotConverged;
    const double t_next = std::min(1.0, t + dt);
    const Lengths from = lengths_at(t), to = lengths_at(t_next);
    Matrix6d pose_per_length;
    Eigen::Matrix<double, 3 * kNumCables, kNumCables> force_per_length;
    ForwardState trial = *x;
    if (internal::LengthSensitivity(*lin, &pose_per_length, &force_per_length)) {
      trial = Predict(*x, pose_per_length, force_per_length, Difference(to, from));
    }
    const bool last = t_next >= 1.0;
    const bool solved =
        internal::LineariseForward(s.p, s.scales, to, trial, &trial_lin) &&
        Newton(s, to, std::min(last ? s.o.max_iterations : kPathPointIterations, left),
               last ? s.o.tolerance_m : kPathPointToleranceM, &trial, &trial_lin, estimate_m);
    if (solved) {
      *x = trial;
      *lin = trial_lin;
      t = t_next;
      dt *= 2.0;
    } else if ((dt *= 0.5) < kMinPathStep) {
      sol->statics.cable = SlackestCable(lengths_at(t), *lin, &sol->statics.limit_value);
      return StaticsStatus::kNoEquilibrium;
    }
  }
  return StaticsStatus::kOk;
}

// The scaled, symmetrised Hessian of the potential (LocateSolution::stiffness) and its
// eigen-decomposition into *sol; `modes` receives the eigenvectors (may be null).
void JudgeStability(const ForwardLinearisation& lin, double size_m, double marginal_fraction,
                    Stability* stability, int* unstable_modes, double* min_stiffness,
                    Matrix6d* stiffness, Matrix6d* modes) {
  Vector6d scale;
  scale << 1.0, 1.0, 1.0, 1.0 / size_m, 1.0 / size_m, 1.0 / size_m;
  const Matrix6d h = -(scale.asDiagonal() * lin.stiffness * scale.asDiagonal());
  *stiffness = 0.5 * (h + h.transpose());
  Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(
      *stiffness, modes != nullptr ? Eigen::ComputeEigenvectors : Eigen::EigenvaluesOnly);
  const Vector6d& values = eigen.eigenvalues();  // ascending
  const double zero = marginal_fraction * std::max(std::abs(values[0]), std::abs(values[5]));
  *min_stiffness = values[0];
  *unstable_modes = 0;
  for (int k = 0; k < 6; ++k) *unstable_modes += values[k] < -zero ? 1 : 0;
  *stability = *unstable_modes > 0           ? Stability::kUnstable
               : std::abs(values[0]) <= zero ? Stability::kMarginal
                                             : Stability::kStable;
  if (modes != nullptr) *modes = eigen.eigenvectors();
}

// The anchors' largest move from pose a to pose b.
double AnchorsMoveM(const StaticsParameters<double>& p, const Pose& a, const Pose& b) {
  double largest = (a.position_m - b.position_m).norm();
  for (const Eigen::Vector3d& anchor : p.anchor_cabin_m) {
    const Eigen::Vector3d d =
        (a.rotation * anchor + a.position_m) - (b.rotation * anchor + b.position_m);
    largest = std::max(largest, d.norm());
  }
  return largest;
}

// Each cable's (Fl, Fz, s0) at a state, for the inverse statics' check.
std::array<internal::CableState<double>, kNumCables> CableStates(const ForwardState& x,
                                                                 const Lengths& s0) {
  std::array<internal::CableState<double>, kNumCables> st;
  for (int i = 0; i < kNumCables; ++i) {
    st[i] = {x.force_n[i].head<2>().norm(), x.force_n[i].z(), s0[i]};
  }
  return st;
}

// Newton from starts displaced by search_radius_m along each of the answer's modes, both
// ways; the distinct equilibria found are counted, the nearest kept (locate.h).
void SearchOtherEquilibria(const Solver& s, const Lengths& s0, const ForwardState& answer,
                           const Matrix6d& modes, LocateSolution* sol) {
  sol->searched = true;
  std::array<Pose, 12> found;
  int n = 0;
  ForwardLinearisation lin;
  for (int k = 0; k < 6; ++k) {
    for (double sign : {1.0, -1.0}) {
      Vector6d dx = sign * s.o.search_radius_m * modes.col(k);
      dx.tail<3>() /= s.scales.size_m;
      ForwardState x;
      x.pose = internal::MoveState(answer, dx, internal::ZeroForces(), 1.0).pose;
      double estimate = 0.0;
      if (!internal::ClosedForcesAt(s.p, s0, x.pose, &x.force_n) ||
          !internal::LineariseForward(s.p, s.scales, s0, x, &lin) ||
          !Newton(s, s0, s.o.max_iterations, s.o.tolerance_m, &x, &lin, &estimate)) {
        continue;
      }
      const double distance = AnchorsMoveM(s.p, x.pose, answer.pose);
      bool seen = distance <= s.o.distinct_m;
      for (int j = 0; j < n && !seen; ++j) {
        seen = AnchorsMoveM(s.p, x.pose, found[j]) <= s.o.distinct_m;
      }
      if (seen) continue;
      found[n++] = x.pose;
      if (sol->other_equilibria++ > 0 && distance >= sol->nearest_other.distance_m) continue;
      OtherEquilibrium& other = sol->nearest_other;
      other.pose = x.pose;
      other.distance_m = distance;
      int unstable = 0;
      double min_stiffness = 0.0;
      Matrix6d unused;
      JudgeStability(lin, s.scales.size_m, s.o.marginal_stiffness_fraction, &other.stability,
                     &unstable, &min_stiffness, &unused, nullptr);
      StaticsSolution check;
      other.status = CheckStaticsState(s.p, x.pose, CableStates(x, s0), s.o.statics, &check);
    }
  }
}

// A converged state: checked (CheckStaticsState), judged, written into *sol.
StaticsStatus Finish(const Solver& s, const Lengths& s0, const ForwardState& x,
                     const ForwardLinearisation& lin, double estimate_m, LocateSolution* sol) {
  const StaticsStatus status =
      CheckStaticsState(s.p, x.pose, CableStates(x, s0), s.o.statics, &sol->statics);
  if (status == StaticsStatus::kNotConverged && sol->statics.limit > 0.0) {
    // Far outside the model's range (a cable stretched by 50%) rounding alone can lift the
    // error estimate above its 1e-12: the range is then the reason to give, not the digits.
    StaticsOptions loose = s.o.statics;
    loose.exact_relative_tolerance = kLooseRelativeTolerance;
    StaticsSolution range;
    const StaticsStatus why = CheckStaticsState(s.p, x.pose, CableStates(x, s0), loose, &range);
    if (why != StaticsStatus::kOk && why != StaticsStatus::kNotConverged) {
      sol->statics = range;
      return why;
    }
  }
  if (status != StaticsStatus::kOk) return status;
  sol->pose = x.pose;
  sol->force_n = x.force_n;
  sol->error_estimate_m = estimate_m;
  internal::LengthSensitivity(lin, &sol->pose_per_length, &sol->force_per_length);
  Matrix6d modes;
  const bool search = s.o.search_radius_m > 0.0;
  JudgeStability(lin, s.scales.size_m, s.o.marginal_stiffness_fraction, &sol->stability,
                 &sol->unstable_modes, &sol->min_stiffness_n_per_m, &sol->stiffness,
                 search ? &modes : nullptr);
  if (search) SearchOtherEquilibria(s, s0, x, modes, sol);
  return StaticsStatus::kOk;
}

bool LengthsUsable(const Lengths& s0) {
  for (double l : s0) {
    if (!(l > 0.0) || !std::isfinite(l)) return false;
  }
  return true;
}

bool AnchorsIndexed(const CableRobot& robot) {
  for (const CableProperties& c : robot.cables) {
    if (c.anchor_index < 0 ||
        c.anchor_index >= static_cast<int>(robot.anchor_points_cabin_m.size())) {
      return false;
    }
  }
  return true;
}

// The warm start: the previous answer moved to the new lengths (before *sol is reset).
ForwardState WarmStart(const LocateSolution& previous, const Lengths& s0) {
  ForwardState x;
  x.pose = previous.pose;
  x.force_n = previous.force_n;
  return Predict(x, previous.pose_per_length, previous.force_per_length,
                 Difference(s0, previous.unstretched_length_m));
}

}  // namespace

void ResetLocateSolution(const Lengths& s0, LocateSolution* sol) {
  sol->pose = Pose();
  sol->statics = StaticsSolution();
  sol->unstretched_length_m = s0;
  sol->iterations = 0;
  sol->continuation = false;
  sol->error_estimate_m = 0.0;
  sol->stability = Stability::kUnknown;
  sol->unstable_modes = 0;
  sol->min_stiffness_n_per_m = 0.0;
  sol->stiffness.setZero();
  sol->pose_per_length.setZero();
  sol->searched = false;
  sol->other_equilibria = 0;
  sol->nearest_other = OtherEquilibrium();
  sol->fit = LocateFit();
  sol->force_n = internal::ZeroForces();
  sol->force_per_length.setZero();
}

namespace {

// `value` to 3 (or 6) significant digits, for messages; '.' in every locale.
std::string Sig(double value) { return internal::FormatDouble("%.3g", value); }
std::string Sig6(double value) { return internal::FormatDouble("%.6g", value); }

}  // namespace

const char* StabilityName(Stability stability) {
  switch (stability) {
    case Stability::kUnknown:
      return "unknown";
    case Stability::kStable:
      return "stable";
    case Stability::kUnstable:
      return "unstable";
    case Stability::kMarginal:
      return "marginal";
  }
  return "unknown";
}

bool LocateOptions::IsValid(std::string* error) const {
  std::string e;
  if (!(tolerance_m > 0.0) || !std::isfinite(tolerance_m)) {
    e = "tolerance_m must be > 0 and finite (got " + Sig(tolerance_m) + ")";
  } else if (max_iterations < 1 || max_continuation_iterations < 1) {
    e = "max_iterations and max_continuation_iterations must be >= 1 (got " +
        std::to_string(max_iterations) + ", " + std::to_string(max_continuation_iterations) + ")";
  } else if (!(marginal_stiffness_fraction >= 0.0 && marginal_stiffness_fraction < 1.0)) {
    e = "marginal_stiffness_fraction must be in [0, 1) (got " + Sig(marginal_stiffness_fraction) +
        ")";
  } else if (!(search_radius_m >= 0.0) || !std::isfinite(search_radius_m)) {
    e = "search_radius_m must be >= 0 and finite (got " + Sig(search_radius_m) + ")";
  } else if (!(distinct_m > 0.0) || !std::isfinite(distinct_m)) {
    e = "distinct_m must be > 0 and finite (got " + Sig(distinct_m) + ")";
  } else if (!statics.IsValid(&e)) {
    e = "statics: " + e;
  }
  if (e.empty()) return true;
  if (error != nullptr) *error = e;
  return false;
}

StaticsStatus Locate(const CableRobot& robot,
                     const std::array<double, kNumCables>& unstretched_length_m,
                     const LocateOptions& options, LocateSolution* solution) {
  const bool warm = options.warm_start && solution->status == StaticsStatus::kOk;
  ForwardState x;
  if (warm) x = WarmStart(*solution, unstretched_length_m);
  ResetLocateSolution(unstretched_length_m, solution);
  if (!options.IsValid(nullptr) || !AnchorsIndexed(robot) || !LengthsUsable(unstretched_length_m)) {
    return solution->status = solution->statics.status = StaticsStatus::kInvalidInput;
  }
  const StaticsParameters<double> p = MakeStaticsParameters(robot);
  int iterations = 0;
  Solver s{p, internal::MakeForwardScales(p), options, &iterations};
  s.shortest_chord_m = *std::min_element(unstretched_length_m.begin(), unstretched_length_m.end());
  ForwardLinearisation lin;
  double estimate_m = 0.0;
  StaticsStatus status = StaticsStatus::kNotConverged;
  if (warm && internal::LineariseForward(p, s.scales, unstretched_length_m, x, &lin) &&
      Newton(s, unstretched_length_m, options.max_iterations, options.tolerance_m, &x, &lin,
             &estimate_m)) {
    status = Finish(s, unstretched_length_m, x, lin, estimate_m, solution);
  }
  if (status != StaticsStatus::kOk) {
    ResetLocateSolution(unstretched_length_m, solution);
    solution->continuation = true;
    status = FollowFromHome(s, unstretched_length_m, &x, &lin, &estimate_m, solution);
    if (status == StaticsStatus::kOk) {
      status = Finish(s, unstretched_length_m, x, lin, estimate_m, solution);
    }
  }
  solution->iterations = iterations;
  if (status != StaticsStatus::kOk) {
    solution->pose = Pose();
    solution->force_n = internal::ZeroForces();
    solution->statics.cables = {};
    solution->stability = Stability::kUnknown;
    solution->statics.status = status;
  }
  return solution->status = status;
}

std::string DescribeLocateStatus(const LocateSolution& solution) {
  std::ostringstream s;
  const StaticsSolution& st = solution.statics;
  switch (solution.status) {
    case StaticsStatus::kOk:
      s << "ok, " << StabilityName(solution.stability);
      if (solution.stability == Stability::kUnstable) {
        s << ": the potential's stiffness has " << solution.unstable_modes
          << " negative mode(s), the softest " << Sig(solution.min_stiffness_n_per_m)
          << " N/m; a small push moves the cabin away from this pose";
      } else if (solution.stability == Stability::kMarginal) {
        s << ": the potential's stiffness is singular (smallest eigenvalue "
          << Sig(solution.min_stiffness_n_per_m)
          << " N/m): a fold, where two equilibria of these lengths meet";
      }
      if (solution.other_equilibria > 0) {
        const OtherEquilibrium& o = solution.nearest_other;
        s << "; not unique: " << solution.other_equilibria << " other equilibri"
          << (solution.other_equilibria > 1 ? "a" : "um")
          << " of these lengths found nearby, the nearest " << Sig(o.distance_m)
          << " m away (anchors' move), " << StabilityName(o.stability) << ", at ("
          << Sig6(o.pose.position_m.x()) << ", " << Sig6(o.pose.position_m.y()) << ", "
          << Sig6(o.pose.position_m.z()) << ") m";
        if (o.status != StaticsStatus::kOk) s << " (" << StaticsStatusName(o.status) << ")";
      }
      break;
    case StaticsStatus::kInvalidInput:
      s << "invalid input: a length is not finite or not positive, or the model or the "
           "options are invalid (LocateOptions::IsValid says which)";
      break;
    case StaticsStatus::kNoEquilibrium:
      s << "no equilibrium with taut cables reached from the home pose: as the lengths move "
           "from the home pose's to these, the equilibrium ends before them (a fold, or a "
           "cable going slack";
      if (st.cable >= 0) {
        s << "; cable " << st.cable + 1
          << " then had s0/k = " << internal::FormatDouble("%.4g", st.limit_value);
      }
      s << ")";
      break;
    case StaticsStatus::kNotConverged:
      if (st.limit > 0.0) {
        s << "the forward solution failed its check: error estimate " << Sig(st.limit_value)
          << " > " << Sig(st.limit) << " (StaticsOptions::exact_relative_tolerance)";
      } else {
        s << "the forward solver did not converge within its iteration limits "
             "(LocateOptions::max_iterations, max_continuation_iterations)";
      }
      break;
    default:
      s << "the equilibrium at these lengths: " << DescribeStatus(st);
      break;
  }
  return s.str();
}

}  // namespace fastcal
