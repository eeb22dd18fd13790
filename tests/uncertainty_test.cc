// Tests of the uncertainty budget (uncertainty.h) on linear least-squares problems, where
// every quantity has a closed form or an exact refit to compare with: robust scale,
// autocorrelation time, the batch correction, coverage under time-correlated errors,
// consider-parameter sensitivities and the score test.
#include "fastcal/uncertainty.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

namespace fastcal {
namespace {

TEST(RobustScaleTest, MedianAndMadIgnoreAMinorityOfGrossErrors) {
  constexpr double kTol = 1e-12;
  const RobustScale s = RobustScaleOf({1, 2, 3, 4, 5});
  EXPECT_NEAR(s.centre, 3.0, kTol);
  EXPECT_NEAR(s.scale, 1.4826 * 1.0, kTol);  // |x - 3| = 2 1 0 1 2: median 1
  const RobustScale g = RobustScaleOf({1, 2, 3, 4, 5, 1e6, -1e6});
  EXPECT_NEAR(g.centre, 3.0, kTol);
  EXPECT_NEAR(g.scale, 1.4826 * 2.0, kTol);  // |x - 3| = 2 1 0 1 2 huge huge: median 2
  EXPECT_EQ(RobustScaleOf({}).scale, 0.0);
}

TEST(RobustScaleTest, NormalSampleGivesItsSigma) {
  constexpr double kSigma = 2.5;
  constexpr double kRelTol = 0.03;  // ~ 1.1 / sqrt(n) for n = 1e4
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal(1.0, kSigma);
  std::vector<double> v(10000);
  for (double& x : v) x = normal(rng);
  EXPECT_NEAR(RobustScaleOf(v).scale, kSigma, kRelTol * kSigma);
}

// AR(1) with coefficient phi has tau = (1 + phi) / (1 - phi).
TEST(AutocorrelationTimeTest, WhiteIsOneAndAr1MatchesItsFormula) {
  constexpr int kSamples = 100000;
  constexpr double kPhi = 0.9;
  constexpr double kWhiteTol = 0.05;
  constexpr double kAr1RelTol = 0.1;  // Sokal's window: bias ~ e^-5, noise ~ sqrt(2 (2W+1) / N)
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  Eigen::VectorXd white(kSamples), ar(kSamples);
  double x = 0.0;
  for (int t = 0; t < kSamples; ++t) {
    white[t] = normal(rng);
    x = kPhi * x + normal(rng);
    ar[t] = x;
  }
  const AutocorrelationTime w = IntegratedAutocorrelationTime(white);
  EXPECT_NEAR(w.tau, 1.0, kWhiteTol);
  EXPECT_TRUE(w.reliable);
  const double expected = (1 + kPhi) / (1 - kPhi);
  const AutocorrelationTime a = IntegratedAutocorrelationTime(ar);
  EXPECT_NEAR(a.tau, expected, kAr1RelTol * expected);
  EXPECT_TRUE(a.reliable);
  EXPECT_GE(a.window, 5.0 * a.tau);
  // A trend has no measurable memory: the window runs out.
  Eigen::VectorXd trend = Eigen::VectorXd::LinSpaced(1000, 0.0, 1.0);
  EXPECT_FALSE(IntegratedAutocorrelationTime(trend).reliable);
}

TEST(LongRunCovarianceTest, WhiteScoresGiveTheirSumsCovariance) {
  constexpr int kSamples = 20000;
  constexpr double kRelTol = 0.08;  // OBM with L = 10: relative sd sqrt(4/3 L / N) ~ 2.6%
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd s(kSamples, 2);
  for (int t = 0; t < kSamples; ++t) {
    const double a = normal(rng), b = normal(rng);
    s(t, 0) = 2.0 * a;
    s(t, 1) = a + b;  // var 2, covariance with the first 2
  }
  const Eigen::MatrixXd omega = LongRunCovarianceOfSum(s, 10);
  EXPECT_NEAR(omega(0, 0) / kSamples, 4.0, kRelTol * 4.0);
  EXPECT_NEAR(omega(1, 1) / kSamples, 2.0, kRelTol * 2.0);
  EXPECT_NEAR(omega(0, 1) / kSamples, 2.0, kRelTol * 2.0);
  EXPECT_DOUBLE_EQ(omega(0, 1), omega(1, 0));
}

// One estimated mean: the correction is Meketon and Schmeiser's N / (N - L), exactly.
TEST(BatchCorrectionTest, OneMeanGivesMeketonSchmeiser) {
  constexpr int kSamples = 1000;
  constexpr double kTol = 1e-9;
  SampleJacobians j = SampleJacobians::Ones(kSamples, 1);
  const Eigen::MatrixXd inverse = Eigen::MatrixXd::Constant(1, 1, 1.0 / kSamples);
  for (int l : {1, 10, 100}) {
    const Eigen::VectorXd c = BatchCorrection(j, 1, inverse, l);
    EXPECT_NEAR(c[0], static_cast<double>(kSamples) / (kSamples - l), kTol) << "L " << l;
  }
  EXPECT_EQ(BatchCorrection(SampleJacobians(), 1, inverse, 10), Eigen::VectorXd::Ones(1));
}

// The running window and its ring of rows (and the replay) against the formula itself:
// each window's M_j summed directly, windows at a stride of L / 16, random rows.
TEST(BatchCorrectionTest, RunningWindowsMatchTheFormula) {
  constexpr int kSamples = 700, kRows = 2, kParameters = 3;
  constexpr double kRelTol = 1e-10;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  SampleJacobians j(kSamples, kRows * kParameters);
  for (int t = 0; t < kSamples; ++t) {
    for (int c = 0; c < kRows * kParameters; ++c) {
      j(t, c) = static_cast<float>(normal(rng) + std::sin(0.01 * t + c));
    }
  }
  Eigen::MatrixXd information = Eigen::MatrixXd::Zero(kParameters, kParameters);
  for (int t = 0; t < kSamples; ++t) {
    const Eigen::MatrixXd jt =
        Eigen::Map<const Eigen::Matrix<float, kRows, kParameters, Eigen::RowMajor>>(j.row(t).data())
            .cast<double>();
    information += jt.transpose() * jt;
  }
  const Eigen::MatrixXd inverse = information.inverse();
  for (int l : {1, 7, 40, 200}) {
    Eigen::VectorXd all = Eigen::VectorXd::Zero(kParameters), kept = all;
    for (int b = 0; b + l <= kSamples; b += std::max(1, l / 16)) {
      Eigen::MatrixXd m = Eigen::MatrixXd::Zero(kParameters, kParameters);
      for (int t = b; t < b + l; ++t) {
        const Eigen::MatrixXd jt =
            Eigen::Map<const Eigen::Matrix<float, kRows, kParameters, Eigen::RowMajor>>(
                j.row(t).data())
                .cast<double>();
        m += jt.transpose() * jt;
      }
      all += m.diagonal();
      kept += (m - m * inverse * m).diagonal();
    }
    const Eigen::VectorXd c = BatchCorrection(j, kRows, inverse, l);
    for (int k = 0; k < kParameters; ++k) {
      EXPECT_NEAR(c[k], all[k] / kept[k], kRelTol * c[k]) << "L " << l << " parameter " << k;
    }
    // A replay that fails gives no correction.
    const SampleJacobianReplay broken = [](const std::function<void(int, const float*)>&) {
      return false;
    };
    EXPECT_EQ(BatchCorrection(broken, kSamples, kRows, inverse, l),
              Eigen::VectorXd::Ones(kParameters));
  }
}

// A linear fit y = J beta + e with slowly varying regressors and errors = AR(1) + white;
// stated noise: the white part only.
struct LinearFit {
  Eigen::MatrixXd j;
  Eigen::VectorXd beta, residuals;
};

LinearFit FitAr1Data(int samples, double phi, double ar_sigma, std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  LinearFit f;
  f.j.resize(samples, 3);
  Eigen::VectorXd y(samples);
  double e = ar_sigma * normal(*rng);
  for (int t = 0; t < samples; ++t) {
    const double w = 2.0 * M_PI * t / samples;
    f.j.row(t) << 1.0, std::cos(w), std::sin(w);
    e = phi * e + std::sqrt(1.0 - phi * phi) * ar_sigma * normal(*rng);
    y[t] = e + normal(*rng);  // truth beta = 0
  }
  const Eigen::MatrixXd m = f.j.transpose() * f.j;
  f.beta = m.ldlt().solve(f.j.transpose() * y);
  f.residuals = f.j * f.beta - y;
  return f;
}

BudgetInputs LinearBudgetInputs(const LinearFit& f) {
  BudgetInputs in;
  in.information = f.j.transpose() * f.j;
  in.prior_information = Eigen::VectorXd::Zero(f.j.cols());
  in.scores = (f.j.array().colwise() * f.residuals.array()).matrix().cast<float>();
  in.jacobians = f.j.cast<float>();
  in.rows_per_sample = 1;
  in.num_residuals = static_cast<int>(f.j.rows());
  in.chi_square = f.residuals.squaredNorm();
  // The band of calibration.h: chi2/nu within 1 +- 3 sqrt(2 / nu) is noise.
  in.misfit_threshold = 1.0 + 3.0 * std::sqrt(2.0 / (f.j.rows() - f.j.cols()));
  return in;
}

// The budget's purpose: with time-correlated errors the formal sigma covers the truth
// far too rarely; the total one covers it about as often as a standard deviation should,
// and is not inflated either (a sigma 1.5x too large gives a mean z^2 of 0.44).
TEST(UncertaintyBudgetTest, CoversTheTruthUnderCorrelatedErrors) {
  constexpr int kRepetitions = 300;
  constexpr int kSamples = 3000;
  constexpr double kPhi = 0.8, kArSigma = 3.0;  // tau = 1 + 2 (9/10) (0.8/0.2) = 8.2
  constexpr double kMinCoverage = 0.9, kMaxFormalCoverage = 0.4;
  constexpr double kMinMeanZ2 = 0.6, kMaxMeanZ2 = 1.6;
  std::mt19937_64 rng(11);
  int covered = 0, covered_formal = 0, count = 0;
  double z2 = 0.0;
  for (int rep = 0; rep < kRepetitions; ++rep) {
    const LinearFit f = FitAr1Data(kSamples, kPhi, kArSigma, &rng);
    UncertaintyBudget b;
    ASSERT_TRUE(ComputeUncertaintyBudget(LinearBudgetInputs(f), &b));
    for (int k = 0; k < 3; ++k) {
      const double z = f.beta[k] / b.parameters[k].total;
      covered += std::abs(z) < 2.0;
      covered_formal += std::abs(f.beta[k] / b.parameters[k].formal) < 2.0;
      z2 += z * z;
      ++count;
    }
  }
  EXPECT_GE(covered, kMinCoverage * count);
  EXPECT_LE(covered_formal, kMaxFormalCoverage * count);
  EXPECT_GT(z2 / count, kMinMeanZ2);
  EXPECT_LT(z2 / count, kMaxMeanZ2);
}

TEST(UncertaintyBudgetTest, ThreadsDoNotChangeTheBudget) {
  // The parameters' influence series measured on several threads: the same bits.
  std::mt19937_64 rng(17);
  const LinearFit f = FitAr1Data(4000, 0.8, 3.0, &rng);
  BudgetInputs in = LinearBudgetInputs(f);
  UncertaintyBudget one;
  ASSERT_TRUE(ComputeUncertaintyBudget(in, &one));
  ASSERT_TRUE(one.correlated);  // the series measured, and their memory used
  for (int threads : {2, 3, 8}) {
    in.num_threads = threads;
    UncertaintyBudget many;
    ASSERT_TRUE(ComputeUncertaintyBudget(in, &many));
    EXPECT_EQ(many.tau, one.tau) << threads << " threads";
    EXPECT_EQ(many.bandwidth, one.bandwidth) << threads << " threads";
    for (size_t k = 0; k < one.parameters.size(); ++k) {
      EXPECT_EQ(many.parameters[k].tau, one.parameters[k].tau) << threads << " threads";
      EXPECT_EQ(many.parameters[k].total, one.parameters[k].total) << threads << " threads";
    }
  }
}

TEST(UncertaintyBudgetTest, WhiteResidualsKeepTheFormalSigmaAndMisfitScalesIt) {
  constexpr int kSamples = 5000;
  constexpr double kRelTol = 0.15;  // the data part's own noise at N / L ~ 600
  std::mt19937_64 rng(13);
  LinearFit f = FitAr1Data(kSamples, 0.0, 0.0, &rng);
  UncertaintyBudget b;
  ASSERT_TRUE(ComputeUncertaintyBudget(LinearBudgetInputs(f), &b));
  EXPECT_TRUE(b.correlation_measured);
  EXPECT_FALSE(b.correlated);  // white: no long-run covariance, only its noise
  EXPECT_EQ(b.misfit_factor, 1.0);
  for (const ParameterBudget& p : b.parameters) {
    EXPECT_EQ(p.statistical, p.formal);
    EXPECT_EQ(p.systematic, 0.0);
  }
  // Residuals three times the stated noise: chi2/nu ~ 9, sigma widened ~3x.
  f.residuals *= 3.0;
  ASSERT_TRUE(ComputeUncertaintyBudget(LinearBudgetInputs(f), &b));
  EXPECT_NEAR(b.misfit_factor, 3.0, kRelTol * 3.0);
  for (const ParameterBudget& p : b.parameters) {
    EXPECT_NEAR(p.widening, 3.0, kRelTol * 3.0);
  }
}

// The misfit factor scales the data's information, not a prior's: a parameter held by a
// tight prior keeps its prior sigma however badly the data fit; and the factor applies
// only above the band the caller gives (the chi-square's own noise).
TEST(UncertaintyBudgetTest, MisfitWidensTheDataNotThePriors) {
  constexpr int kSamples = 1000;
  constexpr double kPriorSigma = 1e-6, kRelTol = 1e-6;
  std::mt19937_64 rng(23);
  LinearFit f = FitAr1Data(kSamples, 0.0, 0.0, &rng);
  f.residuals *= 3.0;
  BudgetInputs in = LinearBudgetInputs(f);
  in.prior_information = Eigen::VectorXd::Zero(3);
  in.prior_information[0] = 1.0 / (kPriorSigma * kPriorSigma);
  in.information.diagonal() += in.prior_information;
  in.num_residuals += 1;
  UncertaintyBudget b;
  ASSERT_TRUE(ComputeUncertaintyBudget(in, &b));
  EXPECT_GT(b.misfit_factor, 2.5);
  EXPECT_LE(b.parameters[0].total, kPriorSigma * (1.0 + kRelTol));
  EXPECT_GT(b.parameters[1].widening, 2.5);
  // A chi2/nu of 1.05 inside a band up to 1.1: no factor.
  f = FitAr1Data(kSamples, 0.0, 0.0, &rng);
  in = LinearBudgetInputs(f);
  in.chi_square = 1.05 * (kSamples - 3);
  in.misfit_threshold = 1.1;
  ASSERT_TRUE(ComputeUncertaintyBudget(in, &b));
  EXPECT_EQ(b.misfit_factor, 1.0);
  in.misfit_threshold = 1.0;
  ASSERT_TRUE(ComputeUncertaintyBudget(in, &b));
  EXPECT_NEAR(b.misfit_factor, std::sqrt(1.05), 1e-12);
}

// Too few samples to measure the residuals' memory: said so, nothing assumed.
TEST(UncertaintyBudgetTest, ShortSeriesIsNotMeasured) {
  std::mt19937_64 rng(29);
  const LinearFit f = FitAr1Data(kMinSamplesForCorrelation - 1, 0.0, 0.0, &rng);
  UncertaintyBudget b;
  ASSERT_TRUE(ComputeUncertaintyBudget(LinearBudgetInputs(f), &b));
  EXPECT_FALSE(b.correlation_measured);
  EXPECT_FALSE(b.correlated);
}

// y = a x + c z + e with c held at c0 (consider, sigma_c): the sensitivity of the
// fitted a to c is exact for a linear model: refit with c0 + dc and compare.
TEST(UncertaintyBudgetTest, ConsiderSensitivityMatchesRefit) {
  constexpr int kSamples = 200;
  constexpr double kSigmaC = 0.3, kTol = 1e-10;
  std::mt19937_64 rng(17);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd jx(kSamples, 2);
  Eigen::VectorXd jc(kSamples), y(kSamples);
  for (int t = 0; t < kSamples; ++t) {
    const double x = 0.1 * t;
    jx.row(t) << 1.0, x;
    jc[t] = std::sin(x);
    y[t] = 1.0 + 2.0 * x + 0.5 * jc[t] + normal(rng);
  }
  const Eigen::MatrixXd m = jx.transpose() * jx;
  auto fit = [&](double c) {
    return Eigen::VectorXd(m.ldlt().solve(jx.transpose() * (y - c * jc)));
  };
  BudgetInputs in;
  in.information = m;
  in.prior_information = Eigen::VectorXd::Zero(2);
  in.num_residuals = kSamples;
  in.chi_square = kSamples;
  in.consider_cross = jx.transpose() * jc;
  in.consider_sigma = Eigen::VectorXd::Constant(1, kSigmaC);
  in.consider_group = {0};
  in.consider_groups = {"c"};
  UncertaintyBudget b;
  ASSERT_TRUE(ComputeUncertaintyBudget(in, &b));
  // The model is r = J_x a + J_c c - y: d a / d c = -M^-1 J_x^T J_c.
  const Eigen::VectorXd moved = fit(kSigmaC) - fit(0.0);
  for (int k = 0; k < 2; ++k) {
    EXPECT_NEAR(b.sensitivity(k, 0) * kSigmaC, moved[k], kTol);
    EXPECT_NEAR(b.parameters[k].systematic, std::abs(moved[k]), kTol);
    ASSERT_EQ(b.parameters[k].systematic_by_group.size(), 1u);
    EXPECT_NEAR(b.parameters[k].systematic_by_group[0], std::abs(moved[k]), kTol);
    EXPECT_NEAR(b.parameters[k].total,
                std::hypot(b.parameters[k].statistical, b.parameters[k].systematic), kTol);
  }
}

// For a linear model the score test's expected decrease is exactly the refit's.
TEST(ScoreTestTest, PredictsTheExactDecreaseOfALinearRefit) {
  constexpr int kSamples = 300;
  constexpr double kRelTol = 1e-9;
  std::mt19937_64 rng(19);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd jx(kSamples, 2);
  Eigen::MatrixXd jc(kSamples, 3);
  Eigen::VectorXd y(kSamples);
  for (int t = 0; t < kSamples; ++t) {
    const double x = 0.02 * t;
    jx.row(t) << 1.0, x;
    jc.row(t) << x * x, std::cos(3 * x), 2.0 + 3.0 * x;  // the last is in the span
    y[t] = 1.0 + x + 0.8 * x * x + normal(rng);
  }
  auto chi2 = [&](const Eigen::MatrixXd& j) {
    const Eigen::VectorXd beta = (j.transpose() * j).ldlt().solve(j.transpose() * y);
    return (j * beta - y).squaredNorm();
  };
  const Eigen::MatrixXd m = jx.transpose() * jx;
  const Eigen::VectorXd beta = m.ldlt().solve(jx.transpose() * y);
  const Eigen::VectorXd r = jx * beta - y;
  const Eigen::VectorXd decrease = ScoreTestDecrease(
      m, jx.transpose() * jc, jc.colwise().squaredNorm().transpose(), jc.transpose() * r);
  const double base = r.squaredNorm();
  for (int c = 0; c < 2; ++c) {
    Eigen::MatrixXd both(kSamples, 3);
    both << jx, jc.col(c);
    const double actual = base - chi2(both);
    EXPECT_NEAR(decrease[c], actual, kRelTol * std::max(1.0, actual)) << "candidate " << c;
  }
  EXPECT_GT(decrease[0], decrease[1]);   // the quadratic term is the one the data hold
  EXPECT_TRUE(std::isnan(decrease[2]));  // already spanned by the free parameters
}

}  // namespace
}  // namespace fastcal
