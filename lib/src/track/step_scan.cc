// The exact whitened step columns' sums at every cut of a stretch (internal/step_scan.h has
// the recursions).
#include "fastcal/internal/step_scan.h"

#include <cmath>
#include <utility>

namespace fastcal::internal {

StepScan ScanSteps(const StepScanInput& in) {
  const int nf = static_cast<int>(in.steps.size());
  const int n = in.columns;
  StepScan out;
  out.cross.assign(in.cuts, Eigen::MatrixXd());
  out.self.assign(in.cuts, Eigen::MatrixXd());
  // The cut sums of the columns themselves from the stretch's end back (`after` first),
  // and per cable G(y) over every column and Q, from the last sample back.
  Eigen::MatrixXd plain = in.after.size() > 0 ? in.after : Eigen::MatrixXd::Zero(nf, n);
  std::vector<Eigen::VectorXd> g(kNumCables, Eigen::VectorXd::Zero(n));
  std::vector<double> q(kNumCables, 0.0);
  for (int t = in.samples - 1; t >= 0; --t) {
    for (int i = 0; i < kNumCables; ++i) {
      const size_t r = static_cast<size_t>(t) * kNumCables + i;
      const double c = in.c[r], a = in.a[r];
      const Eigen::Map<const Eigen::VectorXd> row(in.Row(t, i), n);
      g[i] = c * row + a * g[i];
      q[i] = c * c + a * a * q[i];
      if (t < in.cuts) {
        for (int f = 0; f < nf; ++f) plain.row(f) += row[in.steps[f]] * row.transpose();
      }
    }
    if (t >= in.cuts) continue;
    Eigen::MatrixXd cross = plain;
    Eigen::MatrixXd self(nf, nf);
    for (int f = 0; f < nf; ++f) {
      for (int h = 0; h < nf; ++h) self(f, h) = plain(f, in.steps[h]);
    }
    for (int i = 0; i < kNumCables; ++i) {
      const double* mean = in.prior_mean.data() + (static_cast<size_t>(t) * kNumCables + i) * nf;
      for (int f = 0; f < nf; ++f) {
        if (mean[f] == 0.0) continue;
        cross.row(f) += mean[f] * g[i].transpose();
        for (int h = 0; h < nf; ++h) {
          self(f, h) += mean[f] * g[i][in.steps[h]];
          self(h, f) += mean[f] * g[i][in.steps[h]];
          self(f, h) += mean[f] * mean[h] * q[i];
        }
      }
    }
    out.cross[t] = std::move(cross);
    out.self[t] = std::move(self);
  }
  return out;
}

StepScanRecorder::StepScanRecorder(int columns, std::vector<int> steps, long long first, int cuts,
                                   int samples)
    : first_(first) {
  in_.columns = columns;
  in_.steps = std::move(steps);
  in_.cuts = cuts;
  in_.samples = samples;
  const size_t readings = static_cast<size_t>(samples) * kNumCables;
  in_.rows.assign(readings * columns, 0.0);
  in_.c.assign(readings, 0.0);
  in_.a.assign(readings, 0.0);
  in_.prior_mean.assign(readings * in_.steps.size(), 0.0);
}

void StepScanRecorder::Reading(int cable, double phi, bool fresh, double rho, bool update,
                               const SlowErrorFilter& prior) {
  const long long t = readings_ / kNumCables - first_;
  ++readings_;
  if (t < 0 || t > in_.samples) return;
  // The transition of this cable's difference from its reading before: none across a new
  // series (the filter starts afresh: both columns' states are zero again).
  if (t > 0) {
    const size_t r = static_cast<size_t>(t - 1) * kNumCables + cable;
    in_.a[r] =
        fresh || prior.Fresh() ? 0.0 : phi * (updated_[cable] ? 1.0 - gain_rho_[cable] : 1.0);
  }
  if (t == in_.samples) return;
  const double p = prior.PriorVariance();
  const double f = rho * rho * p + 1.0;
  const size_t r = static_cast<size_t>(t) * kNumCables + cable;
  in_.c[r] = update ? rho / std::sqrt(f) : 0.0;
  gain_rho_[cable] = p * rho * rho / f;
  updated_[cable] = update;
  for (size_t s = 0; s < in_.steps.size(); ++s) {
    in_.prior_mean[r * in_.steps.size() + s] = prior.PriorMean(in_.steps[s]);
  }
}

void StepScanRecorder::Rows(long long sample, const double* rows) {
  const long long t = sample - first_;
  if (t < 0 || t >= in_.samples) return;
  std::copy(rows, rows + static_cast<size_t>(kNumCables) * in_.columns,
            in_.Row(static_cast<int>(t), 0));
}

}  // namespace fastcal::internal
