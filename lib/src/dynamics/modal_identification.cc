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
#include "fastcal/cable.h"
#include "fastcal/catenary.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/plausibility.h"
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

// G0 = H0 H0^T and G1 = H1 H0^T of the block Hankel matrices of y (p x n), r block rows
// and s = n - r columns, H0 = [y_{i+j}], H1 = [y_{i+j+1}] (block row i, column j),
// without forming them: block (i, k) of G0 is sum_j y_{i+j} y_{k+j}^T, and each block a
// step down the diagonal differs from the one before by the first term and the one past
// the last, G0(i, k) = G0(i-1, k-1) - y_{i-1} y_{k-1}^T + y_{i-1+s} y_{k-1+s}^T (and
// G1(i, k) = G1(i-1, k-1) - y_i y_{k-1}^T + y_{i+s} y_{k-1+s}^T). Only the first block row
// and column take a pass over the record: about 3 r p^2 s operations, not 2 (r p)^2 s,
// and memory (r p)^2, not the Hankel matrices' 2 r p s (issue 57).
void HankelGrams(const Eigen::MatrixXd& y, int rows, Eigen::MatrixXd* g0, Eigen::MatrixXd* g1) {
  const int p = static_cast<int>(y.rows());
  const int cols = static_cast<int>(y.cols()) - rows;
  g0->resize(rows * p, rows * p);
  g1->resize(rows * p, rows * p);
  auto sum = [&](int a, int b) {  // sum_{j < cols} y_{a+j} y_{b+j}^T
    return Eigen::MatrixXd(y.middleCols(a, cols) * y.middleCols(b, cols).transpose());
  };
  auto outer = [&](int a, int b) { return Eigen::MatrixXd(y.col(a) * y.col(b).transpose()); };
  for (int k = 0; k < rows; ++k) {
    g0->block(0, k * p, p, p) = sum(0, k);
    g1->block(0, k * p, p, p) = sum(1, k);
    g1->block(k * p, 0, p, p) = sum(k + 1, 0);
  }
  for (int i = 1; i < rows; ++i) {
    for (int k = i; k < rows; ++k) {
      g0->block(i * p, k * p, p, p) = g0->block((i - 1) * p, (k - 1) * p, p, p) -
                                      outer(i - 1, k - 1) + outer(i - 1 + cols, k - 1 + cols);
    }
    for (int k = 1; k < rows; ++k) {
      g1->block(i * p, k * p, p, p) = g1->block((i - 1) * p, (k - 1) * p, p, p) - outer(i, k - 1) +
                                      outer(i + cols, k - 1 + cols);
    }
  }
  for (int i = 1; i < rows; ++i) {  // G0 is symmetric: its lower blocks from the upper
    for (int k = 0; k < i; ++k) {
      g0->block(i * p, k * p, p, p) = g0->block(k * p, i * p, p, p).transpose();
    }
  }
}

