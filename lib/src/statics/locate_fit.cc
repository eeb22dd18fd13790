// The pose from measured lengths, attitude and tensions together (locate.h,
// LocateFromMeasurements): Gauss-Newton over the pose x = (r_p, rotation vector), each
// trial pose's model readings from the inverse statics (statics.h, exact) and their
// derivatives from the forward problem's blocks at that equilibrium
// (fastcal/internal/forward_statics.h):
//   ds0/dx  = -G^-1 K                          (the lengths that hold the cabin at x)
//   dF_i/dx = -D_i^-1 (P_i + g_i ds0_i/dx)     (their forces)
//   dT_i/dx = F_i^T dF_i/dx / T_i,   reading_i = gain_i T_i + bias_i
// Whitened residuals, model minus measured:
//   lengths   (s0_i(x) - s0_meas,i) / sigma_L
//   tensions  (reading_i(x) - T_meas,i) / sigma_i,  sigma_i^2 = sigma_abs^2 + (pct/100 reading_i)^2
//             (the calibration's noise model: the predicted reading, not the measured one)
//   attitude  log(R(x) R_meas^T) / sigma_att      (rotation vector, global axes), whose
//             derivative is J_l^-1(phi), the inverse left Jacobian of SO(3)
//             (forward_statics.h)
// The covariance of the fitted pose is (J^T J)^-1; for lengths alone, sigma_L^2 (dx/ds0)
// (dx/ds0)^T. The answer is then passed through Locate at the fitted pose's own lengths (a
// warm start already at its answer) for the checks, the stability and the search.
#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <string>

#include "fastcal/internal/forward_statics.h"
#include "fastcal/locate.h"

