// Covariance-driven stochastic subspace identification (subspace_identification.h has
// the method and its sources): the record's preparation, its block covariances, the
// identification at every order, the stabilisation diagram's clusters, the jackknife; and
// the synthetic ambient records.
#include "fastcal/subspace_identification.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <complex>
#include <numeric>
#include <random>

#include "dynamics/record_preparation.h"
#include "fastcal/internal/number_text.h"

namespace fastcal {
namespace {

using Complex = std::complex<double>;

// A stable pole's match to the one of the order below.
constexpr double kStableFrequency = 0.01;
constexpr double kStableDamping = 0.05;
constexpr double kStableDampingAbsolute = 0.002;
constexpr double kStableMac = 0.95;
// A cluster: poles within this of its first in frequency and above this MAC with it, at
// this fraction of the orders or more.
constexpr double kClusterFrequency = 0.01;
constexpr double kClusterMac = 0.9;
constexpr double kClusterOrders = 0.2;
// A cluster within this of a more stable one in frequency, with a MAC above kClusterMac to
// it, is that mode's shadow (the noise fitted by a pole beside it), not a mode.
constexpr double kShadowFrequency = 0.03;
// A reference channel's lag-1 autocorrelation reaches this share of the largest.
constexpr double kReferenceShare = 0.5;
// Each block holds at least this many periods of min_frequency_hz.
constexpr double kBlockPeriods = 10.0;

struct Pole {
  double frequency_hz = 0.0;
  double damping_ratio = 0.0;
  Eigen::VectorXcd shape;
  int order = 0;
};

double Mac(const Eigen::VectorXcd& a, const Eigen::VectorXcd& b) {
  const double num = std::norm(a.dot(b));
  const double den = a.squaredNorm() * b.squaredNorm();
  return den > 0.0 ? num / den : 0.0;
}

// The reference channels: those whose lag-1 autocorrelation (of the scaled record, at the
// decimated interval) reaches kReferenceShare of the largest; a channel of white noise has
// none.
std::vector<int> References(const Eigen::MatrixXd& y) {
  const Eigen::Index n = y.cols();
  const Eigen::VectorXd r1 =
      (y.rightCols(n - 1).array() * y.leftCols(n - 1).array()).rowwise().sum() / (n - 1.0);
  std::vector<int> refs;
  for (int c = 0; c < y.rows(); ++c) {
    if (r1[c] >= kReferenceShare * r1.maxCoeff()) refs.push_back(c);
  }
  return refs;
}

// Each block's covariances with the references, R_j = E[y_{k+j} y_ref,k^T] for j = 1 ..
// lags (R_j at index j - 1; channels x references).
std::vector<std::vector<Eigen::MatrixXd>> BlockCovariances(const Eigen::MatrixXd& y,
                                                           const std::vector<int>& refs, int blocks,
                                                           int lags) {
  const int length = static_cast<int>(y.cols()) / blocks;
  Eigen::MatrixXd y_ref(refs.size(), y.cols());
  for (size_t i = 0; i < refs.size(); ++i) y_ref.row(i) = y.row(refs[i]);
  std::vector<std::vector<Eigen::MatrixXd>> out(blocks);
  for (int b = 0; b < blocks; ++b) {
    const Eigen::MatrixXd block = y.middleCols(b * length, length);
    const Eigen::MatrixXd ref = y_ref.middleCols(b * length, length);
    for (int j = 1; j <= lags; ++j) {
      const int pairs = length - j;
      out[b].push_back(block.rightCols(pairs) * ref.leftCols(pairs).transpose() / pairs);
    }
  }
  return out;
}

// The poles of every even order 2 .. max_order from the averaged covariances `r` (R_1 at
// index 0) with `rows` block rows.
std::vector<std::vector<Pole>> PolesByOrder(const std::vector<Eigen::MatrixXd>& r, int rows,
                                            double dt_s, const SsiOptions& o) {
  const int l = static_cast<int>(r[0].rows()), refs = static_cast<int>(r[0].cols());
  Eigen::MatrixXd toeplitz(rows * l, rows * refs);
  for (int a = 0; a < rows; ++a) {
    for (int c = 0; c < rows; ++c) toeplitz.block(a * l, c * refs, l, refs) = r[rows + a - c - 1];
  }
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(toeplitz, Eigen::ComputeThinU);
  const Eigen::VectorXd root = svd.singularValues().cwiseSqrt();
  std::vector<std::vector<Pole>> by_order;
  const int max_order = std::min<int>(o.max_order, static_cast<int>(toeplitz.cols()));
  // A_n = O_up^+ O_down = S_n^-1/2 R_n^-1 (Q^T U_down)_n S_n^1/2 with U_up = Q R: the
  // leading n columns' QR is the leading part of the whole one, so one QR serves every n.
  const Eigen::MatrixXd u = svd.matrixU().leftCols(max_order);
  const Eigen::Index up = static_cast<Eigen::Index>(rows - 1) * l;
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(u.topRows(up));
  const Eigen::MatrixXd qt_down =
      (qr.householderQ().transpose() * u.bottomRows(up)).topRows(max_order);
  for (int n = 2; n <= max_order; n += 2) {
    const Eigen::MatrixXd ratio =
        qr.matrixQR().topLeftCorner(n, n).triangularView<Eigen::Upper>().solve(
            qt_down.topLeftCorner(n, n));
    const Eigen::MatrixXd a =
        root.head(n).cwiseInverse().asDiagonal() * ratio * root.head(n).asDiagonal();
    const Eigen::MatrixXd c = u.topLeftCorner(l, n) * root.head(n).asDiagonal();
    const Eigen::EigenSolver<Eigen::MatrixXd> eig(a);
    std::vector<Pole> poles;
    for (int k = 0; k < n && eig.info() == Eigen::Success; ++k) {
      const Complex mu = eig.eigenvalues()[k];
      if (!(mu.imag() > 0.0)) continue;  // one of each conjugate pair; no real poles
      const Complex s = std::log(mu) / dt_s;
      Pole p;
      p.frequency_hz = std::abs(s) / (2.0 * M_PI);
      p.damping_ratio = -s.real() / std::abs(s);
      if (p.frequency_hz < o.min_frequency_hz || p.frequency_hz > o.max_frequency_hz ||
          !(p.damping_ratio > 0.0 && p.damping_ratio < o.max_damping_ratio)) {
        continue;
      }
      p.shape = c.cast<Complex>() * eig.eigenvectors().col(k);
      p.order = n;
      poles.push_back(p);
    }
    by_order.push_back(poles);
  }
  return by_order;
}

bool Matches(const Pole& a, const Pole& b) {
  return std::abs(a.frequency_hz / b.frequency_hz - 1.0) < kStableFrequency &&
         std::abs(a.damping_ratio - b.damping_ratio) <
             std::max(kStableDampingAbsolute, kStableDamping * b.damping_ratio) &&
         Mac(a.shape, b.shape) > kStableMac;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 == 1 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

struct Cluster {
  Pole mode;  // medians, and the shape of the pole nearest the median frequency
  int count = 0;
};

// The stabilisation diagram's clusters found at kClusterOrders of the orders or more.
std::vector<Cluster> Clusters(const std::vector<std::vector<Pole>>& by_order) {
  std::vector<Pole> stable;
  for (size_t n = 1; n < by_order.size(); ++n) {
    for (const Pole& p : by_order[n]) {
      for (const Pole& q : by_order[n - 1]) {
        if (Matches(p, q)) {
          stable.push_back(p);
          break;
        }
      }
    }
  }
  std::sort(stable.begin(), stable.end(),
            [](const Pole& a, const Pole& b) { return a.frequency_hz < b.frequency_hz; });
  std::vector<bool> used(stable.size(), false);
  std::vector<Cluster> out;
  const int needed =
      std::max(2, static_cast<int>(std::ceil(kClusterOrders * (by_order.size() - 1))));
  for (size_t a = 0; a < stable.size(); ++a) {
    if (used[a]) continue;
    std::vector<size_t> members = {a};
    std::vector<int> orders = {stable[a].order};
    for (size_t b = a + 1; b < stable.size(); ++b) {
      if (used[b]) continue;
      if (stable[b].frequency_hz > stable[a].frequency_hz * (1.0 + kClusterFrequency)) break;
      if (std::find(orders.begin(), orders.end(), stable[b].order) != orders.end()) continue;
      if (Mac(stable[a].shape, stable[b].shape) < kClusterMac) continue;
      members.push_back(b);
      orders.push_back(stable[b].order);
    }
    if (static_cast<int>(members.size()) < needed) continue;
    std::vector<double> f, z;
    for (size_t m : members) {
      used[m] = true;
      f.push_back(stable[m].frequency_hz);
      z.push_back(stable[m].damping_ratio);
    }
    Cluster c;
    c.count = static_cast<int>(members.size());
    c.mode.frequency_hz = Median(f);
    c.mode.damping_ratio = Median(z);
    size_t nearest = members[0];
    for (size_t m : members) {
      if (std::abs(stable[m].frequency_hz - c.mode.frequency_hz) <
          std::abs(stable[nearest].frequency_hz - c.mode.frequency_hz)) {
        nearest = m;
      }
    }
    c.mode.shape = stable[nearest].shape;
    out.push_back(c);
  }
  return out;
}

// The clusters, most stable first, without the shadows of more stable ones.
std::vector<Cluster> WithoutShadows(std::vector<Cluster> clusters) {
  std::stable_sort(clusters.begin(), clusters.end(),
                   [](const Cluster& a, const Cluster& b) { return a.count > b.count; });
  std::vector<Cluster> kept;
  for (const Cluster& c : clusters) {
    bool shadow = false;
    for (const Cluster& k : kept) {
      shadow =
          shadow || (std::abs(c.mode.frequency_hz / k.mode.frequency_hz - 1.0) < kShadowFrequency &&
                     Mac(c.mode.shape, k.mode.shape) > kClusterMac);
    }
    if (!shadow) kept.push_back(c);
  }
  return kept;
}

std::vector<Eigen::MatrixXd> Mean(const std::vector<std::vector<Eigen::MatrixXd>>& blocks,
                                  int left_out) {
  std::vector<Eigen::MatrixXd> out(blocks[0].size());
  int used = 0;
  for (size_t b = 0; b < blocks.size(); ++b) {
    if (static_cast<int>(b) == left_out) continue;
    ++used;
    for (size_t j = 0; j < out.size(); ++j) {
      if (used == 1) {
        out[j] = blocks[b][j];
      } else {
        out[j] += blocks[b][j];
      }
    }
  }
  for (Eigen::MatrixXd& r : out) r /= used;
  return out;
}

// The jackknife's replicates: each of `found`'s modes' nearest (in frequency, MAC above
// kClusterMac) among the clusters of the covariances without block b, for each b.
void JackknifeReplicates(const std::vector<std::vector<Eigen::MatrixXd>>& blocks,
                         const std::vector<Cluster>& found, int rows, double dt_s,
                         const SsiOptions& o, std::vector<std::vector<double>>* f,
                         std::vector<std::vector<double>>* z) {
  f->assign(found.size(), {});
  z->assign(found.size(), {});
  for (int b = 0; b < o.blocks; ++b) {
    const std::vector<Cluster> replicate = Clusters(PolesByOrder(Mean(blocks, b), rows, dt_s, o));
    for (size_t m = 0; m < found.size(); ++m) {
      const Pole& target = found[m].mode;
      const Pole* best = nullptr;
      for (const Cluster& c : replicate) {
        if (Mac(c.mode.shape, target.shape) < kClusterMac) continue;
        if (best == nullptr || std::abs(c.mode.frequency_hz - target.frequency_hz) <
                                   std::abs(best->frequency_hz - target.frequency_hz)) {
          best = &c.mode;
        }
      }
      if (best == nullptr) continue;
      (*f)[m].push_back(best->frequency_hz);
      (*z)[m].push_back(best->damping_ratio);
    }
  }
}

// sqrt((B - 1)/B sum (theta_b - mean)^2); NaN from fewer than 3 replicates.
double JackknifeSigma(const std::vector<double>& v) {
  if (v.size() < 3) return std::nan("");
  const double mean = std::accumulate(v.begin(), v.end(), 0.0) / v.size();
  double sum = 0.0;
  for (double x : v) sum += (x - mean) * (x - mean);
  return std::sqrt((v.size() - 1.0) / v.size() * sum);
}

}  // namespace

bool SsiOptions::IsValid(std::string* error) const {
  if (modes < 1 || modes > kMaxIdentifiedModes) {
    *error = "modes: must be in [1, " + std::to_string(kMaxIdentifiedModes) + "]";
    return false;
  }
  if (!(min_frequency_hz > 0.0 && max_frequency_hz > min_frequency_hz) ||
      !std::isfinite(max_frequency_hz)) {
    *error = "min_frequency_hz, max_frequency_hz: must be finite with 0 < min < max";
    return false;
  }
  // The block Hankel matrix's rows grow with the band's width, its SVD with their square:
  // bounded as ERA's (issue 57), so that no option asks for gigabytes.
  if (max_frequency_hz > kMaxEraBandRatio * min_frequency_hz) {
    *error = "max_frequency_hz: must be at most " +
             std::to_string(static_cast<int>(kMaxEraBandRatio)) + " times min_frequency_hz";
    return false;
  }
  if (max_order < 4 || max_order % 2 != 0 || max_order > 400) {
    *error = "max_order: must be even, in [4, 400]";
    return false;
  }
  if (!(max_damping_ratio > 0.0 && max_damping_ratio < 1.0)) {
    *error = "max_damping_ratio: must be in (0, 1)";
    return false;
  }
  if (blocks < 3 || blocks > 100) {
    *error = "blocks: must be in [3, 100]";
    return false;
  }
  return true;
}

bool IdentifyModesSsi(const VibrationRecord& record, const SsiOptions& o,
                      std::vector<IdentifiedMode>* modes, std::string* error) {
  if (!o.IsValid(error)) return false;
  const double dt = record.sample_interval_s;
  if (!(dt > 0.0) || !std::isfinite(dt) || !record.channels.allFinite() ||
      record.channels.rows() < 1 || record.channels.cols() > kMaxRecordSamples) {
    *error = "the record must have channels, finite values, a sample interval > 0 and at most " +
             std::to_string(kMaxRecordSamples) + " samples";
    return false;
  }
  if (0.5 / dt <= o.max_frequency_hz) {
    *error = "the record's sampling (" + internal::FormatDouble("%.4g", 1.0 / dt) +
             " Hz) must be above twice max_frequency_hz";
    return false;
  }
  const int decimation = internal::DecimationFactor(dt, o.max_frequency_hz);
  const double dt_s = decimation * dt;
  const int rows = static_cast<int>(std::ceil(2.0 / (o.min_frequency_hz * dt_s)));
  const int channels = static_cast<int>(record.channels.rows());
  const double block_s = record.channels.cols() * dt / o.blocks;
  if (block_s < kBlockPeriods / o.min_frequency_hz || rows * channels < o.max_order) {
    *error = "the record is too short: " + std::to_string(o.blocks) + " blocks of " +
             internal::FormatDouble("%.4g", block_s) + " s, each must hold " +
             internal::FormatDouble("%.4g", kBlockPeriods) + " periods of min_frequency_hz (" +
             internal::FormatDouble("%.4g", kBlockPeriods / o.min_frequency_hz) +
             " s), and block rows x channels must reach max_order";
    return false;
  }
  const Eigen::MatrixXd y = internal::DecimatedScaled(record.channels, decimation);
  const std::vector<int> refs = References(y);
  const std::vector<std::vector<Eigen::MatrixXd>> blocks =
      BlockCovariances(y, refs, o.blocks, 2 * rows - 1);
  std::vector<Cluster> found =
      WithoutShadows(Clusters(PolesByOrder(Mean(blocks, -1), rows, dt_s, o)));
  if (static_cast<int>(found.size()) < o.modes) {
    *error = "SSI found " + std::to_string(found.size()) +
             " stable modes (a stabilisation diagram's clusters) in " +
             internal::FormatDouble("%.4g", o.min_frequency_hz) + " to " +
             internal::FormatDouble("%.4g", o.max_frequency_hz) + " Hz, fewer than the " +
             std::to_string(o.modes) + " asked";
    return false;
  }
  found.resize(o.modes);
  std::sort(found.begin(), found.end(), [](const Cluster& a, const Cluster& b) {
    return a.mode.frequency_hz < b.mode.frequency_hz;
  });
  std::vector<std::vector<double>> f, z;
  JackknifeReplicates(blocks, found, rows, dt_s, o, &f, &z);
  // The orders that can hold a stable pole.
  const int orders = std::min<int>(o.max_order, rows * static_cast<int>(refs.size())) / 2 - 1;
  modes->clear();
  for (int m = 0; m < o.modes; ++m) {
    IdentifiedMode mode;
    mode.frequency_hz = found[m].mode.frequency_hz;
    mode.damping_ratio = found[m].mode.damping_ratio;
    mode.frequency_sigma_hz = JackknifeSigma(f[m]);
    mode.damping_sigma = JackknifeSigma(z[m]);
    mode.amplitude = static_cast<double>(found[m].count) / orders;
    modes->push_back(mode);
  }
  return true;
}

bool SimulateAmbientRecord(const AmbientRecordSpec& spec, VibrationRecord* record,
                           std::string* error) {
  const size_t m = spec.frequency_hz.size();
  const int channels = static_cast<int>(spec.shape.rows());
  const double dt = spec.sample_interval_s;
  bool valid = m > 0 && spec.damping_ratio.size() == m &&
               spec.shape.cols() == static_cast<int>(m) && spec.noise_sigma.size() == channels &&
               dt > 0.0 && spec.duration_s > dt;
  for (size_t j = 0; valid && j < m; ++j) {
    valid = spec.frequency_hz[j] > 0.0 && spec.frequency_hz[j] < 0.5 / dt &&
            spec.damping_ratio[j] > 0.0 && spec.damping_ratio[j] < 1.0;
  }
  if (!valid) {
    *error =
        "ambient record: per mode a frequency below the Nyquist and a damping in (0, 1), a "
        "shape column per mode, a noise sigma per channel, sample_interval_s > 0 and a "
        "longer duration_s";
    return false;
  }
  const int n = static_cast<int>(spec.duration_s / dt) + 1;
  record->sample_interval_s = dt;
  record->channels = Eigen::MatrixXd::Zero(channels, n);
  std::mt19937_64 rng(spec.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (size_t j = 0; j < m; ++j) {
    const double w = 2.0 * M_PI * spec.frequency_hz[j], zeta = spec.damping_ratio[j];
    const double r = std::exp(-zeta * w * dt);
    const double a1 = 2.0 * r * std::cos(w * std::sqrt(1.0 - zeta * zeta) * dt), a2 = -r * r;
    const double spread =
        std::sqrt((1.0 - a2) / ((1.0 + a2) * ((1.0 - a2) * (1.0 - a2) - a1 * a1)));
    const int burn_in = static_cast<int>(std::ceil(10.0 / (zeta * w * dt)));
    double q1 = 0.0, q2 = 0.0;  // q_{k-1}, q_{k-2}
    for (int k = -burn_in; k < n; ++k) {
      const double q = a1 * q1 + a2 * q2 + normal(rng);
      q2 = q1;
      q1 = q;
      if (k >= 0) record->channels.col(k) += spec.shape.col(j) * (q / spread);
    }
  }
  for (int k = 0; k < n; ++k) {
    for (int c = 0; c < channels; ++c) record->channels(c, k) += spec.noise_sigma[c] * normal(rng);
  }
  return true;
}

}  // namespace fastcal
