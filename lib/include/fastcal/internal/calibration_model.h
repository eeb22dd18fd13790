// The map from the calibration's free-parameter vector theta (SI, spec order) to the
// statics parameters and the sensor model, and the residual of one sample:
//   r_i = (gain_i * T_i(theta; pose) + bias_i - T_measured_i) / sigma_i,   i = 1..6
// with T_i the forward model's lower-end tension (statics.h) and
//   sigma_i^2 = sigma_abs^2 + (percent/100 * T_predicted_i)^2
// (the predicted reading at the previous pass's parameters: calibration.cc), and, with
// the lengths in the fit (spec noise.length_sigma_m), six more readings of the same sample:
//   r_6+i = (s0_i(theta; pose) + offset_i - s0_measured_i) / sigma_L,      i = 1..6
// with s0_i exact's unstretched length and offset_i the winch encoder's zero
// (length_offset_m); r = 0 for a reading kept out of the fit (a gross error).
// TensionResidual is a pure functor (const members, no side effects). Its Evaluate is the
// one stage every consumer (the folded cost, the linearisation, the design) reads a
// sample's six rows and their 6 x n Jacobian from. With exact statics the Jacobian is
// analytic: the statics' part by the implicit-function theorem (tension_gradient.h),
// contracted with the parameter map (CalibrationModel::ReadingJacobian), the sensors' gain
// and bias directly; ~1 us a sample whatever n (issue 28). With aas and aas-refined,
// whose solutions are explicit sequences of solves, a ceres::Jet as wide as n replays
// them (TensionCost::EvaluateJet). With the lengths in the fit the Jet replays exact's
// solution too (statics_jet.h gives s0's derivatives through the implicit-function
// theorem): slower than the analytic rows, the same numbers.
#ifndef FASTCAL_INTERNAL_CALIBRATION_MODEL_H_
#define FASTCAL_INTERNAL_CALIBRATION_MODEL_H_

#include <ceres/cost_function.h>
#include <ceres/jet.h>

#include <array>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"
#include "fastcal/internal/compact_start.h"
#include "fastcal/internal/tension_gradient.h"
#include "fastcal/slow_error.h"
#include "fastcal/statics.h"

namespace fastcal::internal {

// Largest number of free parameters one cost evaluation handles (Jet size). The
// linearisation's basis (every parameter the model has) needs 55 for FAST's layout, plus
// one per attachment.
inline constexpr int kMaxFreeParameters = 128;

// Readings of one sample: the six tensions (rows 0..5), then with lengths in the fit the
// six lengths (rows 6..11).
inline constexpr int kMaxReadings = 2 * kNumCables;

class CalibrationModel {
 public:
  // `spec` must be valid for `robot` (anchor indices in range).
  CalibrationModel(const CableRobot& robot, const CalibrationSpec& spec);

  int num_free() const { return static_cast<int>(free_.size()); }
  // Index into spec.parameters of free parameter k.
  int spec_index(int k) const { return free_[k]; }
  const CalibrationSpec& spec() const { return spec_; }
  const CableRobot& robot() const { return robot_; }
  const StaticsParameters<double>& base() const { return base_; }
  // Initial values of the free parameters (SI).
  std::vector<double> InitialTheta() const;
  // The value parameter `p` has in the base model (after fixed overrides), SI.
  double BaseValue(const ParameterSpec& p) const;
  // The calibrated model: the input robot with the parameters set to theta (those of
  // `session` where a parameter has one copy per session: sessions.h).
  CableRobot ToRobot(const double* theta, int session = 0) const;