// ERA of the scaled record y at model order `order`: its damped poles in the band
// (frequency in [min, max], damping in (0, max)), largest amplitude first.
std::vector<Pole> Realise(const Eigen::MatrixXd& y, double dt, int order, int rows,
                          const EraOptions& options) {
  const int p = static_cast<int>(y.rows());
  Eigen::MatrixXd g0, g1;
  HankelGrams(y, rows, &g0, &g1);
  // H0 = U S V^T from the eigenpairs of H0 H0^T (rp x rp: small beside H0 itself).
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> gram(g0);
  const Eigen::MatrixXd u = gram.eigenvectors().rightCols(order).rowwise().reverse();
  const Eigen::VectorXd s = gram.eigenvalues().tail(order).reverse().cwiseMax(1e-300).cwiseSqrt();
  const Eigen::VectorXd s_half = s.cwiseSqrt(), s_inv_half = s_half.cwiseInverse();
  // A = S^-1/2 U^T H1 V S^-1/2 with V = H0^T U S^-1.
  const Eigen::MatrixXd a = s_inv_half.asDiagonal() * u.transpose() * g1 * u *
                            s.cwiseInverse().asDiagonal() * s_inv_half.asDiagonal();
  const Eigen::MatrixXd c = u.topRows(p) * s_half.asDiagonal();
  // H0's first column: y_0 .. y_{r-1} stacked (y is column-major: they are contiguous).
  const Eigen::VectorXd h0_first = Eigen::Map<const Eigen::VectorXd>(y.data(), rows * p);
  const Eigen::VectorXd x0 = s_inv_half.asDiagonal() * (u.transpose() * h0_first);
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
    if (!(m.damping_ratio > 0.0 && m.damping_ratio < options.max_damping_ratio)) continue;
    // Outside the band sought: not one of its modes (issue 57: 0.87 Hz, fitting the
    // noise, was matched to a predicted mode at +136%).
    if (!(m.frequency_hz >= options.min_frequency_hz &&
          m.frequency_hz <= options.max_frequency_hz)) {
      continue;
    }
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
  std::vector<Pole> poles = Realise(y, dt, 2 * o.modes + o.extra_order, rows, o);
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
  // The Hankel matrices' block rows grow with the band's width (up to 16 times
  // max_frequency_hz / min_frequency_hz) and with the order; their Grams with the square:
  // bounded, so that no option asks for gigabytes (issue 57).
  if (max_frequency_hz > kMaxEraBandRatio * min_frequency_hz) {
    *error = "era options: max_frequency_hz must be at most " +
             std::to_string(static_cast<int>(kMaxEraBandRatio)) + " times min_frequency_hz";
    return false;
  }
  if (modes < 1 || modes > kMaxIdentifiedModes || extra_order < 0 ||
      extra_order > kMaxEraExtraOrder || block_rows < 0 || block_rows > kMaxEraBlockRows ||
      !(max_damping_ratio > 0.0) || !(max_damping_ratio < 1.0) || bootstrap_records < 2 ||
      bootstrap_records > kMaxBootstrapRecords || bootstrap_block < 1) {
    *error = "era options: modes in [1, " + std::to_string(kMaxIdentifiedModes) +
             "], extra_order in [0, " + std::to_string(kMaxEraExtraOrder) +
             "], block_rows in [0, " + std::to_string(kMaxEraBlockRows) +
             "], max_damping_ratio in (0, 1), bootstrap_records in [2, " +
             std::to_string(kMaxBootstrapRecords) + "] and bootstrap_block >= 1 are needed";
    return false;
  }
  return true;
}

namespace {

// How ERA takes a record (EraOptions): averaged over blocks of `factor` samples into
// `samples` samples `interval_s` apart, with `rows` block rows. Counted in double: a
// record re-stamped every 1e-12 s asked for blocks of 5e11 samples (issue 57: the int cast
// overflowed, which is undefined).
struct EraPlan {
  double factor = 1.0;
  double interval_s = 0.0;
  double samples = 0.0;
  double rows = 0.0;
};

EraPlan PlanOf(const VibrationRecord& record, const EraOptions& options) {
  EraPlan plan;
  const double p = static_cast<double>(record.channels.rows());
  const double order = 2.0 * options.modes + options.extra_order;
  plan.factor =
      std::max(1.0, std::floor(1.0 / (4.0 * options.max_frequency_hz * record.sample_interval_s)));
  plan.interval_s = plan.factor * record.sample_interval_s;
  plan.samples = std::floor(static_cast<double>(record.channels.cols()) / plan.factor);
  plan.rows = options.block_rows > 0
                  ? options.block_rows
                  : std::max(std::ceil(order / p) + 1.0,
                             std::ceil(2.0 / (options.min_frequency_hz * plan.interval_s)));
  return plan;
}

std::string Num(double value) { return internal::FormatDouble("%.6g", value); }

// The modes the record determines (issue 57: asked for 6 where 3 were excited, ERA's
// extra poles, fitting the noise, were matched to predicted modes at +113%): a frequency
// sigma under kMaxRelativeFrequencySigma of the frequency (the noise's poles wander by
// 20-30% from one bootstrap record to the next), and an amplitude of at least
// kMinRelativeAmplitude of the largest mode's (a noise-free record's extra poles, whose
// bootstrap cannot wander, carry 1e-10 of it). False, saying how many are determined,
// when fewer than the modes asked for remain.
bool KeepDeterminedModes(const EraOptions& options, std::vector<IdentifiedMode>* modes,
                         std::string* error) {
  double largest = 0.0;
  for (const IdentifiedMode& m : *modes) largest = std::max(largest, m.amplitude);
  std::vector<IdentifiedMode> kept;
  for (const IdentifiedMode& m : *modes) {
    if (m.frequency_sigma_hz <= kMaxRelativeFrequencySigma * m.frequency_hz &&
        m.amplitude >= kMinRelativeAmplitude * largest) {
      kept.push_back(m);
    }
  }
  if (static_cast<int>(kept.size()) < options.modes) {
    *error = "the record determines " + std::to_string(kept.size()) + " of the " +
             std::to_string(options.modes) +
             " modes asked for (the others' frequencies wander by more than " +
             Num(100 * kMaxRelativeFrequencySigma) +
             "% between bootstrap records, or they carry under " + Num(kMinRelativeAmplitude) +
             " of the largest mode's amplitude: noise, not "
             "vibration): ask for " +
             std::to_string(kept.size());
    return false;
  }
  *modes = std::move(kept);
  return true;
}

}  // namespace

