// The plausible range of a survey design and the test of a pose over it
// (internal/design_range.h; the rule: design.h and docs/design.md, "Poses that hold").
//   range:   delta_j = range_prior_sigmas sigma_j (a prior), or the kind's range_* margin
//   effects: dT_ij = T_i(theta_0 + delta_j e_j) - T_i(theta_0)
//   corners: theta_0 - sum_j sign(dT_ij) delta_j e_j (cable i lowest), + for the highest
#include "fastcal/internal/design_range.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "fastcal/statics.h"

namespace fastcal::internal {
namespace {

bool MovesTheForces(ParameterKind kind) {
  // The sensors' gains and biases and the length encoders' offsets are of the readings.
  return kind != ParameterKind::kSensorGain && kind != ParameterKind::kSensorBias &&
         kind != ParameterKind::kLengthOffset;
}

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
  switch (p.kind) {
    case ParameterKind::kMassCentre:
      return o.range_mass_centre_m;
    case ParameterKind::kAnchorOffset:
    case ParameterKind::kTowerOffset:
      return o.range_offset_m;
    case ParameterKind::kCabinMass:
    case ParameterKind::kLinearDensity:
    case ParameterKind::kEa:
    case ParameterKind::kAttachmentMass:
    case ParameterKind::kAttachmentDensity:
    case ParameterKind::kPartFirstMoment:
    case ParameterKind::kPartMass:
      return o.range_relative * std::abs(value);
    case ParameterKind::kSensorGain:
    case ParameterKind::kSensorBias:
    case ParameterKind::kLengthOffset:
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
    if (!(r.delta_si > 0.0)) continue;
    parameters_.push_back(r);
    theta_index_.push_back(k);
  }
}

// The statics at theta_0 + offset (one entry per range parameter), warm from *start
// when it is not null. True when ok.
bool PlausibleRange::Evaluate(const Pose& pose, const std::vector<double>& offset,
                              const StaticsSolution* start, StaticsSolution* out) const {
  std::vector<double> theta = theta0_;
  for (size_t j = 0; j < offset.size(); ++j) theta[theta_index_[j]] += offset[j];
  StaticsParameters<double> p;
  std::array<double, kNumCables> gain, bias;
  model_.Assemble(theta.data(), &p, &gain, &bias);
  p.reflector = model_.base().reflector;  // Assemble leaves it out (checked in double only)
  StaticsOptions o = options_.workspace.statics;
  o.warm_start = start != nullptr;
  if (start != nullptr) *out = *start;
  return SolveStaticsWithParameters(p, pose, o, out) == StaticsStatus::kOk;
}

bool PlausibleRange::Holds(const Pose& pose, DesignBinding* binding) const {
  const WorkspaceOptions& w = options_.workspace;
  const int n = static_cast<int>(parameters_.size());
  DesignBinding broken;
  auto fail = [&](const StaticsSolution& s, const std::vector<double>& at) {
    broken.constraint = StaticsStatusName(s.status);
    broken.cable = s.cable;
    broken.corner_si = at;
    if (binding != nullptr) *binding = broken;
    return false;
  };
  // The nominal point, then each parameter alone at +delta: the tensions' effects.
  std::vector<double> offset(n, 0.0);
  StaticsSolution nominal;
  if (!Evaluate(pose, offset, nullptr, &nominal)) return fail(nominal, offset);
  std::vector<std::array<double, kNumCables>> effect(n);
  StaticsSolution s;
  for (int j = 0; j < n; ++j) {
    offset.assign(n, 0.0);
    offset[j] = parameters_[j].delta_si;
    if (!Evaluate(pose, offset, &nominal, &s)) return fail(s, offset);
    for (int i = 0; i < kNumCables; ++i) {
      effect[j][i] = s.cables[i].lower_tension_n - nominal.cables[i].lower_tension_n;
    }
  }
  // The corners: the nominal point, each cable's lowest, and with a maximum its highest.
  std::vector<std::vector<double>> corners = {std::vector<double>(n, 0.0)};
  const bool has_max = std::isfinite(w.max_tension_n);
  for (int side = 0; side < (has_max ? 2 : 1); ++side) {
    for (int i = 0; i < kNumCables; ++i) {
      std::vector<double> c(n);
      for (int j = 0; j < n; ++j) {
        const bool lowers = effect[j][i] < 0.0;
        c[j] = (lowers == (side == 0) ? 1.0 : -1.0) * parameters_[j].delta_si;
      }
      if (std::find(corners.begin(), corners.end(), c) == corners.end()) corners.push_back(c);
    }
  }
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  DesignBinding low{"min_tension", -1, kInfinity, w.min_tension_n, {}},
      high{"max_tension", -1, -kInfinity, w.max_tension_n, {}},
      clear{"reflector_clearance", -1, kInfinity, w.statics.min_reflector_clearance_m, {}};
  for (const std::vector<double>& c : corners) {
    const bool ok = c == corners[0] ? (s = nominal, true) : Evaluate(pose, c, &nominal, &s);
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