  // Whether an anchor or tower offset is free: the statics' gradient needs its geometry
  // columns (ExactTensionGradient).
  bool frees_geometry() const { return frees_geometry_; }
  // d reading_i / d theta_k (6 x n, row-major) of the readings gain_i T_i + bias_i at a
  // sample of `session`: Assemble's map differentiated, with `gradient` the statics' and
  // `gain` Assemble's at theta. A parameter of another session has a zero column. With
  // moving parts, `shifts` are the sample's (A_k, b_k) and `at` Assemble's parameters
  // (mass centre c0): the parts' columns are the mass centre's through
  // d c / d Q_k = A_k / M, d c / d m_k = b_k / M, and the cabin mass's gains
  // d c / d M = -(c(q) - c0) / M (moving_parts.h eq. (1)).
  // With a measured frame, `measured_rotation` is the sample's R_m (the data's attitude):
  // the offset's columns are the statics' position partials times -R_m e_j
  // (measured_frame.h (5)), a translation of the cabin being the towers' opposite one.
  void ReadingJacobian(const TensionGradient& gradient, const std::array<double, kNumCables>& gain,
                       int session, double* jacobian, const PartShifts* shifts = nullptr,
                       const StaticsParameters<double>* at = nullptr,
                       const Eigen::Matrix3d* measured_rotation = nullptr) const;
  // Whether the model has moving parts: each sample's statics then move the mass centre
  // to its joint values.
  bool has_parts() const { return base_.num_parts > 0; }
  // Whether the data's poses are a measured frame's (cable_robot.h, measured_frame.h):
  // each sample's cabin pose then follows from its joints and the offset at theta.
  bool has_measured_frame() const { return robot_.measured_frame.has_value(); }
  // A sample's cabin pose from its data pose `measured` at `joints`, with the measured
  // point at `offset_m` (Assemble's at theta): measured_frame.h (3)-(4); `measured` itself
  // without a measured frame.
  Pose CabinPose(const Pose& measured, const JointValues& joints,
                 const Eigen::Vector3d& offset_m) const;

  // Puts the value `v` of parameter `s` where it enters: the statics parameters, the
  // sensors' gains and biases, the encoders' zeros or the measured point; offsets of the
  // geometry are added to the points they move. The switch over kinds that writes.
  template <typename T>
  void Apply(const ParameterSpec& s, const T& v, StaticsParameters<T>* p,
             std::array<T, kNumCables>* gain, std::array<T, kNumCables>* bias,
             std::array<T, kNumCables>* offset, Vector3T<T>* measured_offset) const {
    const auto set_cables = [&s, &v](std::array<T, kNumCables>* values) {
      for (int i = 0; i < kNumCables; ++i) {
        if (s.index < 0 || s.index == i) (*values)[i] = v;
      }
    };
    switch (s.kind) {
      case ParameterKind::kMassCentre:
        p->mass_centre_cabin_m[s.component] = v;
        break;
      case ParameterKind::kCabinMass:
        p->cabin_mass_kg = v;
        break;
      case ParameterKind::kLinearDensity:
        set_cables(&p->linear_density_kg_per_m);
        break;
      case ParameterKind::kEa:
        set_cables(&p->ea_n);
        break;
      case ParameterKind::kAnchorOffset:
        for (int i = 0; i < kNumCables; ++i) {
          if (anchor_of_cable_[i] == s.index) p->anchor_cabin_m[i][s.component] += v;
        }
        break;
      case ParameterKind::kTowerOffset:
        p->tower_top_m[s.index][s.component] += v;
        break;
      case ParameterKind::kSensorGain:
        set_cables(gain);
        break;
      case ParameterKind::kSensorBias:
        set_cables(bias);
        break;
      case ParameterKind::kAttachmentMass:
      case ParameterKind::kAttachmentDensity:
        p->chain[s.index].value[s.component] = v;
        break;
      case ParameterKind::kLengthOffset:
        set_cables(offset);
        break;
      case ParameterKind::kPartFirstMoment:
        p->part_first_moment_kg_m[s.index][s.component] = v;
        break;
      case ParameterKind::kPartMass:
        p->part_mass_kg[s.index] = v;
        break;
      case ParameterKind::kMeasuredOffset:
        (*measured_offset)[s.component] = v;
        break;
    }
  }

