// One calibration's state, passed from stage to stage, and what the stages share: the
// pipeline (calibration.cc) runs the stages in order; the problem, its solution and the
// gross errors are there, the linearisation, budget and diagnostics in
// calibration_diagnostics.cc, the parameter table, verdict and notes in
// calibration_verdict.cc.
#ifndef FASTCAL_SRC_CALIBRATION_CALIBRATION_RUN_H_
#define FASTCAL_SRC_CALIBRATION_CALIBRATION_RUN_H_

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "fastcal/calibration.h"
#include "fastcal/gross_errors.h"
#include "fastcal/internal/calibration_linearisation.h"
#include "fastcal/internal/calibration_model.h"
#include "fastcal/internal/calibration_slow_error.h"
#include "fastcal/internal/compact_start.h"
#include "fastcal/internal/folded_cost.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/units.h"

namespace fastcal::internal {

// A parameter with at least this weight in a weak direction gets a note.
inline constexpr double kNoteWeight = 0.3;
// Chance that noise alone makes some candidate of the misfit ranking "significant".
inline constexpr double kMisfitFamilyError = 0.01;

// The model's readings at some parameters, for every dataset sample.
struct Prediction {
  std::vector<std::array<double, kNumCables>> reading_n;  // gain T + bias
  std::vector<std::array<double, kNumCables>> sigma_n;    // whitening sigma from the reading
  std::vector<std::array<double, kNumCables>> whitened;   // (reading - measured) / sigma
  internal::CompactStarts starts;                          // the statics there (warm starts)
  // With lengths in the fit (else empty): s0 + offset, and (that - measured) / sigma_L.
  std::vector<std::array<double, kNumCables>> length_m;
  std::vector<std::array<double, kNumCables>> length_whitened;
};

struct Run {
  Run(const CableRobot& m, const CalibrationSpec& s, const Dataset& d, const CalibrationOptions& o,
      CalibrationResult* r, std::string* e)
      : model(m), spec(s), data(d), options(o), result(r), error(e) {}

  const CableRobot& model;
  const CalibrationSpec& spec;
  const Dataset& data;
  const CalibrationOptions& options;
  CalibrationResult* result;
  std::string* error;

  std::unique_ptr<CalibrationModel> cm;
  int n = 0;                  // free parameters
  int num_priors = 0;         // of the free parameters
  std::vector<int> fit;       // fitted samples (dataset indices, file order)
  std::vector<bool> is_fit;   // per dataset sample
  std::vector<double> theta;  // free parameters, SI
  StaticsOptions statics;
  std::unique_ptr<ceres::LossFunction> loss;  // a copy for the diagnostics (or null)
  Prediction at;                              // at the current theta
  // The weights and exclusions of the current problem, per fitted sample / dataset sample.
  std::vector<std::array<double, kNumCables>> sigma_n;
  ReadingMask excluded;
  // With lengths in the fit: the lengths kept out, per dataset sample, and the initial
  // model's predicted lengths (for the table before and after).
  ReadingMask length_excluded;
  std::vector<std::array<double, kNumCables>> initial_length_m;
  // The first prediction's readings when they are the RMS table's initial-model row at the
  // fit's attitude (PredictAndScreen; else empty), for Evaluate: a pass over the data saved.
  std::vector<std::array<double, kNumCables>> initial_reading_n;
  // The slow sensor error the current problem whitens by (inactive: white noise only),
  // and per fitted sample each reading's sigma_slow / sigma_white (sample_rows.h).
  SlowErrorProcess slow;
  std::vector<std::array<double, kNumCables>> slow_rho;
  std::unique_ptr<ceres::Problem> problem;
  const internal::FoldedTensionCost* folded = nullptr;  // the problem's data term (it owns it)
  // At the solution: the candidates of the misfit ranking (and consider parameters),
  // the linearisation, and the normal matrix with the priors.
  std::vector<ParameterSpec> candidates;
  std::vector<double> candidate_value_si;
  internal::Linearisation lin;
  Eigen::MatrixXd information;

  // The cabin's pose of sample `s` (its planned attitude with attitude: planned), with the
  // measured frame's point at `measured_offset_m` (Assemble's at theta): measured_frame.h.
  Pose PoseOf(const Sample& s, const Eigen::Vector3d& measured_offset_m) const {
    Pose pose = s.pose;
    if (spec.use_planned_attitude) pose.rotation = s.planned_rotation;
    return cm->CabinPose(pose, s.joint, measured_offset_m);
  }
  const ParameterSpec& Free(int k) const { return spec.parameters[cm->spec_index(k)]; }
  // The current prediction, the fitted samples and their exclusions.
  internal::PredictionView View() const {
    internal::PredictionView v;
    v.data = &data;
    v.reading_n = &at.reading_n;
    v.sigma_n = &at.sigma_n;
    v.fit = &fit;
    v.excluded = &excluded;
    return v;
  }
  // The fitted samples with the current weights, warm starts and exclusions.
  internal::FittedSamples Samples() const {
    internal::FittedSamples s;
    s.model = cm.get();
    s.data = &data;
    s.fit = &fit;
    s.sigma_n = &sigma_n;
    s.starts = &at.starts;
    s.excluded = &excluded;
    s.use_planned_attitude = spec.use_planned_attitude;
    s.statics = statics;
    s.slow_error = slow;
    s.slow_rho = &slow_rho;
    s.length_sigma_m = spec.length_sigma_m;
    s.length_excluded = &length_excluded;
    return s;
  }
  // Readings per sample: the tensions, and the lengths when the spec uses them.
  int Readings() const { return spec.UsesLengths() ? 2 * kNumCables : kNumCables; }
  CalibrationStatus Fail(CalibrationStatus status, const std::string& why) const {
    *error = why;
    return status;
  }
};

inline std::string Fixed(const char* format, double v) { return FormatDouble(format, v); }

inline std::string RatioText(double ratio) { return FormatDouble("%.1e", ratio); }

// " kg/m" after a value; nothing for a dimensionless one ("+-0.0879", not "+-0.0879 1").
inline std::string UnitAfter(const std::string& unit) { return unit == "1" ? "" : " " + unit; }

// x with P(chi-square(1 dof) > x) = tail: the square of the two-sided normal quantile.
inline double ChiSquare1Quantile(double tail) {
  const double z = TwoSidedNormalQuantile(tail);
  return z * z;
}

// Readings of the fitted samples kept out of the fit.
int CountExcluded(const Run& run);
// Reading i of dataset sample t at the current prediction (its whitened residual): a
// tension (i < 6) or, with lengths in the fit, the length of cable i - 6.
ReadingResidual ReadingAt(const Run& run, int t, int i);
// Whether reading i of sample t is kept out, and its whitened residual (ReadingAt's i).
bool ReadingExcluded(const Run& run, int t, int i);
double ReadingWhitened(const Run& run, int t, int i);

// Stages of calibration_diagnostics.cc.
CalibrationStatus FindWorstReadings(Run& run);
CalibrationStatus LineariseAtSolution(Run& run);
CalibrationStatus EstimateUncertainty(Run& run);
CalibrationStatus TestSensorStepsStage(Run& run);
CalibrationStatus ScanChanges(Run& run);
CalibrationStatus Diagnose(Run& run);
// Stages of calibration_verdict.cc.
CalibrationStatus Conclude(Run& run);
CalibrationStatus Evaluate(Run& run);
// The sensor-step test's verdict beside a refit's own.
void AddSensorStepVerdict(CalibrationResult* r);

}  // namespace fastcal::internal

#endif  // FASTCAL_SRC_CALIBRATION_CALIBRATION_RUN_H_
