// The double-precision statics solvers (equations and methods: statics.h).
#include "fastcal/statics.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace fastcal {
namespace {

bool ParametersUsable(const StaticsParameters<double>& p) {
  for (int i = 0; i < kNumCables; ++i) {
    if (!p.tower_top_m[i].allFinite() || !p.anchor_cabin_m[i].allFinite()) return false;
    if (!(p.ea_n[i] > 0.0) || !std::isfinite(p.ea_n[i])) return false;
    if (!(p.linear_density_kg_per_m[i] > 0.0) || !std::isfinite(p.linear_density_kg_per_m[i])) {
      return false;
    }
  }
  return p.cabin_mass_kg > 0.0 && std::isfinite(p.cabin_mass_kg) &&
         p.mass_centre_cabin_m.allFinite() && p.gravity_m_per_s2 < 0.0 &&
         std::isfinite(p.gravity_m_per_s2);
}

// Tensions of each cable's ends (CheckModelRange computes them, FillSolution reports them).
struct EndTensions {
  std::array<double, kNumCables> lower_n, upper_n;
};

void FillSolution(const internal::PoseGeometry<double>& g,
                  const std::array<internal::CableState<double>, kNumCables>& st,
                  const EndTensions& tensions, const std::array<CatenaryForces, kNumCables>& low,
                  const std::array<CatenaryForces, kNumCables>& high, StaticsSolution* sol) {
  Eigen::Vector3d force_sum = Eigen::Vector3d::Zero(), moment_sum = Eigen::Vector3d::Zero();
  for (int i = 0; i < kNumCables; ++i) {
    CableSolution& c = sol->cables[i];
    c.horizontal_force_n = st[i].fl;
    c.force_n = Eigen::Vector3d(-g.ux[i] * st[i].fl, -g.uy[i] * st[i].fl, st[i].fz);
    c.lower_tension_n = tensions.lower_n[i];
    c.unstretched_length_m = st[i].s0;
    c.upper_tension_n = tensions.upper_n[i];
    c.chord_length_m = g.chord[i];
    c.secant_low = low[i];
    c.secant_high = high[i];
    force_sum -= c.force_n;
    moment_sum -= g.r[i].cross(c.force_n);
  }
  const Eigen::Vector3d weight(0.0, 0.0, g.weight_n);
  force_sum += weight;
  moment_sum += g.e.cross(weight);
  sol->force_residual_n = force_sum.norm();
  sol->moment_residual_nm = moment_sum.norm();
}

// The model-range limits of StaticsOptions, on the finished solution: s0 in
// (0, max_length_ratio k] (when computed: AAS may skip it), then every cable's lower and
// upper tension within max_strain EA. Writes the tensions (upper 0 without s0).
StaticsStatus CheckModelRange(const StaticsParameters<double>& p,
                              const internal::PoseGeometry<double>& g,
                              const std::array<internal::CableState<double>, kNumCables>& st,
                              bool have_lengths, const StaticsOptions& o, EndTensions* tensions,
                              int* cable) {
  for (int i = 0; i < kNumCables; ++i) {
    const double lower_n = std::sqrt(st[i].fl * st[i].fl + st[i].fz * st[i].fz);
    double upper_n = lower_n;
    tensions->lower_n[i] = lower_n;
    tensions->upper_n[i] = 0.0;
    if (have_lengths) {
      const double s0_m = st[i].s0;
      if (s0_m > o.max_length_ratio * g.chord[i]) {
        *cable = i;
        return StaticsStatus::kSlackCable;
      }
      if (!(s0_m > 0.0)) {
        *cable = i;
        return StaticsStatus::kOverstretchedCable;
      }
      upper_n = CatenaryTension(st[i].fl, st[i].fz, s0_m, g.w[i]);
      tensions->upper_n[i] = upper_n;
    }
    if (!(std::max(lower_n, upper_n) <= o.max_strain * p.ea_n[i])) {
      *cable = i;
      return StaticsStatus::kOverstretchedCable;
    }
  }
  return StaticsStatus::kOk;
}

StaticsStatus Attempt(const StaticsParameters<double>& p, const Pose& pose, const StaticsOptions& o,
                      const StaticsSolution* previous, StaticsSolution* sol) {
  using internal::CableState;
  // sol->cables is left as it is: FillSolution writes all of it on success, and
  // SolveStaticsWithParameters zeroes it on failure.
  sol->cable = -1;
  sol->outer_iterations = 0;
  sol->catenary_iterations = 0;
  sol->force_residual_n = 0.0;
  sol->moment_residual_nm = 0.0;
  if (!IsFinite(pose) || !ParametersUsable(p)) return StaticsStatus::kInvalidInput;

  internal::PoseGeometry<double> g;
  StaticsStatus status =
      internal::ComputeGeometry(p, pose, o.catenary.vertical_span_fraction, &g, &sol->cable);
  if (status != StaticsStatus::kOk) return status;

  std::array<CatenaryForces, kNumCables> low{}, high{};
  std::array<CableState<double>, kNumCables> st;
  bool have_state = false;
  if (previous != nullptr) {
    for (int i = 0; i < kNumCables; ++i) {
      low[i] = previous->cables[i].secant_low;
      high[i] = previous->cables[i].secant_high;
    }
    if (o.method == StaticsMethod::kExact) {
      for (int i = 0; i < kNumCables; ++i) {
        const CableSolution& c = previous->cables[i];
        st[i] = {c.horizontal_force_n, c.force_n[2], c.unstretched_length_m};
      }
      have_state = true;
    }
  }

  int* cable = &sol->cable;
  int* its = &sol->catenary_iterations;
  if (!have_state) {
    const StaticsOptions so = internal::AasLengthStageOptions(o);
    std::array<double, kNumCables> a, b, fl;
    status = internal::AasLines(p, g, o, previous != nullptr, &low, &high, &a, &b, cable, its);
    if (status != StaticsStatus::kOk) return status;
    if (!internal::SolveEquilibrium(g, a, b, &fl)) return StaticsStatus::kSingular;
    for (int i = 0; i < kNumCables; ++i) {
      if (!(fl[i] > 0.0)) {
        *cable = i;
        return StaticsStatus::kSlackCable;
      }
      st[i] = {fl[i], a[i] * fl[i] + b[i], 0.0};
    }
    const int projections = o.method == StaticsMethod::kAasRefined ? o.refinement_steps
                            : o.method == StaticsMethod::kExact    ? 1
                            : o.compute_unstretched_lengths        ? 1
                                                                   : 0;
    for (int step = 0; step < projections; ++step) {
      std::array<CatenaryCurvePoint, kNumCables> guess;
      for (int i = 0; i < kNumCables; ++i) {
        guess[i] = internal::CurveGuess(st[i].fl, g, i, p.ea_n[i], low[i], high[i], o,
                                        /*model_corrected=*/o.method != StaticsMethod::kExact);
      }
      std::array<CableState<double>, kNumCables> projected = st;
      status = internal::ProjectOnCurves(p, g, so, guess, &projected, cable, its);
      if (status != StaticsStatus::kOk) return status;
      if (o.method == StaticsMethod::kAas) {
        // AAS keeps Fz on its secant line (which satisfies equilibrium); s0 is the length
        // that yields Fl.
        for (int i = 0; i < kNumCables; ++i) st[i].s0 = projected[i].s0;
      } else {
        st = projected;
      }
      if (o.method == StaticsMethod::kAasRefined) {
        status = internal::ReducedNewtonStep(p, g, &st, cable, nullptr, nullptr);
        if (status != StaticsStatus::kOk) return status;
        ++sol->outer_iterations;
      }
    }
  }

  if (o.method == StaticsMethod::kExact) {
    bool converged = false;
    for (int it = 0; it < o.exact_max_iterations && !converged; ++it) {
      double relative_step = 0.0, relative_residual = 0.0;
      status = internal::ReducedNewtonStep(p, g, &st, cable, &relative_step, &relative_residual);
      if (status != StaticsStatus::kOk) return status;
      ++sol->outer_iterations;
      // Newton converges quadratically: a step of relative size d leaves an error of
      // order d^2, so the tolerance is met once d <= sqrt(tolerance) and the end
      // conditions held to the same order before the step.
      const double step_bound = std::sqrt(o.exact_relative_tolerance);
      converged = relative_step <= step_bound && relative_residual <= step_bound;
    }
    if (!converged) return StaticsStatus::kNotConverged;
  }
  const bool have_lengths = o.method != StaticsMethod::kAas || o.compute_unstretched_lengths;
  EndTensions tensions;
  status = CheckModelRange(p, g, st, have_lengths, o, &tensions, cable);
  if (status != StaticsStatus::kOk) return status;
  FillSolution(g, st, tensions, low, high, sol);
  return StaticsStatus::kOk;
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
      return "invalid input";
    case StaticsStatus::kVerticalCable:
      return "vertical cable";
    case StaticsStatus::kSlackCable:
      return "slack cable";
    case StaticsStatus::kSingular:
      return "singular";
    case StaticsStatus::kCatenaryFailed:
      return "catenary not converged";
    case StaticsStatus::kNotConverged:
      return "not converged";
    case StaticsStatus::kOverstretchedCable:
      return "overstretched cable";
  }
  return "unknown";
}