  // The statics parameters and sensor model at theta for a sample of `session`: a
  // parameter of another session (ParameterSpec::session) does not apply.
  // With `measured_offset_m`, the measured frame's point (measured_frame.h) too.
  template <typename T>
  void Assemble(const T* theta, StaticsParameters<T>* p, std::array<T, kNumCables>* gain,
                std::array<T, kNumCables>* bias, int session = 0,
                std::array<T, kNumCables>* offset_m = nullptr,
                Vector3T<T>* measured_offset_m = nullptr) const {
    CastParametersInto(base_, p);
    Vector3T<T> measured_offset = base_measured_offset_m_.cast<T>();
    std::array<T, kNumCables> offset;
    for (int i = 0; i < kNumCables; ++i) {
      (*gain)[i] = T(base_gain_[i]);
      (*bias)[i] = T(base_bias_n_[i]);
      offset[i] = T(base_offset_m_[i]);
    }
    for (int k = 0; k < num_free(); ++k) {
      const ParameterSpec& s = spec_.parameters[free_[k]];
      if (s.session >= 0 && s.session != session) continue;
      Apply(s, theta[k], p, gain, bias, &offset, &measured_offset);
    }
    if (offset_m != nullptr) *offset_m = offset;
    if (measured_offset_m != nullptr) *measured_offset_m = measured_offset;
  }

 private:
  CableRobot robot_;
  CalibrationSpec spec_;
  std::vector<int> free_;
  bool frees_geometry_ = false;
  std::array<int, kNumCables> anchor_of_cable_{};
  StaticsParameters<double> base_;  // the robot with fixed overrides applied
  std::array<double, kNumCables> base_gain_{}, base_bias_n_{}, base_offset_m_{};
  Eigen::Vector3d base_measured_offset_m_ = Eigen::Vector3d::Zero();
};

// The model at one theta for a pass over many samples: the statics parameters, gains and
// biases of each session assembled once (CalibrationModel::Assemble per sample copied
// ~2.5 kB of parameters for each: a tenth of a solve).
class ModelAtTheta {
 public:
  struct Session {
    StaticsParameters<double> statics;
    std::array<double, kNumCables> gain, bias;
    Eigen::Vector3d measured_offset_m = Eigen::Vector3d::Zero();  // measured_frame.h
    bool gains_positive = false;  // else every evaluation fails (TensionResidual)
  };
  // `theta` must outlive this; sessions >= 1.
  ModelAtTheta(const CalibrationModel& model, const double* theta, int sessions);
  const CalibrationModel& model() const { return *model_; }
  const double* theta() const { return theta_; }
  const Session& session(int s) const { return sessions_[s]; }

 private:
  const CalibrationModel* model_;
  const double* theta_;
  std::vector<Session> sessions_;
};

// Whitening sigma of each cable's reading: sqrt(abs^2 + (percent/100 * reading)^2).
std::array<double, kNumCables> TensionSigmas(const std::array<double, kNumCables>& reading_n,
                                             double sigma_abs_n, double sigma_percent);

struct TensionResidual {
  const CalibrationModel* model;
  // The data's pose: the measured frame's when the model declares one (the cabin's pose
  // then follows from the joints and the offset at theta: CalibrationModel::CabinPose).
  Pose pose;
  std::array<double, kNumCables> measured_n;
  std::array<double, kNumCables> sigma_n;
  StaticsOptions statics;
  // The statics at the initial parameters, a constant starting point: each evaluation
  // warm-starts from it, since the parameters move little. Without one (the default)
  // every evaluation starts cold.
  CompactStart start;
  // Readings kept out of the fit: their residual is 0, whatever the parameters.
  std::array<bool, kNumCables> excluded{};
  int session = 0;  // the sample's (Sample::session)
  // With the lengths in the fit (length_sigma_m > 0): the measured lengths, their sigma,
  // and the lengths kept out. readings() residuals in all.
  std::array<double, kNumCables> measured_length_m{};
  double length_sigma_m = 0.0;
  std::array<bool, kNumCables> length_excluded{};
  // The sample's joint values (Sample::joint), for a model with moving parts.
  JointValues joints{};

