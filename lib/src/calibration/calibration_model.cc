// Parameter mapping and cost functions of the calibration (calibration_model.h).
#include "fastcal/internal/calibration_model.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "fastcal/measured_frame.h"

namespace fastcal::internal {

CalibrationModel::CalibrationModel(const CableRobot& robot, const CalibrationSpec& spec)
    : robot_(robot), spec_(spec), base_(MakeStaticsParameters(robot)) {
  for (int i = 0; i < kNumCables; ++i) {
    anchor_of_cable_[i] = robot.cables[i].anchor_index;
    base_gain_[i] = robot.cables[i].sensor_gain;
    base_bias_n_[i] = robot.cables[i].sensor_bias_n;
    base_offset_m_[i] = robot.cables[i].length_offset_m;
  }
  if (robot.measured_frame.has_value()) base_measured_offset_m_ = robot.measured_frame->offset_m;
  for (size_t j = 0; j < spec.parameters.size(); ++j) {
    const ParameterSpec& s = spec.parameters[j];
    if (s.free) {
      free_.push_back(static_cast<int>(j));
      // The measured point's offset moves the cabin: the towers' columns give it.
      frees_geometry_ = frees_geometry_ || KindInfo(s.kind).moves_geometry;
      continue;
    }
    if (!s.has_initial) continue;
    // A fixed parameter with a value overrides the model: fold it into the base.
    Apply(s, s.initial_si, &base_, &base_gain_, &base_bias_n_, &base_offset_m_,
          &base_measured_offset_m_);
  }
}

Pose CalibrationModel::CabinPose(const Pose& measured, const JointValues& joints,
                                 const Eigen::Vector3d& offset_m) const {
  if (!robot_.measured_frame.has_value()) return measured;
  MeasuredFrame frame = *robot_.measured_frame;
  frame.offset_m = offset_m;
  return CabinPoseFromMeasured(frame, robot_.moving_parts, measured, joints);
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
    case ParameterKind::kPartFirstMoment:
      return base_.part_first_moment_kg_m[c][s.component];
    case ParameterKind::kPartMass:
      return base_.part_mass_kg[c];
    case ParameterKind::kMeasuredOffset:
      return base_measured_offset_m_[s.component];
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
  Eigen::Vector3d measured_offset;
  Assemble(theta, &p, &gain, &bias, session, &offset, &measured_offset);
  CableRobot out = robot_;
  if (out.measured_frame.has_value()) out.measured_frame->offset_m = measured_offset;
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
  for (int k = 0; k < p.num_parts; ++k) {
    out.moving_parts.parts[k].first_moment_kg_m = p.part_first_moment_kg_m[k];
    out.moving_parts.parts[k].mass_kg = p.part_mass_kg[k];
  }
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
  if (starts != nullptr && !starts->empty()) f.start = starts->At(t);
  if (excluded != nullptr && !excluded->empty()) f.excluded = (*excluded)[t];
  f.session = sample.session;
  f.joints = sample.joint;
  if (length_sigma_m > 0.0) {
    f.length_sigma_m = length_sigma_m;
    f.measured_length_m = sample.unstretched_length_m;
    if (length_excluded != nullptr && !length_excluded->empty()) {
      f.length_excluded = (*length_excluded)[t];
    }
  }
  return f;
}

void CalibrationModel::ReadingJacobian(const TensionGradient& gradient,
                                       const std::array<double, kNumCables>& gain, int session,
                                       double* jacobian, const PartShifts* shifts,
                                       const StaticsParameters<double>* at,
                                       const Eigen::Matrix3d* measured_rotation) const {
  const int n = num_free();
  Eigen::Map<Eigen::Matrix<double, kNumCables, Eigen::Dynamic, Eigen::RowMajor>> j(jacobian,
                                                                                   kNumCables, n);
  j.setZero();
  const auto cables = [](const ParameterSpec& s, int i) { return s.index < 0 || s.index == i; };
  for (int k = 0; k < n; ++k) {
    const ParameterSpec& s = spec_.parameters[free_[k]];
    if (s.session >= 0 && s.session != session) continue;
    auto column = j.col(k);
    switch (s.kind) {
      case ParameterKind::kMassCentre:
        column = gradient.mass_centre_cabin_m.col(s.component);
        break;
      case ParameterKind::kCabinMass:
        column = gradient.cabin_mass_kg;
        if (shifts != nullptr && at != nullptr) {
          const Eigen::Vector3d shift = MassCentreAt(*at, *shifts) - at->mass_centre_cabin_m;
          column -= gradient.mass_centre_cabin_m * shift / at->cabin_mass_kg;
        }
        break;
      case ParameterKind::kPartFirstMoment:
        if (shifts != nullptr && at != nullptr) {
          column = gradient.mass_centre_cabin_m *
                   (*shifts)[s.index].rotation_minus_identity.col(s.component) / at->cabin_mass_kg;
        }
        break;
      case ParameterKind::kPartMass:
        if (shifts != nullptr && at != nullptr) {
          column =
              gradient.mass_centre_cabin_m * (*shifts)[s.index].translation_m / at->cabin_mass_kg;
        }
        break;
      case ParameterKind::kLinearDensity:
        for (int i = 0; i < kNumCables; ++i) {
          if (cables(s, i)) column += gradient.linear_density_kg_per_m[i];
        }
        break;
      case ParameterKind::kEa:
        for (int i = 0; i < kNumCables; ++i) {
          if (cables(s, i)) column += gradient.ea_n[i];
        }
        break;
      case ParameterKind::kAnchorOffset:
        for (int i = 0; i < kNumCables; ++i) {
          if (anchor_of_cable_[i] == s.index) column += gradient.anchor_m[i].col(s.component);
        }
        break;
      case ParameterKind::kTowerOffset:
        column = gradient.tower_top_m[s.index].col(s.component);
        break;
      case ParameterKind::kMeasuredOffset:
        // dp_c = -R_m e_j: the cabin's translation is every tower's opposite one.
        if (measured_rotation != nullptr) {
          for (int i = 0; i < kNumCables; ++i) {
            column += gradient.tower_top_m[i] * measured_rotation->col(s.component);
          }
        }
        break;
      case ParameterKind::kAttachmentMass:
      case ParameterKind::kAttachmentDensity:
        column = gradient.chain_value[s.index][s.component];
        break;
      case ParameterKind::kSensorGain:
      case ParameterKind::kSensorBias:
      case ParameterKind::kLengthOffset:  // no tension depends on it (lengths: Jets)
        break;                            // after the statics: below
    }
    // The readings are gain_i T_i + bias_i.
    for (int i = 0; i < kNumCables; ++i) {
      if (s.kind == ParameterKind::kSensorGain) {
        column[i] = cables(s, i) ? gradient.tension_n[i] : 0.0;
      } else if (s.kind == ParameterKind::kSensorBias) {
        column[i] = cables(s, i) ? 1.0 : 0.0;
      } else {
        column[i] *= gain[i];
      }
    }
  }
}

ModelAtTheta::ModelAtTheta(const CalibrationModel& model, const double* theta, int sessions)
    : model_(&model), theta_(theta), sessions_(std::max(1, sessions)) {
  for (size_t k = 0; k < sessions_.size(); ++k) {
    Session& s = sessions_[k];
    model.Assemble<double>(theta, &s.statics, &s.gain, &s.bias, static_cast<int>(k), nullptr,
                           &s.measured_offset_m);
    s.gains_positive = std::all_of(s.gain.begin(), s.gain.end(), [](double g) { return g > 0.0; });
  }
}

namespace {

// What the rows of one sample need besides the model.
struct SampleView {
  Pose pose;
  CompactStart start;
  const std::array<double, kNumCables>& measured_n;
  const std::array<double, kNumCables>& sigma_n;
  const std::array<bool, kNumCables>* excluded;  // null: none
  int session;
  const JointValues* joints;  // null: all at zero (a model without moving parts)
  // `start` is the solution of these statics (FittedSamples::starts_solved).
  bool start_solved = false;
};

// What RowsThrough solved: the readings gain T + bias and the solution as a start.
struct SolvedSample {
  std::array<double, kNumCables> reading_n;
  CompactStart start;
};

// A sample's residuals, and with `jacobian` their analytic Jacobian (exact statics only),
// through assembled parameters: TensionResidual's operator() in double, and its
// implicit-function derivatives; with `solved`, what the statics solved.
bool RowsThrough(const CalibrationModel& model, const ModelAtTheta::Session& m,
                 const StaticsOptions& statics, const SampleView& x, double* residuals,
                 double* jacobian, SolvedSample* solved = nullptr) {
  if (!m.gains_positive) return false;  // as operator()
  // With moving parts the mass centre is the sample's own (moving_parts.h eq. (1)).
  PartShifts shifts;
  std::optional<StaticsParameters<double>> at_joints;
  if (model.has_parts()) {
    model.robot().moving_parts.ShiftsAt(x.joints != nullptr ? *x.joints : JointValues{}, &shifts);
    at_joints.emplace(AtJoints(m.statics, shifts));
  }
  const StaticsParameters<double>& params = at_joints ? *at_joints : m.statics;
  // The statics' pose is the cabin's: the data's own without a measured frame.
  const Pose pose =
      model.CabinPose(x.pose, x.joints != nullptr ? *x.joints : JointValues{}, m.measured_offset_m);
  StaticsSolution solution;
  x.start.Restore(pose, statics.method, &solution);
  StaticsOptions options = statics;
  options.warm_start = true;
  // A start that is these statics' solution is not solved again (issue 41: from a
  // converged start the solve still costs half a cold one): its tensions come with the
  // gradient, from the end evaluation the solver's last check made there.
  const bool as_solved = x.start_solved && jacobian != nullptr &&
                         statics.method == StaticsMethod::kExact && x.start.has_start();
  TensionGradient gradient;
  if (as_solved) {
    if (ExactTensionGradient(params, pose, solution, options.catenary.vertical_span_fraction,
                             model.frees_geometry(), &gradient,
                             /*tensions_from_state=*/true) != StaticsStatus::kOk) {
      return false;
    }
    for (int i = 0; i < kNumCables; ++i) solution.cables[i].lower_tension_n = gradient.tension_n[i];
  } else if (SolveStaticsWithParameters(params, pose, options, &solution) != StaticsStatus::kOk) {
    return false;
  }
  for (int i = 0; i < kNumCables; ++i) {
    const bool out = x.excluded != nullptr && (*x.excluded)[i];
    const double reading = m.gain[i] * solution.cables[i].lower_tension_n + m.bias[i];
    residuals[i] = out ? 0.0 : (reading - x.measured_n[i]) / x.sigma_n[i];
    if (solved != nullptr) solved->reading_n[i] = reading;
  }
  if (solved != nullptr) solved->start = CompactStart::Of(solution);
  if (jacobian == nullptr) return true;
  if (!as_solved &&
      ExactTensionGradient(params, pose, solution, options.catenary.vertical_span_fraction,
                           model.frees_geometry(), &gradient) != StaticsStatus::kOk) {
    return false;
  }
  const int n = model.num_free();
  model.ReadingJacobian(gradient, m.gain, x.session, jacobian, at_joints ? &shifts : nullptr,
                        &m.statics, &x.pose.rotation);
  for (int i = 0; i < kNumCables; ++i) {
    const bool out = x.excluded != nullptr && (*x.excluded)[i];
    const double scale = out ? 0.0 : 1.0 / x.sigma_n[i];
    for (int k = 0; k < n; ++k) jacobian[i * n + k] *= scale;
  }
  return true;
}

}  // namespace

bool TensionResidual::Evaluate(const double* theta, double* residuals, double* jacobian) const {
  if (jacobian == nullptr) return (*this)(theta, residuals);
  if (statics.method != StaticsMethod::kExact || length_sigma_m > 0.0) {
    return TensionCost::EvaluateJet(*this, theta, residuals, jacobian);
  }
  ModelAtTheta::Session m;
  model->Assemble<double>(theta, &m.statics, &m.gain, &m.bias, session, nullptr,
                          &m.measured_offset_m);
  m.gains_positive = std::all_of(m.gain.begin(), m.gain.end(), [](double g) { return g > 0.0; });
  return RowsThrough(*model, m, statics,
                     {pose, start, measured_n, sigma_n, &excluded, session, &joints, false},
                     residuals, jacobian);
}

bool FittedSamples::Rows(int j, const ModelAtTheta& at, double* residuals, double* jacobian) const {
  if (length_sigma_m > 0.0 || (jacobian != nullptr && statics.method != StaticsMethod::kExact)) {
    return At(j, &at.model()).Evaluate(at.theta(), residuals, jacobian);
  }
  const int t = (*fit)[j];
  const Sample& sample = data->samples[t];
  SampleView x{sample.pose,
               starts != nullptr && !starts->empty() ? starts->At(t) : CompactStart(),
               sample.tension_n,
               (*sigma_n)[j],
               excluded != nullptr && !excluded->empty() ? &(*excluded)[t] : nullptr,
               sample.session,
               &sample.joint,
               starts_solved};
  if (use_planned_attitude) x.pose.rotation = sample.planned_rotation;
  if (!FillsSolved()) {
    return RowsThrough(at.model(), at.session(sample.session), statics, x, residuals, jacobian);
  }
  SolvedSample s;
  if (!RowsThrough(at.model(), at.session(sample.session), statics, x, residuals, jacobian, &s)) {
    return false;
  }
  (*solved.reading_n)[t] = s.reading_n;
  solved.starts->Set(t, s.start);
  return true;
}

std::array<bool, kNumCables> FittedSamples::Excluded(int j) const {
  if (excluded == nullptr || excluded->empty()) return {};
  return (*excluded)[(*fit)[j]];
}

std::array<bool, kNumCables> FittedSamples::LengthExcluded(int j) const {
  if (length_excluded == nullptr || length_excluded->empty()) return {};
  return (*length_excluded)[(*fit)[j]];
}

int FittedSamples::sessions() const {
  return std::max<int>(1, static_cast<int>(data->session_labels.size()));
}

TensionCost::TensionCost(const TensionResidual& functor) : functor_(functor) {
  set_num_residuals(functor.readings());
  mutable_parameter_block_sizes()->push_back(functor.model->num_free());
}

template <int N>
bool TensionCost::EvaluateJetOf(const TensionResidual& f, const double* theta, double* residuals,
                                double* jacobian) {
  using Jet = ceres::Jet<double, N>;
  const int n = f.model->num_free();
  std::array<Jet, N> t;
  for (int k = 0; k < n; ++k) t[k] = Jet(theta[k], k);
  std::array<Jet, kMaxReadings> r;
  if (!f(t.data(), r.data())) return false;
  for (int i = 0; i < f.readings(); ++i) {
    residuals[i] = r[i].a;
    for (int k = 0; k < n; ++k) jacobian[i * n + k] = r[i].v[k];
  }
  return true;
}

bool TensionCost::EvaluateJet(const TensionResidual& f, const double* theta, double* residuals,
                              double* j) {
  const int n = f.model->num_free();
  if (n <= 1) return EvaluateJetOf<1>(f, theta, residuals, j);
  if (n <= 2) return EvaluateJetOf<2>(f, theta, residuals, j);
  if (n <= 4) return EvaluateJetOf<4>(f, theta, residuals, j);
  if (n <= 8) return EvaluateJetOf<8>(f, theta, residuals, j);
  if (n <= 16) return EvaluateJetOf<16>(f, theta, residuals, j);
  if (n <= 32) return EvaluateJetOf<32>(f, theta, residuals, j);
  if (n <= 64) return EvaluateJetOf<64>(f, theta, residuals, j);
  return EvaluateJetOf<kMaxFreeParameters>(f, theta, residuals, j);
}

bool TensionCost::Evaluate(double const* const* parameters, double* residuals,
                           double** jacobians) const {
  return functor_.Evaluate(parameters[0], residuals, jacobians != nullptr ? jacobians[0] : nullptr);
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