bool CheckRecordSampling(const VibrationRecord& record, const EraOptions& options,
                         std::string* error) {
  if (!options.IsValid(error)) return false;
  const long long n = record.channels.cols();
  if (record.channels.rows() < 1 || !(record.sample_interval_s > 0.0) ||
      !std::isfinite(record.sample_interval_s) || n > kMaxRecordSamples) {
    *error = "record: needs at least one channel, sample_interval_s > 0 and at most " +
             std::to_string(kMaxRecordSamples) + " samples";
    return false;
  }
  const std::string what = "the record (" + std::to_string(n) + " samples every " +
                           Num(record.sample_interval_s) + " s)";
  const std::string band = "the band searched, " + Num(options.min_frequency_hz) + " to " +
                           Num(options.max_frequency_hz) + " Hz";
  const double fastest_interval_s = 1.0 / (4.0 * options.max_frequency_hz);
  if (record.sample_interval_s > fastest_interval_s) {
    *error = what + " is sampled too slowly for " + band +
             ": 4 samples a period of its top, one every " + Num(fastest_interval_s) +
             " s or faster, are needed";
    return false;
  }
  const double span_s = (n - 1) * record.sample_interval_s;
  const double longest_s = kMaxRecordPeriods / options.min_frequency_hz;
  if (span_s > longest_s) {
    *error = what + " spans " + Num(span_s) + " s, longer than any free decay in " + band +
             " lasts (at most " + Num(longest_s) + " s, " + Num(kMaxRecordPeriods) +
             " periods of its bottom): cut the record to the decay";
    return false;
  }
  const EraPlan plan = PlanOf(record, options);
  if (plan.samples < 4.0 * plan.rows) {
    const double shortest_s = 4.0 * plan.rows * plan.interval_s;
    *error = what + " spans " + Num(span_s) + " s, too short for " + band + ": at least " +
             Num(shortest_s) + " s are needed (four times " + Num(plan.rows) + " block rows of " +
             Num(plan.interval_s) + " s, two periods of its bottom)";
    return false;
  }
  return true;
}