  int readings() const { return length_sigma_m > 0.0 ? kMaxReadings : kNumCables; }

  // The readings() residuals and, when `jacobian` is not null, their Jacobian (readings()
  // x n, row-major; rows of excluded readings zero) at theta. False where the statics fail.
  bool Evaluate(const double* theta, double* residuals, double* jacobian) const;

  template <typename T>
  bool operator()(const T* theta, T* residuals) const {
    StaticsParameters<T> p;
    std::array<T, kNumCables> gain, bias, tension, offset, length;
    Vector3T<T> measured_offset;
    const bool lengths = length_sigma_m > 0.0;
    model->Assemble(theta, &p, &gain, &bias, session, &offset, &measured_offset);
    if (p.num_parts > 0) {
      PartShifts shifts;
      model->robot().moving_parts.ShiftsAt(joints, &shifts);
      p.mass_centre_cabin_m = MassCentreAt(p, shifts);
    }
    // Physical limits: a non-positive gain here, and non-positive mass, density or EA in
    // the statics, make the evaluation fail, which Ceres treats as an infeasible step.
    for (const T& g : gain) {
      if (!(ScalarValue(g) > 0.0)) return false;
    }
    // The cabin's pose at the offset's value, and the offset's derivative as the towers'
    // opposite translation (measured_frame.h (5)): dp_c = -R_m d(offset), whose value
    // part is zero, so the double solve is the pose's own.
    Pose cabin = pose;
    if (model->has_measured_frame()) {
      Eigen::Vector3d value;
      for (int k = 0; k < 3; ++k) value[k] = ScalarValue(measured_offset[k]);
      cabin = model->CabinPose(pose, joints, value);
      const Vector3T<T> shift = pose.rotation.cast<T>() * (measured_offset - value.cast<T>());
      for (int i = 0; i < kNumCables; ++i) p.tower_top_m[i] += shift;
    }
    StaticsSolution solution;
    start.Restore(cabin, statics.method, &solution);
    StaticsOptions options = statics;
    options.warm_start = true;
    if (ModelLowerTensions(p, cabin, options, &tension, &solution, lengths ? &length : nullptr) !=
        StaticsStatus::kOk) {
      return false;
    }
    for (int i = 0; i < kNumCables; ++i) {
      residuals[i] =
          excluded[i] ? T(0.0) : (gain[i] * tension[i] + bias[i] - measured_n[i]) / sigma_n[i];
    }
    for (int i = 0; i < kNumCables && lengths; ++i) {
      residuals[kNumCables + i] =
          length_excluded[i] ? T(0.0)
                             : (length[i] + offset[i] - measured_length_m[i]) / length_sigma_m;
    }
    return true;
  }
};

// Where a pass over the fitted samples leaves what their statics solved, per dataset
// sample (FittedSamples::FillsSolved): the model's readings gain T + bias, as a prediction
// at the same parameters computes them, and each solution as the sample's next warm start.
struct SolvedSamples {
  std::vector<std::array<double, kNumCables>>* reading_n = nullptr;
  CompactStarts* starts = nullptr;
};

// The fitted samples of one problem, by reference: nothing per sample is copied (at 10^6
// samples every copy is ~50 MB). The residual of fitted sample j is At(j).
struct FittedSamples {
  const CalibrationModel* model = nullptr;
  const Dataset* data = nullptr;
  const std::vector<int>* fit = nullptr;  // dataset indices, file order
  // Per fitted sample: the whitening sigmas.
  const std::vector<std::array<double, kNumCables>>* sigma_n = nullptr;
  // Per dataset sample: warm starts (may be null or empty: cold starts).
  const CompactStarts* starts = nullptr;
  // Whether each start is the converged solution of the very statics Rows evaluates (the
  // same parameters and pose: a window's second pass at its first's point, track_fold.cc;
  // a fold or the linearisation at the prediction's theta, CompactStarts::SolvedAt): Rows
  // with a Jacobian then takes it as solved instead of solving again (exact only; a
  // sample without a start is solved). The caller's promise: Rows does not check it.
  bool starts_solved = false;
  // Per dataset sample: readings kept out of the fit (may be null or empty).
  const ReadingMask* excluded = nullptr;
  bool use_planned_attitude = false;
  StaticsOptions statics;
  // The slow sensor error the rows are whitened by (slow_error.h; inactive: white noise
  // only, nothing whitened), and per fitted sample each reading's
  // rho = sigma_slow(reading) / sigma_white (sample_rows.h).
  SlowErrorProcess slow_error;
  const std::vector<std::array<double, kNumCables>>* slow_rho = nullptr;
  // The lengths as readings (CalibrationSpec::length_sigma_m; 0: not used) and, per
  // dataset sample, the lengths kept out (may be null or empty).
  double length_sigma_m = 0.0;
  const ReadingMask* length_excluded = nullptr;
  // Where Rows leaves what it solved (FillsSolved), so that a prediction at the same
  // parameters need not solve again (issue 41); nowhere by default. It may be `starts`
  // itself: a sample's start is read before its own is written.
  SolvedSamples solved;

