// The plausible range of a survey design and the test of a pose over it
// (internal/design_range.h; the rule: design.h and docs/design.md, "Poses that hold").
//   range:   delta_j = range_prior_sigmas sigma_j (a prior), or the kind's range_* margin
//   effects: dT_ij = T_i(theta_0 + delta_j e_j) - T_i(theta_0)
//   corners: theta_0 - sum_j sign(dT_ij) delta_j e_j (cable i lowest), + for the highest
//   probabilistic (hold_probability p > 0): margins as corners; the priors' part at
//     -beta g_i / |g_i| sigmas, g_ij = dT_ij / sigma_j per sigma, beta = Phi^-1(1 - p / L)
//     with L the limits (six minima, six maxima when set, the clearance): a pose then
//     breaks a limit with probability <= p over the priors, to first order (the point is
//     solved exactly)
#include "fastcal/internal/design_range.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>

#include "fastcal/gross_errors.h"
#include "fastcal/statics.h"

namespace fastcal::internal {
namespace {

// The sensors' gains and biases and the length encoders' offsets are of the readings.
bool MovesTheForces(ParameterKind kind) { return KindInfo(kind).moves_forces; }

// The spec with every statics parameter that has a prior freed (a considered one held
// fixed otherwise), so that theta holds every parameter of the range.
CalibrationSpec WithRangeFree(const CalibrationSpec& spec) {
  CalibrationSpec out = spec;
  for (ParameterSpec& p : out.parameters) {
    if (MovesTheForces(p.kind) && p.has_prior) p.free = true;
  }
  return out;
}

// The margin of a free parameter without a prior (DesignOptions::range_*), at `value`.
double MarginOf(const ParameterSpec& p, double value, const DesignOptions& o) {
  switch (KindInfo(p.kind).design_margin) {
    case DesignMargin::kMassCentre:
      return o.range_mass_centre_m;
    case DesignMargin::kOffset:
      return o.range_offset_m;
    case DesignMargin::kRelative:
      return o.range_relative * std::abs(value);
    case DesignMargin::kNone:
      break;  // of the readings, not of the statics: no range to hold over
  }
  return 0.0;
}

// Relative slack of a limit kept, for choosing the tightest: (value - limit) over the
// limit, or over `scale` where the limit is smaller (a 0 N margin, a 0 m clearance).
double Slack(double value, double limit, double scale) {
  return (value - limit) / std::max(std::abs(limit), scale);
}
constexpr double kTensionScaleN = 10e3;
constexpr double kClearanceScaleM = 1.0;

}  // namespace

PlausibleRange::PlausibleRange(const CableRobot& robot, const CalibrationSpec& spec,
                               const DesignOptions& options)
    : options_(options), model_(robot, WithRangeFree(spec)), theta0_(model_.InitialTheta()) {
  {
    StaticsParameters<double> p;
    std::array<double, kNumCables> gain, bias;
    model_.Assemble<double>(theta0_.data(), &p, &gain, &bias, 0, nullptr, &measured_offset0_);
  }
  for (int k = 0; k < model_.num_free(); ++k) {
    const ParameterSpec& p = model_.spec().parameters[model_.spec_index(k)];
    if (!MovesTheForces(p.kind)) continue;
    DesignRangeParameter r;
    r.name = p.name;
    r.unit = p.unit;
    r.to_si = p.to_si;
    r.from_prior = p.has_prior;
    r.delta_si = p.has_prior ? options.range_prior_sigmas * p.prior_sigma_si
                             : MarginOf(p, theta0_[k], options);
    r.sigma_si = p.has_prior ? p.prior_sigma_si : 0.0;
    // Under the probabilistic rule a prior's sigma counts even with range_prior_sigmas 0.
    const bool counts = r.delta_si > 0.0 || (options.hold_probability > 0.0 && r.sigma_si > 0.0);
    if (!counts) continue;
    parameters_.push_back(r);
    theta_index_.push_back(k);
  }
}

// The statics at theta_0 + offset (one entry per range parameter), warm from *start
// when it is not null. True when ok.
bool PlausibleRange::Evaluate(const Pose& pose, const JointValues& joints,
                              const std::vector<double>& offset, const StaticsSolution* start,
                              StaticsSolution* out) const {
  std::vector<double> theta = theta0_;
  for (size_t j = 0; j < offset.size(); ++j) theta[theta_index_[j]] += offset[j];
  StaticsParameters<double> p;
  std::array<double, kNumCables> gain, bias;
  Eigen::Vector3d measured_offset;
  model_.Assemble<double>(theta.data(), &p, &gain, &bias, 0, nullptr, &measured_offset);
  p.reflector = model_.base().reflector;  // Assemble leaves it out (checked in double only)
  // The measured point off its initial value: the same data pose holds the cabin
  // elsewhere, dp_c = -R_m d(offset) (measured_frame.h (5)).
  Pose cabin = pose;
  if (model_.has_measured_frame() && measured_offset != measured_offset0_) {
    const CableRobot& robot = model_.robot();
    const Eigen::Matrix3d r_m =
        pose.rotation *
        MeasuredFrameInCabin(*robot.measured_frame, robot.moving_parts, joints).rotation;
    cabin.position_m -= r_m * (measured_offset - measured_offset0_);
  }
  StaticsOptions o = options_.workspace.statics;
  o.warm_start = start != nullptr;
  if (start != nullptr) *out = *start;
  return SolveStaticsWithParameters(p, model_.robot().moving_parts, joints, cabin, o, out) ==
         StaticsStatus::kOk;
}

// Stage: the nominal point's statics and each parameter's effect on the six lower-end
// tensions and the clearance, per its step (the corner rule's delta; else its prior's
// sigma, or its margin). False, with *failed, where a solve fails.
bool PlausibleRange::Effects(const Pose& pose, const JointValues& joints, StaticsSolution* nominal,
                             std::vector<Effect>* effects, std::vector<double>* failed,
                             StaticsSolution* failed_solution) const {
  const int n = static_cast<int>(parameters_.size());
  std::vector<double> offset(n, 0.0);
  if (!Evaluate(pose, joints, offset, nullptr, nominal)) {
    *failed = offset;
    *failed_solution = *nominal;
    return false;
  }
  effects->assign(n, Effect{});
  StaticsSolution s;
  for (int j = 0; j < n; ++j) {
    offset.assign(n, 0.0);
    offset[j] = Step(j);
    if (!(offset[j] > 0.0)) continue;
    if (!Evaluate(pose, joints, offset, nominal, &s)) {
      *failed = offset;
      *failed_solution = s;
      return false;
    }
    for (int i = 0; i < kNumCables; ++i) {
      (*effects)[j].tension_n[i] = s.cables[i].lower_tension_n - nominal->cables[i].lower_tension_n;
    }
    (*effects)[j].clearance_m = s.reflector_clearance_m - nominal->reflector_clearance_m;
  }
  return true;
}

double PlausibleRange::Step(int j) const {
  const DesignRangeParameter& r = parameters_[j];
  if (options_.hold_probability <= 0.0 || !r.from_prior) return r.delta_si;
  return r.sigma_si;
}

// Stage: where to check. The corner rule: for each cable the corner of the box where it is
// lowest (and highest). The probabilistic rule: each margin at its worst end, and the
// priors' part at the design point of the first-order reliability method (Hasofer and
// Lind 1974): with g the limit's gradient per prior sigma, -beta g / |g| sigmas, beta the
// normal quantile of the probability shared among the limits.
std::vector<std::vector<double>> PlausibleRange::Points(const std::vector<Effect>& effects,
                                                        bool has_max) const {
  const int n = static_cast<int>(parameters_.size());
  const bool form = options_.hold_probability > 0.0;
  // Limits shared among: each cable's minimum (and maximum) and the clearance.
  const int limits = kNumCables * (has_max ? 2 : 1) + 1;
  const double beta = form ? TwoSidedNormalQuantile(2.0 * options_.hold_probability / limits) : 0.0;
  std::vector<std::vector<double>> points = {std::vector<double>(n, 0.0)};
  // An effect per unit of the parameter's step (0 where it has none).
  const auto PerStep = [this](double effect, int j) {
    return Step(j) > 0.0 ? effect / Step(j) : 0.0;
  };
  // The point lowering quantity q (its effect per step: effect(j)) the most.
  auto worst = [&](const std::function<double(int)>& effect) {
    std::vector<double> c(n, 0.0);
    double norm = 0.0;
    for (int j = 0; j < n; ++j) {
      if (form && parameters_[j].from_prior) {
        norm += effect(j) * effect(j);
      } else {
        c[j] = (effect(j) < 0.0 ? 1.0 : -1.0) * parameters_[j].delta_si;
      }
    }
    norm = std::sqrt(norm);
    for (int j = 0; j < n && norm > 0.0; ++j) {
      if (form && parameters_[j].from_prior) c[j] = -beta * effect(j) / norm * Step(j);
    }
    if (std::find(points.begin(), points.end(), c) == points.end()) points.push_back(c);
  };
  for (int side = 0; side < (has_max ? 2 : 1); ++side) {
    const double sign = side == 0 ? 1.0 : -1.0;  // lowest, then highest
    for (int i = 0; i < kNumCables; ++i) {
      worst([&](int j) { return PerStep(sign * effects[j].tension_n[i], j); });
    }
  }
  if (form) worst([&](int j) { return PerStep(effects[j].clearance_m, j); });
  return points;
}

bool PlausibleRange::Holds(const Pose& pose, const JointValues& joints,
                           DesignBinding* binding) const {
  const WorkspaceOptions& w = options_.workspace;
  DesignBinding broken;
  auto fail = [&](const StaticsSolution& s, const std::vector<double>& at) {
    broken.constraint = StaticsStatusName(s.status);
    broken.cable = s.cable;
    broken.corner_si = at;
    if (binding != nullptr) *binding = broken;
    return false;
  };
  StaticsSolution nominal, s;
  std::vector<Effect> effects;
  std::vector<double> failed;
  if (!Effects(pose, joints, &nominal, &effects, &failed, &s)) return fail(s, failed);
  const bool has_max = std::isfinite(w.max_tension_n);
  const std::vector<std::vector<double>> points = Points(effects, has_max);
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  DesignBinding low{"min_tension", -1, kInfinity, w.min_tension_n, {}},
      high{"max_tension", -1, -kInfinity, w.max_tension_n, {}},
      clear{"reflector_clearance", -1, kInfinity, w.statics.min_reflector_clearance_m, {}};
  for (const std::vector<double>& c : points) {
    const bool ok = c == points[0] ? (s = nominal, true) : Evaluate(pose, joints, c, &nominal, &s);
    if (!ok) return fail(s, c);
    for (int i = 0; i < kNumCables; ++i) {
      const double t = s.cables[i].lower_tension_n;
      if (t < low.value) low = {low.constraint, i, t, low.limit, c};
      if (t > high.value) high = {high.constraint, i, t, high.limit, c};
    }
    if (s.reflector_clearance_m < clear.value) {
      clear = {clear.constraint, -1, s.reflector_clearance_m, clear.limit, c};
    }
  }
  const bool holds = low.value >= low.limit && (!has_max || high.value <= high.limit);
  if (binding == nullptr) return holds;
  // The tightest: the broken one, else the one with the least relative slack.
  double slack = Slack(low.value, low.limit, kTensionScaleN);
  *binding = low;
  if (has_max && Slack(high.limit, high.value, kTensionScaleN) < slack) {
    slack = Slack(high.limit, high.value, kTensionScaleN);
    *binding = high;
  }
  if (std::isfinite(clear.value) && Slack(clear.value, clear.limit, kClearanceScaleM) < slack) {
    *binding = clear;
  }
  return holds;
}

}  // namespace fastcal::internal
