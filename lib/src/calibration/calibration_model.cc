// Parameter mapping and cost functions of the calibration (calibration_model.h).
#include "fastcal/internal/calibration_model.h"

#include <cmath>

namespace fastcal::internal {

CalibrationModel::CalibrationModel(const CableRobot& robot, const CalibrationSpec& spec)
    : robot_(robot), spec_(spec), base_(MakeStaticsParameters(robot)) {
  for (int i = 0; i < kNumCables; ++i) {
    anchor_of_cable_[i] = robot.cables[i].anchor_index;
    base_gain_[i] = robot.cables[i].sensor_gain;
    base_bias_n_[i] = robot.cables[i].sensor_bias_n;
    base_offset_m_[i] = robot.cables[i].length_offset_m;
  }
  for (size_t j = 0; j < spec.parameters.size(); ++j) {
    const ParameterSpec& s = spec.parameters[j];
    if (s.free) {
      free_.push_back(static_cast<int>(j));
      continue;
    }
    if (!s.has_initial) continue;
    // A fixed parameter with a value overrides the model: fold it into the base.
    const double v = s.initial_si;
    for (int i = 0; i < kNumCables; ++i) {
      const bool cable = s.index < 0 || s.index == i;
      switch (s.kind) {
        case ParameterKind::kMassCentre:
          base_.mass_centre_cabin_m[s.component] = v;
          break;
        case ParameterKind::kCabinMass:
          base_.cabin_mass_kg = v;
          break;
        case ParameterKind::kLinearDensity:
          if (cable) base_.linear_density_kg_per_m[i] = v;
          break;
        case ParameterKind::kEa:
          if (cable) base_.ea_n[i] = v;
          break;
        case ParameterKind::kAnchorOffset:
          if (anchor_of_cable_[i] == s.index) base_.anchor_cabin_m[i][s.component] += v;
          break;
        case ParameterKind::kTowerOffset:
          if (i == s.index) base_.tower_top_m[i][s.component] += v;
          break;
        case ParameterKind::kSensorGain:
          if (cable) base_gain_[i] = v;
          break;
        case ParameterKind::kSensorBias:
          if (cable) base_bias_n_[i] = v;
          break;
        case ParameterKind::kAttachmentMass:
        case ParameterKind::kAttachmentDensity:
          if (i == s.index) base_.chain[i].value[s.component] = v;
          break;
        case ParameterKind::kLengthOffset:
          if (cable) base_offset_m_[i] = v;
          break;
      }
    }
  }
}

double CalibrationModel::BaseValue(const ParameterSpec& s) const {
  const int c = s.index < 0 ? 0 : s.index;
  switch (s.kind) {
    case ParameterKind::kMassCentre:
      return base_.mass_centre_cabin_m[s.component];
    case ParameterKind::kCabinMass:
      return base_.cabin_mass_kg;
    case ParameterKind::kLinearDensity: {
      if (s.index >= 0) return base_.linear_density_kg_per_m[c];
      double sum = 0;
      for (double d : base_.linear_density_kg_per_m) sum += d;
      return sum / kNumCables;
    }
    case ParameterKind::kEa: {
      if (s.index >= 0) return base_.ea_n[c];
      double sum = 0;
      for (double d : base_.ea_n) sum += d;
      return sum / kNumCables;
    }
    case ParameterKind::kAnchorOffset:
    case ParameterKind::kTowerOffset:
      return 0.0;  // offsets are relative to the (overridden) base geometry
    case ParameterKind::kSensorGain: {
      if (s.index >= 0) return base_gain_[c];
      double sum = 0;
      for (double d : base_gain_) sum += d;
      return sum / kNumCables;
    }
    case ParameterKind::kSensorBias: {
      if (s.index >= 0) return base_bias_n_[c];
      double sum = 0;
      for (double d : base_bias_n_) sum += d;
      return sum / kNumCables;
    }
    case ParameterKind::kAttachmentMass:
    case ParameterKind::kAttachmentDensity:
      return base_.chain[c].value[s.component];
    case ParameterKind::kLengthOffset: {
      if (s.index >= 0) return base_offset_m_[c];
      double sum = 0;
      for (double d : base_offset_m_) sum += d;
      return sum / kNumCables;
    }
  }
  return 0.0;
}

std::vector<double> CalibrationModel::InitialTheta() const {
  std::vector<double> theta;
  for (int k = 0; k < num_free(); ++k) {
    const ParameterSpec& s = spec_.parameters[free_[k]];
    theta.push_back(s.has_initial ? s.initial_si : BaseValue(s));
  }
  return theta;
}

CableRobot CalibrationModel::ToRobot(const double* theta, int session) const {
  StaticsParameters<double> p;
  std::array<double, kNumCables> gain, bias, offset;
  Assemble(theta, &p, &gain, &bias, session, &offset);
  CableRobot out = robot_;
  // Anchor points: the offset of the first cable tied to each point (all its cables
  // carry the same offset by construction).
  for (size_t j = 0; j < out.anchor_points_cabin_m.size(); ++j) {
    for (int i = 0; i < kNumCables; ++i) {
      if (anchor_of_cable_[i] == static_cast<int>(j)) {
        out.anchor_points_cabin_m[j] = p.anchor_cabin_m[i];
        break;
      }
    }
  }
  for (int i = 0; i < kNumCables; ++i) {
    CableProperties& c = out.cables[i];
    c.tower_top_m = p.tower_top_m[i];
    c.ea_n = p.ea_n[i];
    c.linear_density_kg_per_m = p.linear_density_kg_per_m[i];
    c.sensor_gain = gain[i];
    c.sensor_bias_n = bias[i];
    c.length_offset_m = offset[i];
    for (size_t j = 0; j < c.attachments.size(); ++j)
      c.attachments[j].SetValue(p.chain[i].value[j]);
  }
  out.cabin_mass_kg = p.cabin_mass_kg;
  out.mass_centre_cabin_m = p.mass_centre_cabin_m;
  return out;
}

std::array<double, kNumCables> TensionSigmas(const std::array<double, kNumCables>& reading_n,
                                             double sigma_abs_n, double sigma_percent) {
  std::array<double, kNumCables> s;
  for (int i = 0; i < kNumCables; ++i) {
    const double rel = sigma_percent / 100.0 * reading_n[i];
    s[i] = std::sqrt(sigma_abs_n * sigma_abs_n + rel * rel);
  }
  return s;
}

TensionResidual FittedSamples::At(int j, const CalibrationModel* through) const {
  const int t = (*fit)[j];
  const Sample& sample = data->samples[t];
  TensionResidual f;
  f.model = through != nullptr ? through : model;
  f.pose = sample.pose;
  if (use_planned_attitude) f.pose.rotation = sample.planned_rotation;
  f.measured_n = sample.tension_n;
  f.sigma_n = (*sigma_n)[j];
  f.statics = statics;
  if (starts != nullptr && !starts->empty()) f.start = (*starts)[t];
  if (excluded != nullptr && !excluded->empty()) f.excluded = (*excluded)[t];
  f.session = sample.session;
  if (length_sigma_m > 0.0) {
    f.length_sigma_m = length_sigma_m;
    f.measured_length_m = sample.unstretched_length_m;
    if (length_excluded != nullptr && !length_excluded->empty()) {
      f.length_excluded = (*length_excluded)[t];
    }
  }
  return f;
}

TensionCost::TensionCost(const TensionResidual& functor)
    : functor_(functor), n_(functor.model->num_free()) {
  set_num_residuals(functor.readings());
  mutable_parameter_block_sizes()->push_back(n_);
}

template <int N>
bool TensionCost::EvaluateJet(const double* theta, double* residuals, double* jacobian) const {
  using Jet = ceres::Jet<double, N>;
  std::array<Jet, N> t;
  for (int k = 0; k < n_; ++k) t[k] = Jet(theta[k], k);
  std::array<Jet, kMaxReadings> r;
  if (!functor_(t.data(), r.data())) return false;
  for (int i = 0; i < functor_.readings(); ++i) {
    residuals[i] = r[i].a;
    for (int k = 0; k < n_; ++k) jacobian[i * n_ + k] = r[i].v[k];
  }
  return true;
}

bool TensionCost::Evaluate(double const* const* parameters, double* residuals,
                           double** jacobians) const {
  const double* theta = parameters[0];
  if (jacobians == nullptr || jacobians[0] == nullptr) return functor_(theta, residuals);
  double* j = jacobians[0];
  if (n_ <= 1) return EvaluateJet<1>(theta, residuals, j);
  if (n_ <= 2) return EvaluateJet<2>(theta, residuals, j);
  if (n_ <= 4) return EvaluateJet<4>(theta, residuals, j);
  if (n_ <= 8) return EvaluateJet<8>(theta, residuals, j);
  if (n_ <= 16) return EvaluateJet<16>(theta, residuals, j);
  if (n_ <= 32) return EvaluateJet<32>(theta, residuals, j);
  if (n_ <= 64) return EvaluateJet<64>(theta, residuals, j);
  return EvaluateJet<kMaxFreeParameters>(theta, residuals, j);
}

PriorCost::PriorCost(int num_free, int k, double mean, double sigma)
    : n_(num_free), k_(k), mean_(mean), sigma_(sigma) {
  set_num_residuals(1);
  mutable_parameter_block_sizes()->push_back(num_free);
}

bool PriorCost::Evaluate(double const* const* parameters, double* residuals,
                         double** jacobians) const {
  residuals[0] = (parameters[0][k_] - mean_) / sigma_;
  if (jacobians != nullptr && jacobians[0] != nullptr) {
    for (int k = 0; k < n_; ++k) jacobians[0][k] = k == k_ ? 1.0 / sigma_ : 0.0;
  }
  return true;
}

}  // namespace fastcal::internal