namespace fastcal {
namespace {

using internal::ForwardLinearisation;
using internal::ForwardState;
using internal::Matrix6d;
using internal::Vector6d;

constexpr int kMaxReadings = 2 * kNumCables + 3;
using Residuals = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxReadings, 1>;
using Jacobian = Eigen::Matrix<double, Eigen::Dynamic, 6, 0, kMaxReadings, 6>;

// The fit is converged when its step moves the anchors by at most this (m) or
// LocateOptions::tolerance_m, whichever is larger: measured lengths and tensions determine
// the pose to millimetres, so a finer optimum is rounding.
constexpr double kFitToleranceM = 1e-8;
// A fit step whose cost rises is halved at most this many times.
constexpr int kMaxFitHalvings = 10;

// The model's readings at one trial pose, whitened, with their Jacobian.
struct FitPoint {
  Pose pose;
  StaticsSolution statics;  // the inverse statics there (its forces and lengths)
  Residuals r;
  Jacobian j;
  double cost = 0.0;
  LocateFit fit;  // residuals in units (model minus measured)
  // The tension rows' sigmas: those used in r and j (frozen: the step's start's), and
  // this point's own, from its predicted readings (Reweight).
  std::array<double, kNumCables> used_sigma_n{}, own_sigma_n{};
  int first_tension_row = -1;  // -1: no tension rows
};

// The tension rows of *f divided by its own sigmas instead of the frozen ones.
void Reweight(FitPoint* f) {
  for (int i = 0; i < kNumCables && f->first_tension_row >= 0; ++i) {
    const double scale = f->used_sigma_n[i] / f->own_sigma_n[i];
    f->r[f->first_tension_row + i] *= scale;
    f->j.row(f->first_tension_row + i) *= scale;
    f->used_sigma_n[i] = f->own_sigma_n[i];
  }
  f->cost = f->r.squaredNorm();
  f->fit.chi2 = f->cost;
}

// d(s0)/dx and d(T_i)/dx at an equilibrium (file comment); false where G or K is singular.
bool ReadingDerivatives(const ForwardLinearisation& lin, const ForwardState& x,
                        Matrix6d* length_per_pose, Matrix6d* tension_per_pose) {
  *length_per_pose = -lin.length_coupling.partialPivLu().solve(lin.stiffness);
  if (!length_per_pose->allFinite()) return false;
  for (int i = 0; i < kNumCables; ++i) {
    Eigen::Matrix<double, 3, 6> p;
    p << Eigen::Matrix3d::Identity(), -internal::Skew(lin.r[i]);
    const Eigen::Matrix<double, 3, 6> df =
        -lin.ends[i].d_inverse * (p + lin.ends[i].de_ds0 * length_per_pose->row(i));
    tension_per_pose->row(i) = x.force_n[i].transpose() * df / x.force_n[i].norm();
  }
  return true;
}

// The fit's residuals and Jacobian at `pose`; `warm` starts the inverse statics. The
// tensions are divided by `frozen_sigma_n` when not null (a trial step is judged by the
// cost of its start's weights), else by the sigmas of their own predicted readings. A
// status other than ok where the model has no answer there.
StaticsStatus EvaluateFit(const CableRobot& robot, const StaticsParameters<double>& p,
                          const LocateMeasurement& m, const LocateNoise& noise,
                          const LocateOptions& options, const StaticsSolution& warm,
                          const Pose& pose, const std::array<double, kNumCables>* frozen_sigma_n,
                          FitPoint* f) {
  StaticsOptions so = options.statics;
  so.method = StaticsMethod::kExact;
  so.warm_start = true;
  f->pose = pose;
  f->statics = warm;
  const StaticsStatus status = SolveStaticsWithParameters(p, pose, so, &f->statics);
  if (status != StaticsStatus::kOk) return status;
  ForwardState x;
  x.pose = pose;
  internal::Lengths s0;
  for (int i = 0; i < kNumCables; ++i) {
    x.force_n[i] = f->statics.cables[i].force_n;
    s0[i] = f->statics.cables[i].unstretched_length_m;
  }
  ForwardLinearisation lin;
  Matrix6d ds0, dt;
  if (!internal::LineariseForward(p, internal::MakeForwardScales(p), s0, x, &lin) ||
      !ReadingDerivatives(lin, x, &ds0, &dt)) {
    return StaticsStatus::kSingular;
  }
  f->fit = LocateFit();
  f->r.resize(kMaxReadings);
  f->j.resize(kMaxReadings, 6);
  int n = 0;
  for (int i = 0; i < kNumCables; ++i, ++n) {
    f->fit.length_residual_m[i] = s0[i] - m.length_m[i];
    f->r[n] = f->fit.length_residual_m[i] / noise.length_sigma_m;
    f->j.row(n) = ds0.row(i) / noise.length_sigma_m;
  }
  f->first_tension_row = m.has_tensions ? n : -1;
  if (m.has_tensions) {
    for (int i = 0; i < kNumCables; ++i, ++n) {
      const CableProperties& c = robot.cables[i];
      const double reading = c.SensorReadingN(f->statics.cables[i].lower_tension_n);
      const double relative = noise.tension_sigma_percent / 100.0 * reading;
      f->own_sigma_n[i] =
          std::sqrt(noise.tension_sigma_n * noise.tension_sigma_n + relative * relative);
      const double sigma = frozen_sigma_n != nullptr ? (*frozen_sigma_n)[i] : f->own_sigma_n[i];
      f->used_sigma_n[i] = sigma;
      f->fit.tension_residual_n[i] = reading - m.tension_n[i];
      f->r[n] = f->fit.tension_residual_n[i] / sigma;
      f->j.row(n) = c.sensor_gain * dt.row(i) / sigma;
    }
  }
  if (m.has_attitude) {
    const double sigma = noise.attitude_sigma_deg * M_PI / 180.0;
    const Eigen::Vector3d phi = internal::RotationDifference(pose.rotation, m.rotation);
    f->fit.attitude_residual_rad = phi;
    f->r.segment<3>(n) = phi / sigma;
    f->j.block<3, 3>(n, 0).setZero();
    f->j.block<3, 3>(n, 3) = internal::InverseLeftJacobian(phi) / sigma;
    n += 3;
  }
  f->r.conservativeResize(n);
  f->j.conservativeResize(n, 6);
  f->cost = f->r.squaredNorm();
  f->fit.readings = n;
  f->fit.chi2 = f->cost;
  return StaticsStatus::kOk;
}

// Gauss-Newton from *f (evaluated at the lengths' answer, with its own weights) until its
// step is small. The tensions' weights follow the predicted readings (iteratively
// reweighted, as the calibration's passes): a step is judged by the cost with its start's
// weights, which it never raises (a step that would is halved), then reweighted.
StaticsStatus FitPose(const CableRobot& robot, const StaticsParameters<double>& p,
                      const LocateMeasurement& m, const LocateNoise& noise,
                      const LocateOptions& options, FitPoint* f) {
  const internal::ForwardScales scales = internal::MakeForwardScales(p);
  const double tolerance_m = std::max(options.tolerance_m, kFitToleranceM);
  FitPoint trial;
  for (int it = 0; it < options.max_iterations; ++it) {
    const Matrix6d normal = f->j.transpose() * f->j;
    const Vector6d dx = normal.ldlt().solve(-f->j.transpose() * f->r);
    if (!dx.allFinite()) return StaticsStatus::kSingular;
    const double step = internal::StepSizeM(dx, scales.size_m);
    if (step <= tolerance_m) {
      f->fit.iterations = it;
      return StaticsStatus::kOk;
    }
    double fraction = 1.0;
    bool accepted = false;
    for (int h = 0; h <= kMaxFitHalvings && !accepted; ++h, fraction *= 0.5) {
      ForwardState moved;
      moved.pose = f->pose;
      moved = internal::MoveState(moved, dx, internal::ZeroForces(), fraction);
      accepted = EvaluateFit(robot, p, m, noise, options, f->statics, moved.pose, &f->used_sigma_n,
                             &trial) == StaticsStatus::kOk &&
                 (trial.cost <= f->cost || fraction * step <= tolerance_m);
    }
    if (!accepted) return StaticsStatus::kNotConverged;
    *f = trial;
    Reweight(f);
  }
  return StaticsStatus::kNotConverged;
}

bool MeasurementUsable(const LocateMeasurement& m) {
  if (m.has_attitude) {
    if (!m.rotation.allFinite()) return false;
    constexpr double kRotationTolerance = 1e-6;
    if (!((m.rotation.transpose() * m.rotation - Eigen::Matrix3d::Identity())
              .cwiseAbs()
              .maxCoeff() <= kRotationTolerance)) {
      return false;
    }
  }
  for (int i = 0; i < kNumCables && m.has_tensions; ++i) {
    if (!std::isfinite(m.tension_n[i])) return false;
  }
  return true;
}

}  // namespace

bool LocateNoise::IsValid(std::string* error) const {
  std::string e;
  if (!(length_sigma_m > 0.0) || !std::isfinite(length_sigma_m)) {
    e = "length_sigma_m must be > 0 and finite";
  } else if (!(tension_sigma_n >= 0.0) || !(tension_sigma_percent >= 0.0) ||
             !std::isfinite(tension_sigma_n) || !std::isfinite(tension_sigma_percent) ||
             !(tension_sigma_n > 0.0 || tension_sigma_percent > 0.0)) {
    e = "tension_sigma_n and tension_sigma_percent must be >= 0, finite and not both 0";
  } else if (!(attitude_sigma_deg > 0.0) || !std::isfinite(attitude_sigma_deg)) {
    e = "attitude_sigma_deg must be > 0 and finite";
  }
  if (e.empty()) return true;
  if (error != nullptr) *error = e;
  return false;
}

StaticsStatus LocateFromMeasurements(const CableRobot& robot, const LocateMeasurement& measured,
                                     const LocateNoise& noise, const LocateOptions& options,
                                     LocateSolution* solution) {
  if (!noise.IsValid(nullptr) || !MeasurementUsable(measured)) {
    ResetLocateSolution(measured.length_m, solution);
    return solution->status = solution->statics.status = StaticsStatus::kInvalidInput;
  }
  // The encoders' zeros removed: the unstretched lengths the statics hold (residuals,
  // model minus measured, are unchanged by moving the offset to the other side).
  LocateMeasurement measurement = measured;
  for (int i = 0; i < kNumCables; ++i) measurement.length_m[i] -= robot.cables[i].length_offset_m;
  StaticsStatus status = Locate(robot, measurement.length_m, options, solution);
  if (status != StaticsStatus::kOk) return status;
  const double variance = noise.length_sigma_m * noise.length_sigma_m;
  if (!measurement.has_attitude && !measurement.has_tensions) {
    solution->fit.readings = kNumCables;
    solution->fit.covariance =
        variance * solution->pose_per_length * solution->pose_per_length.transpose();
    return status;
  }
  const StaticsParameters<double> p = MakeStaticsParameters(robot);
  FitPoint f;
  status = EvaluateFit(robot, p, measurement, noise, options, solution->statics, solution->pose,
                       nullptr, &f);
  if (status == StaticsStatus::kOk) status = FitPose(robot, p, measurement, noise, options, &f);
  if (status != StaticsStatus::kOk) {
    ResetLocateSolution(measurement.length_m, solution);
    return solution->status = solution->statics.status = status;
  }
  // The fitted pose through Locate at its own lengths: a warm start at its answer.
  solution->pose = f.pose;
  solution->pose_per_length.setZero();
  solution->force_per_length.setZero();
  for (int i = 0; i < kNumCables; ++i) {
    solution->force_n[i] = f.statics.cables[i].force_n;
    solution->unstretched_length_m[i] = f.statics.cables[i].unstretched_length_m;
  }
  LocateOptions warm = options;
  warm.warm_start = true;
  const std::array<double, kNumCables> lengths = solution->unstretched_length_m;
  status = Locate(robot, lengths, warm, solution);
  if (status != StaticsStatus::kOk) return status;
  f.fit.fitted = true;
  f.fit.covariance = (f.j.transpose() * f.j).inverse();
  solution->fit = f.fit;
  return status;
}

Eigen::Matrix3d RpyDegPerRotationVector(const Eigen::Matrix3d& rotation) {
  // R = Rz(yaw) Ry(pitch) Rx(roll): the angular velocity (global axes) is
  // E (droll, dpitch, dyaw) with E = (Rz Ry e_x, Rz e_y, e_z).
  const Eigen::Vector3d rpy_rad = RpyDegFromRotation(rotation) * M_PI / 180.0;
  const Eigen::Matrix3d rz =
      Eigen::AngleAxisd(rpy_rad.z(), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d ry =
      Eigen::AngleAxisd(rpy_rad.y(), Eigen::Vector3d::UnitY()).toRotationMatrix();
  Eigen::Matrix3d e;
  e << rz * ry * Eigen::Vector3d::UnitX(), rz * Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ();
  return e.inverse() * (180.0 / M_PI);
}

}  // namespace fastcal