bool IdentifyModesEra(const VibrationRecord& record, const EraOptions& options,
                      std::vector<IdentifiedMode>* modes, std::string* error) {
  if (!CheckRecordSampling(record, options, error)) return false;
  if (!record.channels.allFinite()) {
    *error = "record: its samples must be finite";
    return false;
  }
  // Within int now: CheckRecordSampling bounds the samples, so the block and the rows.
  const EraPlan plan = PlanOf(record, options);
  const int factor = static_cast<int>(plan.factor);
  const double dt = plan.interval_s;
  const int rows = static_cast<int>(plan.rows);
  const Eigen::MatrixXd y = internal::DecimatedScaled(record.channels, factor);
  const std::vector<Pole> poles = Identify(y, dt, options, rows);
  // Fewer damped poles than asked for go on to the bootstrap: the shortfall is then said
  // once, by KeepDeterminedModes, with the modes the record does determine (a noise-free
  // record's extra poles are rounding, damped on one machine and not on another).
  if (poles.empty()) {
    *error = "found no damped mode in the band searched (asked for " +
             std::to_string(options.modes) + ")";
    return false;
  }
  modes->assign(poles.size(), IdentifiedMode());
  for (size_t i = 0; i < poles.size(); ++i) {
    (*modes)[i].frequency_hz = poles[i].frequency_hz;
    (*modes)[i].damping_ratio = poles[i].damping_ratio;
    (*modes)[i].amplitude = poles[i].amplitude;
  }
  BootstrapSigmas(y, dt, options, rows, poles, modes);
  if (!KeepDeterminedModes(options, modes, error)) return false;
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
  // Counted in double first: the int cast of a count beyond its range is undefined (issue
  // 57: an interval of 1e-300 s asked for 4e302 samples).
  const double samples = std::floor(spec.duration_s / spec.sample_interval_s) + 1.0;
  if (!(samples <= static_cast<double>(kMaxRecordSamples))) {
    *error = "free decay: duration_s / sample_interval_s = " +
             internal::FormatDouble("%.3g", spec.duration_s / spec.sample_interval_s) +
             " samples, more than the " + std::to_string(kMaxRecordSamples) + " a record may hold";
    return false;
  }
  const int n = static_cast<int>(samples);
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
  ModesResult nominal, coarse;
  if (!ComputeModes(robot, pose, options, &nominal, error)) return false;
  // The prediction's own error: the lumped chain's frequencies converge as 1/N^2, so a
  // chain of N/2 segments tells it, (f_N - f_N/2) / 3 (issue 57: a noise-free record of
  // the model itself, identified to 1e-12, "disagreed with the model" at chi2 1e11).
  ModesOptions coarse_options = options;
  coarse_options.segments = std::max(2, options.segments / 2);
  if (!ComputeModes(robot, pose, coarse_options, &coarse, error)) return false;
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
    c.prediction_sigma =
        nearest < coarse.modes.size()
            ? std::abs(m.frequency_hz - coarse.modes[nearest].frequency_hz) / (3.0 * m.frequency_hz)
            : 0.0;
    c.difference_sigma = std::hypot(id.frequency_sigma_hz / m.frequency_hz, c.prediction_sigma);
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

// The six lower-end tensions (kN) at `pose` with the unstretched lengths of `statics`;
// false where a catenary has no solution.
bool TensionsAtFixedLengths(const CableRobot& robot, const Pose& pose,
                            const StaticsSolution& statics, Eigen::Matrix<double, 6, 1>* t) {
  for (int i = 0; i < kNumCables; ++i) {
    const CableProperties& c = robot.cables[i];
    const Eigen::Vector3d chord =
        c.tower_top_m - (pose.position_m + pose.rotation * robot.AnchorOfCable(i));
    CatenaryForces f;
    int iterations = 0;
    if (Cable::Of(c).Forces(chord.head<2>().norm(), chord.z(),
                            statics.cables[i].unstretched_length_m, robot.gravity_m_per_s2,
                            CatenarySolverOptions(), nullptr, &f,
                            &iterations) != CatenaryStatus::kOk) {
      return false;
    }
    (*t)[i] = std::hypot(f.fl_n, f.fz_n) / 1e3;
  }
  return true;
}

// d(tension kN)/d(u, theta) by central differences (R -> exp(theta) R) into *j.
bool TensionPerCabinMotion(const CableRobot& robot, const Pose& pose,
                           const StaticsSolution& statics, Eigen::Matrix<double, 6, 6>* j,
                           std::string* error) {
  constexpr double kStepM = 1e-3, kStepRad = 1e-5;
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
    Eigen::Matrix<double, 6, 1> t_plus, t_minus;
    if (!TensionsAtFixedLengths(robot, plus, statics, &t_plus) ||
        !TensionsAtFixedLengths(robot, minus, statics, &t_minus)) {
      *error = "vibration record: a cable's catenary has no solution a step from the pose";
      return false;
    }
    j->col(k) = (t_plus - t_minus) / (2.0 * h);
  }
  return true;
}

}  // namespace

bool VibrationRecordSpec::IsValid(std::string* error) const {
  const VibrationRecordSpec& spec = *this;
  if (spec.modes.empty() || spec.damping_ratio.size() != spec.modes.size()) {
    *error = "vibration record: modes and damping_ratio: one damping ratio per excited mode";
    return false;
  }
  if (!(spec.amplitude_m > 0.0 && spec.amplitude_m <= kMaxVibrationAmplitudeM)) {
    *error = "vibration record: amplitude_m = " + internal::FormatDouble("%g", spec.amplitude_m) +
             " m: must be in (0, " + internal::FormatDouble("%g", kMaxVibrationAmplitudeM) +
             "] m (the linearisation holds for small motions)";
    return false;
  }
  if (!(spec.position_noise_m >= 0.0) || !(spec.attitude_noise_deg >= 0.0) ||
      !(spec.tension_noise_kn >= 0.0) || !std::isfinite(spec.position_noise_m) ||
      !std::isfinite(spec.attitude_noise_deg) || !std::isfinite(spec.tension_noise_kn)) {
    *error = "vibration record: noise sigmas must be >= 0 and finite";
    return false;
  }
  if (!(spec.sample_interval_s > 0.0) || !(spec.duration_s > spec.sample_interval_s) ||
      !std::isfinite(spec.duration_s)) {
    *error = "vibration record: sample_interval_s > 0 and a finite, longer duration_s";
    return false;
  }
  const double samples = spec.duration_s / spec.sample_interval_s + 1.0;
  if (!(samples <= static_cast<double>(kMaxRecordSamples))) {
    *error = "vibration record: duration_s " + internal::FormatDouble("%g", spec.duration_s) +
             " s every sample_interval_s " + internal::FormatDouble("%g", spec.sample_interval_s) +
             " s is " + internal::FormatDouble("%.3g", samples) + " samples, more than the " +
             std::to_string(kMaxRecordSamples) + " a record may hold";
    return false;
  }
  return modes_options.IsValid(error);
}

