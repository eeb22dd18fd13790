// The fit's folded data term (internal/folded_cost.h) against Ceres's own per-sample
// residual blocks, and the deterministic chunked passes it runs on
// (internal/sample_chunks.h).
#include "fastcal/internal/folded_cost.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <memory>
#include <random>
#include <vector>

#include "fastcal/internal/calibration_linearisation.h"
#include "fastcal/internal/sample_chunks.h"
#include "fastcal/trajectory.h"

namespace fastcal::internal {
namespace {

// Folded and per-block evaluations differ by rounding only (a QR against sums).
constexpr double kRelTol = 1e-9;

// Random poses over the cap with seeded 3% noise around a shifted mass centre: residuals
// of a few sigma, so that a robust loss with scale 1 acts on some of them.
Dataset RandomData(int samples) {
  CableRobot truth = CableRobot::NominalFast();
  truth.mass_centre_cabin_m = Eigen::Vector3d(0.22, 0.11, 0.5);
  RandomWorkspaceSpec spec;
  spec.samples = samples;
  spec.seed = 3;
  std::vector<Eigen::Vector3d> positions;
  std::vector<Pose> poses;
  std::string error;
  EXPECT_TRUE(RandomWorkspacePositions(spec, &positions, &error)) << error;
  EXPECT_TRUE(PosesWithAttitudeLaw(positions, FocalAttitudeLaw(), &poses, &error)) << error;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  StaticsOptions exact;
  Dataset d;
  d.path = "random";
  for (const Pose& pose : poses) {
    StaticsSolution s;
    EXPECT_EQ(SolveStatics(truth, pose, exact, &s), StaticsStatus::kOk);
    Sample sample;
    sample.line = static_cast<int>(d.samples.size()) + 2;
    sample.pose = pose;
    for (int i = 0; i < kNumCables; ++i) {
      sample.tension_n[i] = s.cables[i].lower_tension_n * (1.0 + 0.03 * normal(rng));
    }
    d.samples.push_back(sample);
  }
  return d;
}

CalibrationSpec MassCentreSpec() {
  CalibrationSpec spec;
  for (int c = 0; c < 3; ++c) {
    ParameterSpec p;
    p.kind = ParameterKind::kMassCentre;
    p.component = c;
    p.name = std::string("mass_centre_m.") + "xyz"[c];
    p.free = true;
    spec.parameters.push_back(p);
  }
  ParameterSpec density;
  density.kind = ParameterKind::kLinearDensity;
  density.name = "linear_density_kg_per_m";
  density.free = true;
  spec.parameters.push_back(density);
  return spec;
}

// The mass centre, a common density, and per cable a sensor gain and bias (each enters
// one cable's reading only: the fold by reading).
CalibrationSpec SensorSpec() {
  CalibrationSpec spec = MassCentreSpec();
  for (ParameterKind kind : {ParameterKind::kSensorGain, ParameterKind::kSensorBias}) {
    for (int i = 0; i < kNumCables; ++i) {
      ParameterSpec p;
      p.kind = kind;
      p.index = i;
      p.name = std::string(kind == ParameterKind::kSensorGain ? "sensor_gain" : "sensor_bias_kN") +
               "[" + std::to_string(i + 1) + "]";
      p.free = true;
      spec.parameters.push_back(p);
    }
  }
  return spec;
}

// The problem's inputs, owned here (FittedSamples points into them).
struct Fixture {
  Dataset data;
  CalibrationSpec spec = MassCentreSpec();
  CalibrationModel model{CableRobot::NominalFast(), spec};
  std::vector<int> fit;
  std::vector<std::array<double, kNumCables>> sigma_n;
  ReadingMask excluded;

  explicit Fixture(int samples, const CalibrationSpec& with = MassCentreSpec())
      : data(RandomData(samples)), spec(with), model(CableRobot::NominalFast(), spec) {
    for (size_t t = 0; t < data.samples.size(); ++t) {
      fit.push_back(static_cast<int>(t));
      sigma_n.push_back(TensionSigmas(data.samples[t].tension_n, 0.0, 3.0));
    }
    excluded.assign(data.samples.size(), {});
    excluded[7][2] = true;  // a reading kept out: residual 0 whatever theta
  }
  // A slow sensor error (slow_error.h), off unless WithSlowError is called.
  SlowErrorProcess slow;
  std::vector<std::array<double, kNumCables>> slow_rho;

