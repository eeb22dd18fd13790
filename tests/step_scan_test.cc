// The exact whitened step columns (internal/step_scan.h) against their definition: each
// step column built explicitly (zero before the cut, the column from it on) and whitened by
// its own pass of the filters, for every cut of a stretch, with readings out of the fit and
// a series that starts again inside the stretch.
#include "fastcal/internal/step_scan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fastcal/internal/slow_error_filter.h"

namespace fastcal::internal {
namespace {

// The recursions against a direct sum of products of unit-sized columns: the digits of
// double arithmetic over a few hundred terms.
constexpr double kSumTolerance = 1e-9;

struct Pass {
  int samples = 0, columns = 0;
  std::vector<double> time_s;
  std::vector<int> session;
  std::vector<std::array<double, kNumCables>> rho;
  std::vector<std::array<bool, kNumCables>> excluded;
  std::vector<double> raw;  // [t][i][columns]
  double* Raw(int t, int i) {
    return raw.data() + (static_cast<size_t>(t) * kNumCables + i) * columns;
  }
};

Pass DrawPass(int samples, int columns, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  Pass p;
  p.samples = samples;
  p.columns = columns;
  double t = 0.0;
  for (int k = 0; k < samples; ++k) {
    t += 1.0 + 2.0 * uniform(rng);
    p.time_s.push_back(t);
    p.session.push_back(k < samples * 2 / 3 ? 0 : 1);  // a new series two thirds in
    std::array<double, kNumCables> rho;
    std::array<bool, kNumCables> out;
    for (int i = 0; i < kNumCables; ++i) {
      rho[i] = 0.3 + 0.5 * uniform(rng);
      out[i] = uniform(rng) < 0.05;
    }
    p.rho.push_back(rho);
    p.excluded.push_back(out);
  }
  p.raw.resize(static_cast<size_t>(samples) * kNumCables * columns);
  for (double& x : p.raw) x = normal(rng);
  return p;
}

// Whitens `rows` (the pass's layout) in place with the filters, zeroing readings out of the
// fit, telling `observer` (may be null).
void Whiten(const Pass& p, std::vector<double>* rows, WhitenObserver* observer) {
  SlowErrorProcess process;
  process.sigma_percent = 1.0;
  process.time_constant_s = 40.0;
  ReadingWhitener whitener(process, p.columns);
  whitener.set_observer(observer);
  for (int k = 0; k < p.samples; ++k) {
    double* row = rows->data() + static_cast<size_t>(k) * kNumCables * p.columns;
    whitener.WhitenOnly(p.time_s[k], p.session[k], p.rho[k].data(), p.excluded[k].data(), row);
    for (int i = 0; i < kNumCables; ++i) {
      if (p.excluded[k][i]) std::fill(row + i * p.columns, row + (i + 1) * p.columns, 0.0);
    }
  }
}

TEST(StepScanTest, RecursionsAreTheExplicitStepColumnsWhitened) {
  constexpr int kSamples = 240, kColumns = 5, kFirst = 60, kCuts = 120;
  const std::vector<int> steps = {0, 3};
  Pass p = DrawPass(kSamples, kColumns, 3);
  std::vector<double> white = p.raw;
  StepScanRecorder recorder(kColumns, steps, kFirst, kCuts, kSamples - kFirst);
  Whiten(p, &white, &recorder);
  for (int k = 0; k < kSamples; ++k) {
    recorder.Rows(k, white.data() + static_cast<size_t>(k) * kNumCables * kColumns);
  }
  StepScanInput in = recorder.input();
  // After the cuts: the plain sums of the rows from sample kFirst + kCuts on.
  in.after = Eigen::MatrixXd::Zero(steps.size(), kColumns);
  for (int t = kFirst + kCuts; t < kSamples; ++t) {
    for (int i = 0; i < kNumCables; ++i) {
      const double* w = white.data() + (static_cast<size_t>(t) * kNumCables + i) * kColumns;
      for (size_t f = 0; f < steps.size(); ++f) {
        for (int c = 0; c < kColumns; ++c) in.after(f, c) += w[steps[f]] * w[c];
      }
    }
  }
  const StepScan scan = ScanSteps(in);
  ASSERT_EQ(scan.cross.size(), static_cast<size_t>(kCuts));
  for (const int cut : {0, 1, 37, 79, 80, 81, 119}) {
    // The explicit step columns from sample kFirst + cut on, whitened by their own pass.
    std::vector<double> stepped = p.raw;
    for (int t = 0; t < kFirst + cut; ++t) {
      for (int i = 0; i < kNumCables; ++i) {
        for (int f : steps) stepped[(static_cast<size_t>(t) * kNumCables + i) * kColumns + f] = 0.0;
      }
    }
    Whiten(p, &stepped, nullptr);
    Eigen::MatrixXd cross = Eigen::MatrixXd::Zero(steps.size(), kColumns);
    Eigen::MatrixXd self = Eigen::MatrixXd::Zero(steps.size(), steps.size());
    for (int t = kFirst + cut; t < kSamples; ++t) {
      for (int i = 0; i < kNumCables; ++i) {
        const size_t r = (static_cast<size_t>(t) * kNumCables + i) * kColumns;
        for (size_t f = 0; f < steps.size(); ++f) {
          for (int c = 0; c < kColumns; ++c) cross(f, c) += stepped[r + steps[f]] * white[r + c];
          for (size_t h = 0; h < steps.size(); ++h) {
            self(f, h) += stepped[r + steps[f]] * stepped[r + steps[h]];
          }
        }
      }
    }
    EXPECT_LT((scan.cross[cut] - cross).cwiseAbs().maxCoeff(), kSumTolerance * cross.norm())
        << "cut " << cut << "\n"
        << scan.cross[cut] << "\nexplicit\n"
        << cross;
    EXPECT_LT((scan.self[cut] - self).cwiseAbs().maxCoeff(), kSumTolerance * self.norm())
        << "cut " << cut;
  }
  // The transient matters: the step's own information differs from the cut column's by
  // about a reading's worth, far beyond the recursions' tolerance.
  Eigen::MatrixXd cut_self = Eigen::MatrixXd::Zero(steps.size(), steps.size());
  for (int t = kFirst + 37; t < kSamples; ++t) {
    for (int i = 0; i < kNumCables; ++i) {
      const size_t r = (static_cast<size_t>(t) * kNumCables + i) * kColumns;
      for (size_t f = 0; f < steps.size(); ++f) {
        for (size_t h = 0; h < steps.size(); ++h)
          cut_self(f, h) += white[r + steps[f]] * white[r + steps[h]];
      }
    }
  }
  EXPECT_GT((scan.self[37] - cut_self).cwiseAbs().maxCoeff(),
            1e4 * kSumTolerance * cut_self.norm());
}

}  // namespace
}  // namespace fastcal::internal