namespace {

// The largest displacement of a point of the cabin, its origin O' or an anchor point (the
// cabin's rim), under the cabin's motion `shape` = (u, theta), global axes.
double LargestCabinDisplacement(const CableRobot& robot, const Pose& pose,
                                const Eigen::Matrix<double, 6, 1>& shape) {
  const Eigen::Vector3d u = shape.head<3>(), theta = shape.tail<3>();
  double largest = u.norm();
  for (const Eigen::Vector3d& a : robot.anchor_points_cabin_m) {
    largest = std::max(largest, (u + theta.cross(pose.rotation * a)).norm());
  }
  return largest;
}

// The record's motion within what the cables and the plausibility limits take: every
// tension above zero (no cable slackens), every position plausible.
bool CheckRecordedMotion(const VibrationRecord& record, std::string* error) {
  const PlausibilityLimits limits;
  for (int k = 0; k < record.channels.cols(); ++k) {
    std::string why;
    if (!CheckPosition(record.channels.col(k).head<3>(), limits, &why)) {
      *error = "vibration record: amplitude_m: at t = " +
               internal::FormatDouble("%g", k * record.sample_interval_s) + " s " + why;
      return false;
    }
    for (int i = 0; i < kNumCables; ++i) {
      if (record.channels(6 + i, k) > 0.0) continue;
      *error = "vibration record: amplitude_m: cable " + std::to_string(i + 1) +
               "'s tension falls to " + internal::FormatDouble("%.4g", record.channels(6 + i, k)) +
               " kN at t = " + internal::FormatDouble("%g", k * record.sample_interval_s) +
               " s: a motion the taut cables of the linearised model cannot make (a smaller "
               "amplitude)";
      return false;
    }
  }
  return true;
}

}  // namespace

bool SimulateVibrationRecord(const CableRobot& robot, const Pose& pose,
                             const VibrationRecordSpec& spec, VibrationRecord* record,
                             std::string* error) {
  if (!spec.IsValid(error)) return false;
  ModesOptions options = spec.modes_options;
  options.modes = std::max(options.modes, *std::max_element(spec.modes.begin(), spec.modes.end()));
  ModesResult predicted;
  if (!ComputeModes(robot, pose, options, &predicted, error)) return false;
  Eigen::Matrix<double, 6, 6> tension;
  if (!TensionPerCabinMotion(robot, pose, predicted.statics, &tension, error)) return false;
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
    if (!(mode.CabinShare() >= kMinExcitedCabinShare)) {
      *error = "vibration record: mode " + std::to_string(m) + " holds " +
               internal::FormatDouble("%.2g", 100 * mode.CabinShare()) +
               "% of its energy in the cabin, under " +
               internal::FormatDouble("%g", 100 * kMinExcitedCabinShare) +
               "%: a cable's mode, which the cabin's motion cannot show; excite another";
      return false;
    }
    const double scale = spec.amplitude_m / LargestCabinDisplacement(robot, pose, mode.cabin_shape);
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
  return CheckRecordedMotion(*record, error);
}

std::string ModesComparisonCsv(const ModesComparisonResult& r) {
  // Ten significant digits, "0" for zero (the command line's numbers).
  const auto num = [](double v, int digits = 10) {
    return v == 0.0 ? std::string("0")
                    : internal::FormatDouble("%." + std::to_string(digits) + "g", v);
  };
  std::string out =
      "mode,frequency_hz,frequency_sigma_hz,damping_ratio,damping_sigma,predicted_mode,"
      "predicted_hz,predicted_kind,difference_percent,difference_sigma_percent";
  for (int p = 0; p < kModeParameters; ++p) out += std::string(",dlnf_dln_") + ModeParameterName(p);
  out += "\n";
  for (size_t i = 0; i < r.modes.size(); ++i) {
    const ModeComparison& c = r.modes[i];
    const IdentifiedMode& m = c.identified;
    out += std::to_string(i + 1) + "," + num(m.frequency_hz) + "," + num(m.frequency_sigma_hz) +
           "," + num(m.damping_ratio) + "," + num(m.damping_sigma) + "," +
           std::to_string(c.predicted_mode) + "," + num(c.predicted_hz) + "," +
           (c.predicted_cabin_share > 0.5 ? "cabin" : "cable") + "," + num(100 * c.difference) +
           "," + num(100 * c.difference_sigma);
    for (int p = 0; p < kModeParameters; ++p) out += "," + num(c.sensitivity[p], 4);
    out += "\n";
  }
  return out;
}

}  // namespace fastcal