  FittedSamples Samples() const {
    FittedSamples s;
    s.model = &model;
    s.data = &data;
    s.fit = &fit;
    s.sigma_n = &sigma_n;
    s.excluded = &excluded;
    s.statics = ModelFitStaticsOptions(StaticsMethod::kExact);
    s.slow_error = slow;
    s.slow_rho = &slow_rho;
    return s;
  }
  // Samples 1 s apart, a second session from `session_start` on, and a slow error with
  // tau = 20 s whose ratio to the white sigma varies by reading.
  void WithSlowError(int session_start) {
    data.session_labels = {"a", "b"};
    for (size_t t = 0; t < data.samples.size(); ++t) {
      data.samples[t].time_s = static_cast<double>(t);
      data.samples[t].session = static_cast<int>(t) >= session_start ? 1 : 0;
      std::array<double, kNumCables> rho{};
      for (int i = 0; i < kNumCables; ++i) rho[i] = 0.6 + 0.4 * std::sin(0.1 * t + i);
      slow_rho.push_back(rho);
    }
    slow.sigma_percent = 2.0;
    slow.time_constant_s = 20.0;
  }
};

struct Evaluation {
  double cost = 0.0;
  Eigen::VectorXd gradient;
  Eigen::MatrixXd normal;  // J^T J
};

Evaluation Evaluate(ceres::Problem* problem) {
  double cost = 0.0;
  std::vector<double> gradient;
  ceres::CRSMatrix j;
  EXPECT_TRUE(problem->Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, &gradient, &j));
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(j.num_rows, j.num_cols);
  for (int r = 0; r < j.num_rows; ++r) {
    for (int p = j.rows[r]; p < j.rows[r + 1]; ++p) dense(r, j.cols[p]) = j.values[p];
  }
  return {cost, Eigen::Map<Eigen::VectorXd>(gradient.data(), gradient.size()),
          dense.transpose() * dense};
}

// rho(s) = s + s^2 / 100: rho'' > 0, the corrector's alpha branch (Huber and Cauchy have
// rho'' <= 0).
class ConvexLoss : public ceres::LossFunction {
 public:
  void Evaluate(double s, double rho[3]) const override {
    rho[0] = s + 0.01 * s * s;
    rho[1] = 1.0 + 0.02 * s;
    rho[2] = 0.02;
  }
};

std::unique_ptr<ceres::LossFunction> Loss(int kind) {
  if (kind == 1) return std::make_unique<ceres::HuberLoss>(1.0);
  if (kind == 2) return std::make_unique<ceres::CauchyLoss>(1.0);
  if (kind == 3) return std::make_unique<ConvexLoss>();
  return nullptr;
}

// Cost, gradient and Gauss-Newton matrix of the folded block are those of one Ceres
// residual block per sample with the loss attached (Ceres's own corrector is the
// reference), without a loss, with Huber, Cauchy and a convex loss, on more samples than
// a chunk.
TEST(FoldedCostTest, MatchesOneCeresBlockPerSample) {
  const Fixture f(2 * kSampleChunk + 100);
  std::vector<double> theta = f.model.InitialTheta();
  theta[2] += 0.4;  // z off the truth: residuals of a few sigma
  for (int kind = 0; kind < 4; ++kind) {
    const std::unique_ptr<ceres::LossFunction> loss = Loss(kind);
    ceres::Problem::Options borrowed;
    borrowed.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem blocks(borrowed), folded(borrowed);
    const FittedSamples samples = f.Samples();
    for (int j = 0; j < samples.size(); ++j) {
      blocks.AddResidualBlock(new TensionCost(samples.At(j)), loss.get(), theta.data());
    }
    folded.AddResidualBlock(new FoldedTensionCost(samples, loss.get(), 2), nullptr, theta.data());
    const Evaluation a = Evaluate(&blocks);
    const Evaluation b = Evaluate(&folded);
    EXPECT_NEAR(b.cost, a.cost, kRelTol * a.cost) << "loss " << kind;
    EXPECT_LT((b.gradient - a.gradient).norm(), kRelTol * a.gradient.norm()) << "loss " << kind;
    EXPECT_LT((b.normal - a.normal).norm(), kRelTol * a.normal.norm()) << "loss " << kind;
    // A trial step's cost, without Jacobians: the same number.
    double cost_only = 0.0;
    ASSERT_TRUE(
        folded.Evaluate(ceres::Problem::EvaluateOptions(), &cost_only, nullptr, nullptr, nullptr));
    EXPECT_NEAR(cost_only, a.cost, kRelTol * a.cost) << "loss " << kind;
  }
}

// With a slow sensor error the folded block is generalised least squares: cost, gradient
// and Gauss-Newton matrix those of r^T Sigma^-1 r per cable, Sigma = I + D C D (D the
// ratios, C_ts = exp(-|t - s| / tau) within a session, 0 across), computed densely from
// the per-sample rows; the reading kept out is missing. Over two chunks, so that the
// filters carry across a chunk boundary, and with a session break inside the second.
TEST(FoldedCostTest, SlowErrorGivesDenseGeneralisedLeastSquares) {
  constexpr int kSamples = kSampleChunk + 60;
  Fixture f(kSamples);
  f.WithSlowError(kSampleChunk + 20);
  std::vector<double> theta = f.model.InitialTheta();
  theta[2] += 0.4;
  const FittedSamples samples = f.Samples();
  const int n = static_cast<int>(theta.size());
  Evaluation dense{0.0, Eigen::VectorXd::Zero(n), Eigen::MatrixXd::Zero(n, n)};
  std::vector<Eigen::Matrix<double, kNumCables, Eigen::Dynamic, Eigen::RowMajor>> jac(kSamples);
  std::vector<Eigen::Matrix<double, kNumCables, 1>> res(kSamples);
  for (int t = 0; t < kSamples; ++t) {
    jac[t].resize(kNumCables, n);
    const TensionCost cost(samples.At(t));
    const double* parameters[1] = {theta.data()};
    double* jacobians[1] = {jac[t].data()};
    ASSERT_TRUE(cost.Evaluate(parameters, res[t].data(), jacobians));
  }
  for (int i = 0; i < kNumCables; ++i) {
    std::vector<int> kept;
    for (int t = 0; t < kSamples; ++t) {
      if (!f.excluded[t][i]) kept.push_back(t);
    }
    const int m = static_cast<int>(kept.size());
    Eigen::MatrixXd sigma = Eigen::MatrixXd::Identity(m, m), j(m, n);
    Eigen::VectorXd r(m);
    for (int a = 0; a < m; ++a) {
      const int ta = kept[a];
      j.row(a) = jac[ta].row(i);
      r[a] = res[ta][i];
      for (int b = 0; b < m; ++b) {
        const int tb = kept[b];
        if (f.data.samples[ta].session != f.data.samples[tb].session) continue;
        sigma(a, b) += f.slow_rho[ta][i] * f.slow_rho[tb][i] *
                       std::exp(-std::abs(ta - tb) / f.slow.time_constant_s);
      }
    }
    const Eigen::LLT<Eigen::MatrixXd> llt(sigma);
    dense.cost += 0.5 * r.dot(llt.solve(r));
    dense.gradient += j.transpose() * llt.solve(r);
    dense.normal += j.transpose() * llt.solve(j);
  }
  ceres::Problem folded;
  folded.AddResidualBlock(new FoldedTensionCost(samples, nullptr, 2), nullptr, theta.data());
  const Evaluation b = Evaluate(&folded);
  EXPECT_NEAR(b.cost, dense.cost, kRelTol * dense.cost);
  EXPECT_LT((b.gradient - dense.gradient).norm(), kRelTol * dense.gradient.norm());
  EXPECT_LT((b.normal - dense.normal).norm(), kRelTol * dense.normal.norm());
  double cost_only = 0.0;
  ASSERT_TRUE(
      folded.Evaluate(ceres::Problem::EvaluateOptions(), &cost_only, nullptr, nullptr, nullptr));
  EXPECT_NEAR(cost_only, dense.cost, kRelTol * dense.cost);
}

// Folding each reading's rows on their own first (sensor gains and biases enter one
// cable's reading): the cost, gradient and Gauss-Newton matrix of the full-width fold,
// with a slow error, two sessions and a reading kept out, theta off the truth in every
// kind of column.
TEST(FoldedCostTest, FoldByReadingIsTheFullFold) {
  Fixture f(2 * kSampleChunk + 100, SensorSpec());
  f.WithSlowError(kSampleChunk + 20);
  std::vector<double> theta = f.model.InitialTheta();
  theta[2] += 0.4;
  theta[5] += 0.01;  // a sensor gain
  theta[12] += 900;  // a sensor bias, in N
  const FittedSamples samples = f.Samples();
  ceres::Problem full, by_reading;
  auto* plain = new FoldedTensionCost(samples, nullptr, 2, /*by_reading=*/false);
  auto* split = new FoldedTensionCost(samples, nullptr, 2);
  EXPECT_FALSE(plain->folds_by_reading());
  ASSERT_TRUE(split->folds_by_reading());
  full.AddResidualBlock(plain, nullptr, theta.data());
  by_reading.AddResidualBlock(split, nullptr, theta.data());
  const Evaluation a = Evaluate(&full);
  const Evaluation b = Evaluate(&by_reading);
  EXPECT_NEAR(b.cost, a.cost, kRelTol * a.cost);
  EXPECT_LT((b.gradient - a.gradient).norm(), kRelTol * a.gradient.norm());
  EXPECT_LT((b.normal - a.normal).norm(), kRelTol * a.normal.norm());
  // A loss's correction mixes a sample's rows: then every row is folded at full width.
  const ceres::HuberLoss huber(1.0);
  EXPECT_FALSE(FoldedTensionCost(samples, &huber, 2).folds_by_reading());
}

// The folded block's residuals and Jacobian on `threads` threads, theta moved off the
// initial model.
std::vector<double> FoldedOnThreads(const Fixture& f, const ceres::LossFunction* loss,
                                    int threads) {
  std::vector<double> theta = f.model.InitialTheta();
  theta[0] += 0.1;
  const FoldedTensionCost cost(f.Samples(), loss, threads);
  std::vector<double> out(cost.num_residuals() * (1 + theta.size()));
  const double* parameters[1] = {theta.data()};
  double* jacobians[1] = {out.data() + cost.num_residuals()};
  EXPECT_TRUE(cost.Evaluate(parameters, out.data(), jacobians));
  return out;
}

// One thread or three: the same bits.
TEST(FoldedCostTest, ThreadsGiveTheSameBits) {
  const Fixture f(3 * kSampleChunk + 7);
  const ceres::HuberLoss huber(1.0);
  EXPECT_EQ(FoldedOnThreads(f, &huber, 1), FoldedOnThreads(f, &huber, 3));
}

// With the slow error's filters in the ordered stage too, and folded by reading.
TEST(FoldedCostTest, ThreadsGiveTheSameBitsWithASlowError) {
  Fixture f(3 * kSampleChunk + 7);
  f.WithSlowError(2 * kSampleChunk + 500);
  EXPECT_EQ(FoldedOnThreads(f, nullptr, 1), FoldedOnThreads(f, nullptr, 3));
  Fixture sensors(3 * kSampleChunk + 7, SensorSpec());
  sensors.WithSlowError(2 * kSampleChunk + 500);
  EXPECT_EQ(FoldedOnThreads(sensors, nullptr, 1), FoldedOnThreads(sensors, nullptr, 3));
}

// A trial step's cost, then the Jacobian at the same theta (the memo): the same numbers
// as a fresh block's, and the cost the one its residuals carry.
TEST(FoldedCostTest, CostThenJacobianAtTheSameTheta) {
  const Fixture f(kSampleChunk + 30);
  const ceres::HuberLoss huber(1.0);
  const std::vector<double> fresh = FoldedOnThreads(f, &huber, 2);
  std::vector<double> theta = f.model.InitialTheta();
  theta[0] += 0.1;  // as FoldedOnThreads
  const FoldedTensionCost cost(f.Samples(), &huber, 2);
  const int m = cost.num_residuals();
  const double* parameters[1] = {theta.data()};
  std::vector<double> trial(m);
  ASSERT_TRUE(cost.Evaluate(parameters, trial.data(), nullptr));
  double fresh_cost = 0.0, trial_cost = 0.0;
  for (int k = 0; k < m; ++k) {
    fresh_cost += fresh[k] * fresh[k];
    trial_cost += trial[k] * trial[k];
  }
  constexpr double kRelTol = 1e-12;  // |z|^2 + e^2 against the sum of rho, rounding
  EXPECT_NEAR(trial_cost, fresh_cost, kRelTol * fresh_cost);
  std::vector<double> out(m * (1 + theta.size()));
  double* jacobians[1] = {out.data() + m};
  ASSERT_TRUE(cost.Evaluate(parameters, out.data(), jacobians));
  EXPECT_EQ(out, fresh);
  theta[1] += 0.01;  // another theta: not the memo's
  ASSERT_TRUE(cost.Evaluate(parameters, trial.data(), nullptr));
  EXPECT_NE(trial[m - 1] * trial[m - 1], trial_cost);
}

// What an evaluation solved (FittedSamples::solved) is the prediction at its theta: each
// fitted sample's readings as SolveStatics gives them from cold, its solution the next
// start; SolvedAt says so at that theta only, and not after a failed evaluation (Predict
// would otherwise take stale readings for the new weights).
TEST(FoldedCostTest, LeavesWhatItSolvedForThePredictionAtTheSameTheta) {
  Fixture f(kSampleChunk + 30, SensorSpec());
  f.fit.erase(f.fit.begin() + 5);  // a held-out sample: not written
  std::vector<std::array<double, kNumCables>> reading_n(f.data.samples.size(), {-1.0});
  CompactStarts starts;
  starts.Reset(f.data.samples.size());
  FittedSamples samples = f.Samples();
  samples.starts = &starts;
  samples.solved = {&reading_n, &starts};
  const FoldedTensionCost cost(samples, nullptr, 2);
  std::vector<double> theta = f.model.InitialTheta();
  theta[0] += 0.1;
  theta[5] = 1.01;  // sensor_gain[2]
  EXPECT_FALSE(cost.SolvedAt(theta.data()));
  std::vector<double> residuals(cost.num_residuals());
  const double* parameters[1] = {theta.data()};
  ASSERT_TRUE(cost.Evaluate(parameters, residuals.data(), nullptr));
  EXPECT_TRUE(cost.SolvedAt(theta.data()));
  const CableRobot robot = f.model.ToRobot(theta.data());
  // The fold solved warm from nothing (cold) and SolveStatics from cold: to the solver's
  // tolerance, not bit for bit.
  constexpr double kReadingRelTol = 1e-9;
  for (size_t t = 0; t < f.data.samples.size(); ++t) {
    if (t == 5) {
      EXPECT_EQ(reading_n[t][0], -1.0);
      EXPECT_FALSE(starts.At(t).has_start());
      continue;
    }
    StaticsSolution s;
    ASSERT_EQ(SolveStatics(robot, f.data.samples[t].pose,
                           ModelFitStaticsOptions(StaticsMethod::kExact), &s),
              StaticsStatus::kOk);
    for (int i = 0; i < kNumCables; ++i) {
      const double expected = robot.cables[i].SensorReadingN(s.cables[i].lower_tension_n);
      ASSERT_NEAR(reading_n[t][i], expected, kReadingRelTol * expected) << t << " " << i;
    }
    ASSERT_TRUE(starts.At(t).has_start()) << t;
  }
  std::vector<double> other = theta;
  other[1] += 0.01;
  EXPECT_FALSE(cost.SolvedAt(other.data()));
  other[3] = -1.0;  // a density the statics cannot hold: the evaluation fails
  const double* failing[1] = {other.data()};
  EXPECT_FALSE(cost.Evaluate(failing, residuals.data(), nullptr));
  EXPECT_FALSE(cost.SolvedAt(other.data()));
  EXPECT_FALSE(cost.SolvedAt(theta.data()));
  // Nowhere to leave them (the default), or a path that is not the prediction's: never.
  const FoldedTensionCost plain(f.Samples(), nullptr, 2);
  ASSERT_TRUE(plain.Evaluate(parameters, residuals.data(), nullptr));
  EXPECT_FALSE(plain.SolvedAt(theta.data()));
  samples.statics = ModelFitStaticsOptions(StaticsMethod::kAas);
  const FoldedTensionCost aas(samples, nullptr, 2);
  ASSERT_TRUE(aas.Evaluate(parameters, residuals.data(), nullptr));
  EXPECT_FALSE(aas.SolvedAt(theta.data()));
}

// A window's second pass (track_fold.cc) evaluates its rows where its first pass solved:
// from those solutions taken as solved (FittedSamples::starts_solved), the readings are the
// first pass's bit for bit and the rows those of a solve from the same starts to the
// solver's tolerance; a sample without a start is solved.
TEST(FoldedCostTest, RowsTakeASolvedStartAsTheSolution) {
  constexpr double kRowRelTol = 1e-9;  // the solves' 1e-12, through the derivatives
  Fixture f(40, SensorSpec());
  const int n = f.model.num_free();
  std::vector<double> theta = f.model.InitialTheta();
  theta[0] += 0.1;
  theta[5] = 1.01;  // sensor_gain[2]
  const ModelAtTheta at(f.model, theta.data(), 1);
  std::vector<std::array<double, kNumCables>> reading_n(f.data.samples.size());
  CompactStarts starts;
  starts.Reset(f.data.samples.size());
  FittedSamples first = f.Samples();
  first.solved = {&reading_n, &starts};
  std::array<double, kNumCables> r{};
  for (int j = 0; j < first.size(); ++j) ASSERT_TRUE(first.Rows(j, at, r.data(), nullptr)) << j;
  CompactStarts some = starts;
  some.Set(3, StaticsSolution());  // no start: solved
  FittedSamples taken = f.Samples(), solved = f.Samples();
  taken.starts = solved.starts = &some;
  taken.starts_solved = true;
  std::vector<double> jt(kNumCables * n), js(kNumCables * n);
  std::array<double, kNumCables> rt{}, rs{};
  for (int j = 0; j < taken.size(); ++j) {
    ASSERT_TRUE(taken.Rows(j, at, rt.data(), jt.data())) << j;
    ASSERT_TRUE(solved.Rows(j, at, rs.data(), js.data())) << j;
    const Sample& sample = f.data.samples[j];
    for (int i = 0; i < kNumCables; ++i) {
      if (f.excluded[j][i]) continue;
      if (j != 3) {
        EXPECT_EQ(rt[i], (reading_n[j][i] - sample.tension_n[i]) / f.sigma_n[j][i]) << j << i;
      }
      EXPECT_NEAR(rt[i], rs[i], kRowRelTol * std::abs(reading_n[j][i] / f.sigma_n[j][i]));
    }
    const double scale = Eigen::Map<Eigen::VectorXd>(js.data(), js.size()).cwiseAbs().maxCoeff();
    for (size_t k = 0; k < jt.size(); ++k) {
      ASSERT_NEAR(jt[k], js[k], kRowRelTol * scale) << j << " " << k;
    }
  }
}

// The calibration's prediction marks its starts as solved at its model's theta
// (compact_start.h): a fold there takes them as solved (the readings it leaves are the prediction's bit for
// bit, its R the same to rounding) and keeps the mark; a fold anywhere else forgets it.
TEST(FoldedCostTest, AFoldWhereTheStartsWereSolvedTakesThemAsSolved) {
  Fixture f(kSampleChunk + 30, SensorSpec());
  std::vector<double> theta = f.model.InitialTheta();
  theta[0] += 0.1;
  theta[5] = 1.01;  // sensor_gain[2]
  const int n = f.model.num_free();
  std::vector<std::array<double, kNumCables>> predicted(f.data.samples.size());
  CompactStarts starts;
  starts.Reset(f.data.samples.size());
  FittedSamples samples = f.Samples();
  samples.starts = &starts;
  samples.solved = {&predicted, &starts};
  std::vector<double> residuals(n + 1), jacobian((n + 1) * n);
  double* jacobians[1] = {jacobian.data()};
  const double* at_theta[1] = {theta.data()};
  {  // the prediction's pass (Predict solves every sample at theta the same way)
    const FoldedTensionCost first(samples, nullptr, 2);
    ASSERT_TRUE(first.Evaluate(at_theta, residuals.data(), nullptr));
  }
  starts.MarkSolvedAt(&f.model, theta.data(), n);
  std::vector<std::array<double, kNumCables>> reading_n(f.data.samples.size());
  samples.solved = {&reading_n, &starts};
  CompactStarts unmarked = starts;
  unmarked.ForgetSolved();
  FittedSamples solving = f.Samples();
  solving.starts = &unmarked;
  const FoldedTensionCost taking(samples, nullptr, 2), solving_cost(solving, nullptr, 2);
  ASSERT_TRUE(taking.Evaluate(at_theta, residuals.data(), jacobians));
  EXPECT_TRUE(starts.SolvedAt(&f.model, theta.data(), n));
  // Another model of the same width at the same theta: not these statics.
  const CalibrationModel twin(CableRobot::NominalFast(), f.spec);
  EXPECT_FALSE(starts.SolvedAt(&twin, theta.data(), n));
  for (size_t t = 0; t < reading_n.size(); ++t) {
    for (int i = 0; i < kNumCables; ++i) ASSERT_EQ(reading_n[t][i], predicted[t][i]) << t << i;
  }
  Eigen::MatrixXd r_taking, r_solving;
  ASSERT_TRUE(taking.FoldedAt(theta.data(), &r_taking));
  ASSERT_TRUE(solving_cost.Evaluate(at_theta, residuals.data(), jacobians));
  ASSERT_TRUE(solving_cost.FoldedAt(theta.data(), &r_solving));
  const Eigen::MatrixXd normal_taking = r_taking.transpose() * r_taking;
  const Eigen::MatrixXd normal_solving = r_solving.transpose() * r_solving;
  EXPECT_LT((normal_taking - normal_solving).norm(), kRelTol * normal_solving.norm());
  std::vector<double> other = theta;
  other[1] += 0.01;
  const double* elsewhere[1] = {other.data()};
  ASSERT_TRUE(taking.Evaluate(elsewhere, residuals.data(), jacobians));
  EXPECT_FALSE(starts.SolvedAt(&f.model, theta.data(), n));
  EXPECT_FALSE(starts.SolvedAt(&f.model, other.data(), n));
}

// The linearisation at a point folds each reading's rows over its own columns first
// (issue 41): its R factor must still give R^T R = J^T J, the information it sums row by
// row (in lower triangles, as its blocks and sessions), with sensors per cable, a slow
// error over two sessions and a reading kept out.
TEST(FoldedCostTest, LinearisationRFactorIsTheInformation) {
  Fixture f(kSampleChunk + 30, SensorSpec());
  f.WithSlowError(kSampleChunk / 2);
  std::vector<double> theta = f.model.InitialTheta();
  theta[0] += 0.1;
  LinearisationInputs in;
  in.samples = f.Samples();
  in.theta = theta.data();
  in.num_threads = 2;
  Linearisation lin;
  std::string error;
  ASSERT_TRUE(Linearise(in, &lin, &error)) << error;
  const Eigen::MatrixXd rtr = lin.r_factor.transpose() * lin.r_factor;
  EXPECT_LE((rtr - lin.information).norm(), kRelTol * lin.information.norm());
  for (int k = 0; k < lin.information.rows(); ++k) {
    EXPECT_NEAR(rtr(k, k), lin.information(k, k), kRelTol * lin.information(k, k)) << k;
  }
  // The blocks' and the two sessions' information, summed in lower triangles and made
  // whole, add up to the whole (every entry, both triangles).
  const double scale = lin.information.norm();
  Eigen::MatrixXd blocks = Eigen::MatrixXd::Zero(lin.information.rows(), lin.information.cols());
  for (const FoldSums& b : lin.folds) blocks += b.information;
  EXPECT_LE((blocks - lin.information).cwiseAbs().maxCoeff(), kRelTol * scale);
  ASSERT_EQ(lin.session_information.size(), 2u);
  const Eigen::MatrixXd sessions = lin.session_information[0] + lin.session_information[1];
  EXPECT_LE((sessions - lin.information).cwiseAbs().maxCoeff(), kRelTol * scale);
  // And each session's is its own samples': the second session linearised alone (the slow
  // error's filters start afresh at a session, so its rows are the same) has it as its
  // whole. The sums run over runs of samples: a run must end where the session does.
  std::vector<int> fit_b;
  std::vector<std::array<double, kNumCables>> sigma_b, rho_b;
  for (size_t j = 0; j < f.fit.size(); ++j) {
    if (f.data.samples[f.fit[j]].session != 1) continue;
    fit_b.push_back(f.fit[j]);
    sigma_b.push_back(f.sigma_n[j]);
    rho_b.push_back(f.slow_rho[j]);
  }
  LinearisationInputs only_b = in;
  only_b.samples.fit = &fit_b;
  only_b.samples.sigma_n = &sigma_b;
  only_b.samples.slow_rho = &rho_b;
  Linearisation lin_b;
  ASSERT_TRUE(Linearise(only_b, &lin_b, &error)) << error;
  EXPECT_LE((lin_b.information - lin.session_information[1]).cwiseAbs().maxCoeff(),
            kRelTol * scale);
}

// A sample the statics cannot solve (a non-positive density) fails the evaluation, as one
// per-sample block would: Ceres then rejects the step.
TEST(FoldedCostTest, AnUnsolvableSampleFailsTheEvaluation) {
  const Fixture f(50);
  std::vector<double> theta = f.model.InitialTheta();
  theta[3] = -1.0;  // linear density
  const FoldedTensionCost cost(f.Samples(), nullptr, 2);
  std::vector<double> residuals(cost.num_residuals()), jacobian(cost.num_residuals() * 4);
  const double* parameters[1] = {theta.data()};
  double* jacobians[1] = {jacobian.data()};
  EXPECT_FALSE(cost.Evaluate(parameters, residuals.data(), jacobians));
  EXPECT_FALSE(cost.Evaluate(parameters, residuals.data(), nullptr));
}

// Sums merged in chunk order: a sum whose value depends on the order of its terms comes
// out the same on 1, 2 and 4 threads, and equals the serial sum of the chunks' sums.
TEST(SampleChunksTest, SumsDoNotDependOnThreads) {
  constexpr int kCount = 10000, kChunk = 64;
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> exponent(-20.0, 20.0);
  std::vector<double> values(kCount);
  for (double& v : values) v = std::pow(10.0, exponent(rng)) * (rng() % 2 ? 1 : -1);
  double serial = 0.0;
  for (int begin = 0; begin < kCount; begin += kChunk) {
    double chunk = 0.0;
    for (int t = begin; t < std::min(kCount, begin + kChunk); ++t) chunk += values[t];
    serial += chunk;
  }
  for (int threads : {1, 2, 4}) {
    double total = 0.0;
    const int failed = ReduceChunks<double>(
        kCount, threads, [] { return 0.0; },
        [&](int begin, int end, double* sum) {
          for (int t = begin; t < end; ++t) *sum += values[t];
          return -1;
        },
        [&](const double& sum) { total += sum; }, kChunk);
    EXPECT_EQ(failed, -1);
    EXPECT_EQ(total, serial) << threads << " threads";
  }
}

// The ordered stage sees the chunks one at a time in chunk order (a running recursion
// gives the serial answer), between parallel work and merge, on any number of threads.
TEST(SampleChunksTest, OrderedStageRunsInChunkOrder) {
  constexpr int kCount = 3000, kChunk = 64;
  std::vector<double> serial(kCount);
  double state = 0.0;
  for (int t = 0; t < kCount; ++t) serial[t] = state = 0.9 * state + std::sin(t);
  for (int threads : {1, 2, 4}) {
    std::vector<double> out(kCount);
    double carried = 0.0;
    int chunks = 0;
    const int failed = ReduceChunksInOrder<std::vector<double>>(
        kCount, threads, [] { return std::vector<double>(); },
        [&](int begin, int end, std::vector<double>* v) {
          for (int t = begin; t < end; ++t) v->push_back(std::sin(t));
          return -1;
        },
        [&](int begin, int end, std::vector<double>* v) {
          for (int t = begin; t < end; ++t)
            (*v)[t - begin] = carried = 0.9 * carried + (*v)[t - begin];
        },
        [&](int begin, int end, std::vector<double>* v) {
          std::copy(v->begin(), v->end(), out.begin() + begin);
          return -1;
        },
        [&](const std::vector<double>&) { ++chunks; }, kChunk);
    EXPECT_EQ(failed, -1);
    EXPECT_EQ(out, serial) << threads << " threads";
    EXPECT_EQ(chunks, (kCount + kChunk - 1) / kChunk);
  }
}

// The first failing item is named, whatever the threads and whichever chunk failed first
// in time.
TEST(SampleChunksTest, TheFirstFailureIsNamed) {
  constexpr int kCount = 5000, kChunk = 100;
  for (int threads : {1, 2, 4}) {
    const int failed = ForEachChunk(
        kCount, threads,
        [](int begin, int end) {
          for (int t = begin; t < end; ++t) {
            if (t == 1234 || t == 4321) return t;
          }
          return -1;
        },
        kChunk);
    EXPECT_EQ(failed, 1234) << threads << " threads";
    const int reduced = ReduceChunks<int>(
        kCount, threads, [] { return 0; },
        [](int begin, int end, int*) {
          for (int t = begin; t < end; ++t) {
            if (t == 4321 || t == 777) return t;
          }
          return -1;
        },
        [](const int&) {}, kChunk);
    EXPECT_EQ(reduced, 777) << threads << " threads";
  }
}

}  // namespace
}  // namespace fastcal::internal