  int size() const { return static_cast<int>(fit->size()); }
  // Rows per sample: the six tensions, twelve with the lengths.
  int readings() const { return length_sigma_m > 0.0 ? kMaxReadings : kNumCables; }
  bool whitened() const { return slow_error.IsActive() && slow_rho != nullptr; }
  // Fitted sample j's residual through `through` (default: model).
  TensionResidual At(int j, const CalibrationModel* through = nullptr) const;
  // The stage every pass over the samples reads from: fitted sample j's six residuals and,
  // when `jacobian` is not null, their Jacobian (6 x n, row-major) at `at` (through the
  // model `at` was made for, with at least as many sessions as the data). The same
  // numbers as At(j, &at.model()).Evaluate(at.theta(), ...).
  bool Rows(int j, const ModelAtTheta& at, double* residuals, double* jacobian) const;
  // Whether Rows fills `solved`: with somewhere to put it, on the path of exact statics
  // without lengths (the readings of another path are not a prediction's).
  bool FillsSolved() const {
    return solved.reading_n != nullptr && solved.starts != nullptr && length_sigma_m <= 0.0 &&
           statics.method == StaticsMethod::kExact;
  }
  // The number of sessions a ModelAtTheta for these samples needs.
  int sessions() const;
  // Fitted sample j's readings kept out of the fit, and its lengths kept out.
  std::array<bool, kNumCables> Excluded(int j) const;
  std::array<bool, kNumCables> LengthExcluded(int j) const;
};

// ceres::CostFunction over one parameter block (theta) of size num_free <=
// kMaxFreeParameters: TensionResidual::Evaluate.
class TensionCost : public ceres::CostFunction {
 public:
  explicit TensionCost(const TensionResidual& functor);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  // The Jacobian by a ceres::Jet through the replayed statics, whatever the method:
  // aas's and aas-refined's derivatives, and a reference for the analytic ones (tests).
  static bool EvaluateJet(const TensionResidual& f, const double* theta, double* residuals,
                          double* jacobian);

 private:
  template <int N>
  static bool EvaluateJetOf(const TensionResidual& f, const double* theta, double* residuals,
                            double* jacobian);
  TensionResidual functor_;
};

// (theta_k - mean) / sigma on one coordinate of theta.
class PriorCost : public ceres::CostFunction {
 public:
  PriorCost(int num_free, int k, double mean, double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  int n_, k_;
  double mean_, sigma_;
};

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_CALIBRATION_MODEL_H_
