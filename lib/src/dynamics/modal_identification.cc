// The eigensystem realisation algorithm on free decays, with bootstrap sigmas, and the
// free decays it is tested on (modal_identification.h has the equations and sources).
#include "fastcal/modal_identification.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <complex>
#include <random>
#include <string>
#include <vector>

#include "dynamics/record_preparation.h"
#include "fastcal/catenary.h"
#include "fastcal/statics.h"

namespace fastcal {
namespace {

using Complex = std::complex<double>;

// One identified pole with what the record needs to rebuild its part.
struct Pole {
  double frequency_hz = 0.0;
  double damping_ratio = 0.0;
  double amplitude = 0.0;
  Complex z;               // discrete-time eigenvalue
  Eigen::VectorXcd shape;  // C psi (scaled channels)
  Complex initial;         // q0
};

// Block Hankel matrix of y (p x n) from sample `shift`: r block rows, s columns.
Eigen::MatrixXd Hankel(const Eigen::MatrixXd& y, int rows, int cols, int shift) {
  const int p = static_cast<int>(y.rows());
  Eigen::MatrixXd h(rows * p, cols);
  for (int i = 0; i < rows; ++i) h.middleRows(i * p, p) = y.middleCols(i + shift, cols);
  return h;
}

// ERA of the scaled record y at model order `order`: its damped poles (positive
// frequency, damping in (0, max)), largest amplitude first.
std::vector<Pole> Realise(const Eigen::MatrixXd& y, double dt, int order, int rows,
                          double max_damping) {
  const int p = static_cast<int>(y.rows());
  const int cols = static_cast<int>(y.cols()) - rows;
  const Eigen::MatrixXd h0 = Hankel(y, rows, cols, 0), h1 = Hankel(y, rows, cols, 1);
  // H0 = U S V^T from the eigenpairs of H0 H0^T (rp x rp: small beside H0 itself).
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> gram(h0 * h0.transpose());
  const int n = static_cast<int>(gram.eigenvalues().size());
  const Eigen::MatrixXd u = gram.eigenvectors().rightCols(order).rowwise().reverse();
  const Eigen::VectorXd s = gram.eigenvalues().tail(order).reverse().cwiseMax(1e-300).cwiseSqrt();
  (void)n;
  const Eigen::VectorXd s_half = s.cwiseSqrt(), s_inv_half = s_half.cwiseInverse();
  // A = S^-1/2 U^T H1 V S^-1/2 with V = H0^T U S^-1.
  const Eigen::MatrixXd a = s_inv_half.asDiagonal() * u.transpose() * (h1 * h0.transpose()) * u *
                            s.cwiseInverse().asDiagonal() * s_inv_half.asDiagonal();
  const Eigen::MatrixXd c = u.topRows(p) * s_half.asDiagonal();
  const Eigen::VectorXd x0 = s_inv_half.asDiagonal() * (u.transpose() * h0.col(0));
  const Eigen::EigenSolver<Eigen::MatrixXd> eigen(a);
  const Eigen::MatrixXcd psi = eigen.eigenvectors();
  const Eigen::VectorXcd q0 = psi.partialPivLu().solve(x0.cast<Complex>());
  std::vector<Pole> poles;
  for (int i = 0; i < order; ++i) {
    const Complex z = eigen.eigenvalues()[i];
    if (!(z.imag() > 0.0)) continue;  // one of each conjugate pair; real poles are no modes
    const Complex pole = std::log(z) / dt;
    Pole m;
    m.frequency_hz = std::abs(pole) / (2.0 * M_PI);
    m.damping_ratio = -pole.real() / std::abs(pole);
    if (!(m.damping_ratio > 0.0 && m.damping_ratio < max_damping)) continue;
    m.z = z;
    m.shape = c.cast<Complex>() * psi.col(i);
    m.initial = q0[i];
    m.amplitude = 2.0 * m.shape.norm() * std::abs(q0[i]);
    poles.push_back(m);
  }
  std::sort(poles.begin(), poles.end(),
            [](const Pole& a, const Pole& b) { return a.amplitude > b.amplitude; });
  return poles;
}

// The record the poles describe: y_k = sum 2 Re(C psi z^k q0).
Eigen::MatrixXd Rebuild(const std::vector<Pole>& poles, int channels, int samples) {
  Eigen::MatrixXd y = Eigen::MatrixXd::Zero(channels, samples);
  for (const Pole& m : poles) {
    Complex zk = m.initial;
    for (int k = 0; k < samples; ++k) {
      y.col(k) += 2.0 * (m.shape * zk).real();
      zk *= m.z;
    }
  }
  return y;
}

// The `count` largest modes of y, or fewer when the record has fewer.
std::vector<Pole> Identify(const Eigen::MatrixXd& y, double dt, const EraOptions& o, int rows) {
  std::vector<Pole> poles = Realise(y, dt, 2 * o.modes + o.extra_order, rows, o.max_damping_ratio);
  if (static_cast<int>(poles.size()) > o.modes) poles.resize(o.modes);
  return poles;
}

// A moving-block bootstrap copy of `residual` (channels x samples).
Eigen::MatrixXd ResampleBlocks(const Eigen::MatrixXd& residual, int block, std::mt19937_64* rng) {
  const int n = static_cast<int>(residual.cols());
  const int b = std::min(block, n);
  std::uniform_int_distribution<int> start(0, n - b);
  Eigen::MatrixXd out(residual.rows(), n);
  for (int k = 0; k < n; k += b) {
    const int len = std::min(b, n - k);
    out.middleCols(k, len) = residual.middleCols(start(*rng), len);
  }
  return out;
}

// Each mode's sigma from `records` bootstrap records: the nearest mode in frequency of each
// record's identification.
void BootstrapSigmas(const Eigen::MatrixXd& y, double dt, const EraOptions& o, int rows,
                     const std::vector<Pole>& poles, std::vector<IdentifiedMode>* modes) {
  const Eigen::MatrixXd fit =
      Rebuild(poles, static_cast<int>(y.rows()), static_cast<int>(y.cols()));
  const Eigen::MatrixXd residual = y - fit;
  std::mt19937_64 rng(o.seed);
  std::vector<std::vector<double>> f(poles.size()), zeta(poles.size());
  for (int b = 0; b < o.bootstrap_records; ++b) {
    const std::vector<Pole> again =
        Identify(fit + ResampleBlocks(residual, o.bootstrap_block, &rng), dt, o, rows);
    for (size_t i = 0; i < poles.size() && !again.empty(); ++i) {
      const Pole* nearest = &again[0];
      for (const Pole& m : again) {
        if (std::abs(m.frequency_hz - poles[i].frequency_hz) <
            std::abs(nearest->frequency_hz - poles[i].frequency_hz)) {
          nearest = &m;
        }
      }
      f[i].push_back(nearest->frequency_hz);
      zeta[i].push_back(nearest->damping_ratio);
    }
  }
  auto sigma = [](const std::vector<double>& v) {
    if (v.size() < 2) return 0.0;
    double mean = 0.0, sum2 = 0.0;
    for (double x : v) mean += x / v.size();
    for (double x : v) sum2 += (x - mean) * (x - mean);
    return std::sqrt(sum2 / (v.size() - 1));
  };
  for (size_t i = 0; i < poles.size(); ++i) {
    (*modes)[i].frequency_sigma_hz = sigma(f[i]);
    (*modes)[i].damping_sigma = sigma(zeta[i]);
  }
}

}  // namespace

bool EraOptions::IsValid(std::string* error) const {
  if (!(min_frequency_hz > 0.0) || !(max_frequency_hz > min_frequency_hz) ||
      !std::isfinite(max_frequency_hz)) {
    *error = "era options: 0 < min_frequency_hz < max_frequency_hz (finite) is needed";
    return false;
  }
  if (modes < 1 || extra_order < 0 || block_rows < 0 || !(max_damping_ratio > 0.0) ||
      !(max_damping_ratio < 1.0) || bootstrap_records < 2 || bootstrap_block < 1) {
    *error =
        "era options: modes >= 1, extra_order >= 0, block_rows >= 0, max_damping_ratio in (0, "
        "1), bootstrap_records >= 2 and bootstrap_block >= 1 are needed";
    return false;
  }
  return true;
}

bool IdentifyModesEra(const VibrationRecord& record, const EraOptions& options,
                      std::vector<IdentifiedMode>* modes, std::string* error) {
  if (!options.IsValid(error)) return false;
  const int p = static_cast<int>(record.channels.rows());
  if (p < 1 || !(record.sample_interval_s > 0.0) || !record.channels.allFinite()) {
    *error = "record: needs at least one channel, finite samples and sample_interval_s > 0";
    return false;
  }
  const int factor = internal::DecimationFactor(record.sample_interval_s, options.max_frequency_hz);
  const double dt = factor * record.sample_interval_s;
  const int n = static_cast<int>(record.channels.cols()) / factor;
  const int order = 2 * options.modes + options.extra_order;
  const int rows =
      options.block_rows > 0
          ? options.block_rows
          : std::max((order + p - 1) / p + 1,
                     static_cast<int>(std::ceil(2.0 / (options.min_frequency_hz * dt))));
  if (n < 4 * rows) {
    *error = "record: " + std::to_string(record.channels.cols()) + " samples every " +
             std::to_string(record.sample_interval_s) + " s are too few for " +
             std::to_string(rows) + " block rows of " + std::to_string(dt) +
             " s (two periods of min_frequency_hz): need four times as long";
    return false;
  }
  const Eigen::MatrixXd y = internal::DecimatedScaled(record.channels, factor);
  const std::vector<Pole> poles = Identify(y, dt, options, rows);
  if (static_cast<int>(poles.size()) < options.modes) {
    *error = "found " + std::to_string(poles.size()) + " damped modes, fewer than the " +
             std::to_string(options.modes) + " asked for";
    return false;
  }
  modes->assign(poles.size(), IdentifiedMode());
  for (size_t i = 0; i < poles.size(); ++i) {
    (*modes)[i].frequency_hz = poles[i].frequency_hz;
    (*modes)[i].damping_ratio = poles[i].damping_ratio;
    (*modes)[i].amplitude = poles[i].amplitude;
  }
  BootstrapSigmas(y, dt, options, rows, poles, modes);
  std::sort(modes->begin(), modes->end(), [](const IdentifiedMode& a, const IdentifiedMode& b) {
    return a.frequency_hz < b.frequency_hz;
  });
  return true;
}

double EnvelopeDecayRatio(const VibrationRecord& record) {
  const Eigen::Index quarter = record.channels.cols() / 4;
  if (quarter < 1 || record.channels.rows() < 1) return 1.0;
  const Eigen::MatrixXd y = internal::DecimatedScaled(record.channels, 1);
  const double last = y.rightCols(quarter).squaredNorm();
  return last > 0.0 ? y.leftCols(quarter).squaredNorm() / last : 1.0;
}

bool SimulateFreeDecay(const FreeDecaySpec& spec, VibrationRecord* record, std::string* error) {
  const size_t m = spec.frequency_hz.size();
  const int channels = static_cast<int>(spec.shape.rows());
  if (m == 0 || spec.damping_ratio.size() != m || spec.shape.cols() != static_cast<int>(m) ||
      (!spec.phase_rad.empty() && spec.phase_rad.size() != m) ||
      spec.noise_sigma.size() != channels || !(spec.sample_interval_s > 0.0) ||
      !(spec.duration_s > spec.sample_interval_s)) {
    *error =
        "free decay: one frequency, damping (and phase) per mode, a shape column per mode, "
        "a noise sigma per channel, sample_interval_s > 0 and a longer duration_s";
    return false;
  }
  const int n = static_cast<int>(spec.duration_s / spec.sample_interval_s) + 1;
  record->sample_interval_s = spec.sample_interval_s;
  record->channels = Eigen::MatrixXd::Zero(channels, n);
  for (size_t j = 0; j < m; ++j) {
    const double w = 2.0 * M_PI * spec.frequency_hz[j], zeta = spec.damping_ratio[j];
    const double wd = w * std::sqrt(1.0 - zeta * zeta);
    const double phase = spec.phase_rad.empty() ? 0.0 : spec.phase_rad[j];
    for (int k = 0; k < n; ++k) {
      const double t = k * spec.sample_interval_s;
      record->channels.col(k) +=
          spec.shape.col(j) * (std::exp(-zeta * w * t) * std::cos(wd * t + phase));
    }
  }
  std::mt19937_64 rng(spec.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int k = 0; k < n; ++k) {
    for (int c = 0; c < channels; ++c) record->channels(c, k) += spec.noise_sigma[c] * normal(rng);
  }
  return true;
}

const char* ModeParameterName(int parameter) {
  static const char* const kNames[kModeParameters] = {"linear_density", "cabin_mass",
                                                      "cabin_inertia"};
  return parameter >= 0 && parameter < kModeParameters ? kNames[parameter] : "";
}

namespace {

// `robot` with parameter `p` scaled by `factor`.
CableRobot Scaled(CableRobot robot, int p, double factor) {
  if (p == 0) {
    for (CableProperties& c : robot.cables) c.linear_density_kg_per_m *= factor;
  } else if (p == 1) {
    robot.cabin_mass_kg *= factor;
  } else {
    robot.cabin_inertia_kg_m2 *= factor;
  }
  return robot;
}

// Each parameter's single-parameter weighted least-squares fit of the differences.
void FitParameters(ModesComparisonResult* result) {
  for (const ModeComparison& m : result->modes) {
    const double r = m.difference / std::max(m.difference_sigma, 1e-15);
    result->chi2_model += r * r;
  }
  const double dof = static_cast<double>(result->modes.size());
  result->agrees = result->chi2_model <= dof + 3.0 * std::sqrt(2.0 * dof);
  for (int p = 0; p < kModeParameters; ++p) {
    double sw = 0.0, sd = 0.0;
    for (const ModeComparison& m : result->modes) {
      const double w = 1.0 / std::max(m.difference_sigma * m.difference_sigma, 1e-30);
      sw += w * m.sensitivity[p] * m.sensitivity[p];
      sd += w * m.sensitivity[p] * m.difference;
    }
    ParameterFit& fit = result->fits[p];
    fit.relative_change = sw > 0.0 ? sd / sw : 0.0;
    fit.sigma = sw > 0.0 ? 1.0 / std::sqrt(sw) : HUGE_VAL;
    fit.chi2 = 0.0;
    for (const ModeComparison& m : result->modes) {
      const double r = (m.difference - m.sensitivity[p] * fit.relative_change) /
                       std::max(m.difference_sigma, 1e-15);
      fit.chi2 += r * r;
    }
    if (fit.chi2 < result->fits[result->best].chi2) result->best = p;
  }
}

}  // namespace

bool CompareWithPrediction(const CableRobot& robot, const Pose& pose,
                           const std::vector<IdentifiedMode>& identified,
                           const ModesOptions& options, ModesComparisonResult* result,
                           std::string* error) {
  constexpr double kStep = 0.01;  // each parameter's relative step for the sensitivities
  ModesResult nominal;
  if (!ComputeModes(robot, pose, options, &nominal, error)) return false;
  std::array<ModesResult, kModeParameters> stepped;
  for (int p = 0; p < kModeParameters; ++p) {
    if (!ComputeModes(Scaled(robot, p, 1.0 + kStep), pose, options, &stepped[p], error)) {
      return false;
    }
  }
  *result = ModesComparisonResult();
  for (const IdentifiedMode& id : identified) {
    ModeComparison c;
    c.identified = id;
    size_t nearest = 0;
    for (size_t i = 0; i < nominal.modes.size(); ++i) {
      if (std::abs(nominal.modes[i].frequency_hz - id.frequency_hz) <
          std::abs(nominal.modes[nearest].frequency_hz - id.frequency_hz)) {
        nearest = i;
      }
    }
    const Mode& m = nominal.modes[nearest];
    c.predicted_mode = static_cast<int>(nearest) + 1;
    c.predicted_hz = m.frequency_hz;
    c.predicted_cabin_share = m.CabinShare();
    c.difference = id.frequency_hz / m.frequency_hz - 1.0;
    c.difference_sigma = id.frequency_sigma_hz / m.frequency_hz;
    for (int p = 0; p < kModeParameters; ++p) {
      // The same mode after the step (a 1% step moves no mode past its neighbour's
      // frequency, except in a cluster; the index is kept).
      const double hz =
          stepped[p].modes[std::min(nearest, stepped[p].modes.size() - 1)].frequency_hz;
      c.sensitivity[p] = std::log(hz / m.frequency_hz) / std::log1p(kStep);
    }
    result->modes.push_back(c);
  }
  FitParameters(result);
  return true;
}

namespace {

// The six lower-end tensions (kN) at `pose` with the unstretched lengths of `statics`.
Eigen::Matrix<double, 6, 1> TensionsAtFixedLengths(const CableRobot& robot, const Pose& pose,
                                                   const StaticsSolution& statics) {
  Eigen::Matrix<double, 6, 1> t;
  for (int i = 0; i < kNumCables; ++i) {
    const CableProperties& c = robot.cables[i];
    const Eigen::Vector3d chord =
        c.tower_top_m - (pose.position_m + pose.rotation * robot.AnchorOfCable(i));
    CatenaryForces f;
    int iterations = 0;
    SolveCatenaryForcesDouble(chord.head<2>().norm(), chord.z(),
                              statics.cables[i].unstretched_length_m, c.ea_n,
                              c.linear_density_kg_per_m * robot.gravity_m_per_s2,
                              CatenarySolverOptions(), nullptr, &f, &iterations);
    t[i] = std::hypot(f.fl_n, f.fz_n) / 1e3;
  }
  return t;
}

// d(tension kN)/d(u, theta) by central differences (R -> exp(theta) R).
Eigen::Matrix<double, 6, 6> TensionPerCabinMotion(const CableRobot& robot, const Pose& pose,
                                                  const StaticsSolution& statics) {
  constexpr double kStepM = 1e-3, kStepRad = 1e-5;
  Eigen::Matrix<double, 6, 6> j;
  for (int k = 0; k < 6; ++k) {
    const double h = k < 3 ? kStepM : kStepRad;
    Pose plus = pose, minus = pose;
    if (k < 3) {
      plus.position_m[k] += h;
      minus.position_m[k] -= h;
    } else {
      const Eigen::Vector3d axis = Eigen::Vector3d::Unit(k - 3);
      plus.rotation = Eigen::AngleAxisd(h, axis).toRotationMatrix() * pose.rotation;
      minus.rotation = Eigen::AngleAxisd(-h, axis).toRotationMatrix() * pose.rotation;
    }
    j.col(k) = (TensionsAtFixedLengths(robot, plus, statics) -
                TensionsAtFixedLengths(robot, minus, statics)) /
               (2.0 * h);
  }
  return j;
}

}  // namespace

bool SimulateVibrationRecord(const CableRobot& robot, const Pose& pose,
                             const VibrationRecordSpec& spec, VibrationRecord* record,
                             std::string* error) {
  if (spec.modes.empty() || spec.damping_ratio.size() != spec.modes.size() ||
      !(spec.amplitude_m > 0.0) || !(spec.position_noise_m >= 0.0) ||
      !(spec.attitude_noise_deg >= 0.0) || !(spec.tension_noise_kn >= 0.0)) {
    *error =
        "vibration record: one damping ratio per excited mode, amplitude_m > 0 and "
        "noise sigmas >= 0 are needed";
    return false;
  }
  ModesOptions options = spec.modes_options;
  options.modes = std::max(options.modes, *std::max_element(spec.modes.begin(), spec.modes.end()));
  ModesResult predicted;
  if (!ComputeModes(robot, pose, options, &predicted, error)) return false;
  const Eigen::Matrix<double, 6, 6> tension = TensionPerCabinMotion(robot, pose, predicted.statics);
  FreeDecaySpec decay;
  decay.shape.resize(12, static_cast<int>(spec.modes.size()));
  for (size_t j = 0; j < spec.modes.size(); ++j) {
    const int m = spec.modes[j];
    if (m < 1 || m > static_cast<int>(predicted.modes.size())) {
      *error = "vibration record: mode " + std::to_string(m) + " is not among the " +
               std::to_string(predicted.modes.size()) + " predicted";
      return false;
    }
    const Mode& mode = predicted.modes[m - 1];
    const double scale =
        spec.amplitude_m / std::max(mode.cabin_shape.head<3>().cwiseAbs().maxCoeff(), 1e-300);
    const Eigen::Matrix<double, 6, 1> motion = scale * mode.cabin_shape;
    decay.shape.col(j).head<3>() = motion.head<3>();
    decay.shape.col(j).segment<3>(3) = motion.tail<3>() * (180.0 / M_PI);
    decay.shape.col(j).tail<6>() = tension * motion;
    decay.frequency_hz.push_back(mode.frequency_hz);
    decay.damping_ratio.push_back(spec.damping_ratio[j]);
    decay.phase_rad.push_back(0.0);
  }
  decay.noise_sigma.resize(12);
  decay.noise_sigma << Eigen::Vector3d::Constant(spec.position_noise_m),
      Eigen::Vector3d::Constant(spec.attitude_noise_deg),
      Eigen::Matrix<double, 6, 1>::Constant(spec.tension_noise_kn);
  decay.sample_interval_s = spec.sample_interval_s;
  decay.duration_s = spec.duration_s;
  decay.seed = spec.seed;
  if (!SimulateFreeDecay(decay, record, error)) return false;
  Eigen::Matrix<double, 12, 1> base;
  base << pose.position_m, RpyDegFromRotation(pose.rotation), Eigen::Matrix<double, 6, 1>::Zero();
  for (int i = 0; i < kNumCables; ++i)
    base[6 + i] = predicted.statics.cables[i].lower_tension_n / 1e3;
  record->channels.colwise() += base;
  return true;
}

}  // namespace fastcal