namespace {

// Which rule of StaticsOptions::IsValid `o` breaks first (kNone: none). Separate from the
// message so that SolveStatics can check without allocating.
enum class OptionsRule {
  kNone,
  kSecants,
  kRefinementSteps,
  kExactTolerance,
  kStartTolerance,
  kModelRange,
  kExactIterations,
  kCatenary
};

OptionsRule BrokenRule(const StaticsOptions& o) {
  if (!(o.secant_low_fraction > 0.0) || !(o.secant_high_fraction > o.secant_low_fraction) ||
      !std::isfinite(o.secant_high_fraction)) {
    return OptionsRule::kSecants;
  }
  if (o.refinement_steps < 1) return OptionsRule::kRefinementSteps;
  if (!(o.exact_relative_tolerance > 0.0)) return OptionsRule::kExactTolerance;
  if (!(o.exact_start_catenary_tolerance > 0.0) || !(o.aas_secant_tolerance > 0.0) ||
      !(o.aas_length_tolerance > 0.0)) {
    return OptionsRule::kStartTolerance;
  }
  if (!(o.max_strain > 0.0) || !(o.max_length_ratio > 1.0)) return OptionsRule::kModelRange;
  if (o.exact_max_iterations < 1) return OptionsRule::kExactIterations;
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
    case OptionsRule::kRefinementSteps:
      e << "refinement_steps must be >= 1 (got " << refinement_steps << ")";
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
    case OptionsRule::kExactIterations:
      e << "exact_max_iterations must be >= 1 (got " << exact_max_iterations << ")";
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
  o.compute_unstretched_lengths = false;
  o.aas_secant_tolerance = o.catenary.relative_tolerance;
  o.aas_length_tolerance = o.catenary.relative_tolerance;
  return o;
}

StaticsParameters<double> MakeStaticsParameters(const CableRobot& robot) {
  StaticsParameters<double> p;
  for (int i = 0; i < kNumCables; ++i) {
    p.tower_top_m[i] = robot.cables[i].tower_top_m;
    p.anchor_cabin_m[i] = robot.AnchorOfCable(i);
    p.ea_n[i] = robot.cables[i].ea_n;
    p.linear_density_kg_per_m[i] = robot.cables[i].linear_density_kg_per_m;
  }
  p.cabin_mass_kg = robot.cabin_mass_kg;
  p.mass_centre_cabin_m = robot.mass_centre_cabin_m;
  p.gravity_m_per_s2 = robot.gravity_m_per_s2;
  return p;
}

StaticsStatus SolveStaticsWithParameters(const StaticsParameters<double>& parameters,
                                         const Pose& pose, const StaticsOptions& options,
                                         StaticsSolution* solution) {
  if (BrokenRule(options) != OptionsRule::kNone) {
    // Invalid options are invalid input (StaticsOptions::IsValid says which).
    const StaticsStatus status = solution->status = StaticsStatus::kInvalidInput;
    solution->cables = {};
    solution->cable = -1;
    return status;
  }
  const bool warm = options.warm_start && solution->status == StaticsStatus::kOk;
  StaticsSolution previous;
  if (warm) previous = *solution;
  StaticsStatus status = Attempt(parameters, pose, options, warm ? &previous : nullptr, solution);
  if (status != StaticsStatus::kOk && warm) {
    status = Attempt(parameters, pose, options, nullptr, solution);
  }
  if (status != StaticsStatus::kOk) {
    const int cable = solution->cable;
    solution->cables = {};
    solution->cable = cable;
  }
  solution->status = status;
  return status;
}

StaticsStatus SolveStatics(const CableRobot& robot, const Pose& pose, const StaticsOptions& options,
                           StaticsSolution* solution) {
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
  return SolveStaticsWithParameters(MakeStaticsParameters(robot), pose, options, solution);
}

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
    case StaticsStatus::kSlackCable:
      s << "cable " << c
        << " would be slack (horizontal force <= 0, or an unstretched length over 1.5 times "
           "its chord, StaticsOptions::max_length_ratio): the pose cannot be held with taut "
           "cables";
      break;
    case StaticsStatus::kSingular:
      s << "the equilibrium equations are singular at this pose";
      break;
    case StaticsStatus::kCatenaryFailed:
      s << "the catenary of cable " << c << " did not converge";
      break;
    case StaticsStatus::kNotConverged:
      s << "the exact solver did not converge";
      break;
    case StaticsStatus::kOverstretchedCable:
      s << "cable " << c
        << " would be stretched beyond the model's elastic range (strain over 5%, "
           "StaticsOptions::max_strain, or an unstretched length <= 0): the pose cannot be held "
           "as modelled";
      break;
  }
  return s.str();
}

}  // namespace fastcal
