// The block-arrow solve of a track (internal/block_arrow.h) against the same problem
// assembled and solved densely.
#include "fastcal/internal/block_arrow.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

namespace fastcal::internal {
namespace {

// Relative agreement of the Schur route with the dense one: both are backward stable on
// these well-conditioned problems.
constexpr double kTolerance = 1e-9;

struct Dense {
  Eigen::MatrixXd m;      // normal matrix over [a_1 .. a_W, b]
  Eigen::VectorXd rhs;    // its right-hand side
  Eigen::MatrixXd omega;  // sum of the blocks' scaled information (and priors)
  std::vector<int> a_offset;
  int b_offset = 0;
};

// A random problem: W windows of p own and m local shared parameters mapped into q.
ArrowProblem RandomProblem(int windows, int p, int q, std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  ArrowProblem problem;
  problem.q = q;
  problem.shared_prior_information = Eigen::VectorXd::Zero(q);
  problem.shared_prior_mean = Eigen::VectorXd::Zero(q);
  problem.shared_prior_information[0] = 4.0;  // one shared prior
  problem.shared_prior_mean[0] = 0.3;
  for (int w = 0; w < windows; ++w) {
    ArrowBlock k;
    k.p = p;
    // The window sees q - 1 of the shared parameters: the last one in alternate windows
    // is another entry (a stretch), as a split sensor bias.
    for (int j = 0; j < q - 2; ++j) k.shared_index.push_back(j);
    k.shared_index.push_back(w % 2 == 0 ? q - 2 : q - 1);
    const int n = p + k.m();
    Eigen::MatrixXd j(3 * n, n);
    for (int r = 0; r < j.rows(); ++r) {
      for (int c = 0; c < n; ++c) j(r, c) = normal(*rng);
    }
    k.h = j.transpose() * j;
    k.g = Eigen::VectorXd(n);
    k.x0 = Eigen::VectorXd(n);
    for (int c = 0; c < n; ++c) {
      k.g[c] = normal(*rng);
      k.x0[c] = normal(*rng);
    }
    k.c = 10.0;
    k.prior_information = Eigen::VectorXd::Zero(p);
    k.prior_mean = Eigen::VectorXd::Zero(p);
    k.prior_information[0] = 2.0;
    k.prior_mean[0] = -0.1;
    k.scale = 1.0 + 0.5 * w;
    problem.blocks.push_back(k);
  }
  return problem;
}

Dense Assemble(const ArrowProblem& problem) {
  Dense d;
  int size = 0;
  for (const ArrowBlock& k : problem.blocks) {
    d.a_offset.push_back(size);
    size += k.p;
  }
  d.b_offset = size;
  size += problem.q;
  d.m = Eigen::MatrixXd::Zero(size, size);
  d.omega = Eigen::MatrixXd::Zero(size, size);
  d.rhs = Eigen::VectorXd::Zero(size);
  for (size_t w = 0; w < problem.blocks.size(); ++w) {
    const ArrowBlock& k = problem.blocks[w];
    // T maps the block's local variables to the global ones.
    Eigen::MatrixXd t = Eigen::MatrixXd::Zero(k.p + k.m(), size);
    for (int a = 0; a < k.p; ++a) t(a, d.a_offset[w] + a) = 1.0;
    for (int j = 0; j < k.m(); ++j) t(k.p + j, d.b_offset + k.shared_index[j]) = 1.0;
    d.m += t.transpose() * k.h * t;
    d.omega += t.transpose() * (k.scale * k.h) * t;
    d.rhs += t.transpose() * (k.h * k.x0 - k.g);
    for (int a = 0; a < k.p; ++a) {
      d.m(d.a_offset[w] + a, d.a_offset[w] + a) += k.prior_information[a];
      d.omega(d.a_offset[w] + a, d.a_offset[w] + a) += k.prior_information[a];
      d.rhs[d.a_offset[w] + a] += k.prior_information[a] * k.prior_mean[a];
    }
  }
  for (int e = 0; e < problem.q; ++e) {
    d.m(d.b_offset + e, d.b_offset + e) += problem.shared_prior_information[e];
    d.omega(d.b_offset + e, d.b_offset + e) += problem.shared_prior_information[e];
    d.rhs[d.b_offset + e] += problem.shared_prior_information[e] * problem.shared_prior_mean[e];
  }
  return d;
}

void ExpectNear(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  ASSERT_EQ(a.rows(), b.rows());
  ASSERT_EQ(a.cols(), b.cols());
  EXPECT_LE((a - b).norm(), kTolerance * std::max(1.0, b.norm())) << a << "\nvs\n" << b;
}

class BlockArrowTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::mt19937_64 rng(20240501);
    problem_ = RandomProblem(5, 3, 6, &rng);
    dense_ = Assemble(problem_);
    ASSERT_TRUE(solver_.Solve(problem_));
    inverse_ = dense_.m.inverse();
  }
  Eigen::MatrixXd Block(const Eigen::MatrixXd& m, int w, int u) const {
    const int rw = w < 0 ? dense_.b_offset : dense_.a_offset[w];
    const int ru = u < 0 ? dense_.b_offset : dense_.a_offset[u];
    return m.block(rw, ru, w < 0 ? problem_.q : 3, u < 0 ? problem_.q : 3);
  }
  ArrowProblem problem_;
  Dense dense_;
  ArrowSolver solver_;
  Eigen::MatrixXd inverse_;
};

TEST_F(BlockArrowTest, SolutionMatchesTheDenseSolve) {
  const Eigen::VectorXd x = dense_.m.ldlt().solve(dense_.rhs);
  for (int w = 0; w < 5; ++w) ExpectNear(solver_.a(w), x.segment(dense_.a_offset[w], 3));
  ExpectNear(solver_.b(), x.tail(problem_.q));
}

TEST_F(BlockArrowTest, PredictedChiSquareIsTheMinimumOfTheQuadraticModels) {
  // sum_w c + 2 g^T dx + dx^T H dx plus the priors, at any point (a_w, b).
  const auto chi2 = [&](const std::vector<Eigen::VectorXd>& a, const Eigen::VectorXd& b) {
    double sum = 0.0;
    for (int w = 0; w < 5; ++w) {
      const ArrowBlock& k = problem_.blocks[w];
      Eigen::VectorXd x(k.p + k.m());
      x.head(k.p) = a[w];
      for (int j = 0; j < k.m(); ++j) x[k.p + j] = b[k.shared_index[j]];
      const Eigen::VectorXd dx = x - k.x0;
      sum += k.c + 2.0 * k.g.dot(dx) + dx.dot(k.h * dx);
      const Eigen::VectorXd da = a[w] - k.prior_mean;
      sum += da.dot(k.prior_information.cwiseProduct(da));
    }
    const Eigen::VectorXd db = b - problem_.shared_prior_mean;
    return sum + db.dot(problem_.shared_prior_information.cwiseProduct(db));
  };
  std::vector<Eigen::VectorXd> a;
  for (int w = 0; w < 5; ++w) a.push_back(solver_.a(w));
  const double at_solution = chi2(a, solver_.b());
  EXPECT_NEAR(solver_.ChiSquare(), at_solution, kTolerance * at_solution);
  // Moving any one parameter by 0.01 raises it (by the curvature: second order).
  for (int e = 0; e < problem_.q; ++e) {
    Eigen::VectorXd b = solver_.b();
    b[e] += 0.01;
    EXPECT_GT(chi2(a, b), at_solution);
  }
  a[3][1] -= 0.01;
  EXPECT_GT(chi2(a, solver_.b()), at_solution);
}

TEST_F(BlockArrowTest, FormalCovarianceBlocksAreTheInverse) {
  for (int w = 0; w < 5; ++w) {
    for (int u = 0; u < 5; ++u) ExpectNear(solver_.FormalAA(w, u), Block(inverse_, w, u));
    ExpectNear(solver_.FormalAB(w), Block(inverse_, w, -1));
  }
  ExpectNear(solver_.FormalBB(), Block(inverse_, -1, -1));
}

TEST_F(BlockArrowTest, SandwichBlocksAreTheDenseSandwich) {
  const Eigen::MatrixXd sandwich = inverse_ * dense_.omega * inverse_;
  for (int w = 0; w < 5; ++w) {
    for (int u = 0; u < 5; ++u) ExpectNear(solver_.SandwichAA(w, u), Block(sandwich, w, u));
    ExpectNear(solver_.SandwichAB(w), Block(sandwich, w, -1));
  }
  ExpectNear(solver_.SandwichBB(), Block(sandwich, -1, -1));
}

TEST_F(BlockArrowTest, SandwichWithUnitScalesIsTheFormalCovariance) {
  for (ArrowBlock& k : problem_.blocks) k.scale = 1.0;
  ASSERT_TRUE(solver_.Solve(problem_));
  for (int w = 0; w < 5; ++w) ExpectNear(solver_.SandwichAA(w, 4 - w), solver_.FormalAA(w, 4 - w));
  ExpectNear(solver_.SandwichBB(), solver_.FormalBB());
}

TEST_F(BlockArrowTest, SolveForIsTheInverseTimesTheRightHandSide) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  ArrowVector c;
  Eigen::MatrixXd dense(dense_.m.rows(), 2);
  for (int w = 0; w < 5; ++w) {
    c.a.push_back(Eigen::MatrixXd(3, 2));
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 2; ++k) dense(dense_.a_offset[w] + r, k) = c.a[w](r, k) = normal(rng);
    }
  }
  c.b = Eigen::MatrixXd(problem_.q, 2);
  for (int r = 0; r < problem_.q; ++r) {
    for (int k = 0; k < 2; ++k) dense(dense_.b_offset + r, k) = c.b(r, k) = normal(rng);
  }
  const ArrowVector x = solver_.SolveFor(c);
  const Eigen::MatrixXd expected = inverse_ * dense;
  for (int w = 0; w < 5; ++w) ExpectNear(x.a[w], expected.block(dense_.a_offset[w], 0, 3, 2));
  ExpectNear(x.b, expected.bottomRows(problem_.q));
}

// A rows x cols matrix of seeded standard normal entries.
Eigen::MatrixXd NormalMatrix(int rows, int cols, std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd m(rows, cols);
  for (int c = 0; c < cols; ++c) {
    for (int r = 0; r < rows; ++r) m(r, c) = normal(*rng);
  }
  return m;
}

TEST_F(BlockArrowTest, QuadraticFormOfSomeWindowsIsTheDenseOne) {
  // C zero but in windows 1 and 3 and in b: C^T M^-1 C from the dense inverse.
  std::mt19937_64 rng(11);
  const std::vector<int> windows = {1, 3};
  std::vector<Eigen::MatrixXd> c_a;
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(dense_.m.rows(), 2);
  for (int w : windows) {
    c_a.push_back(NormalMatrix(3, 2, &rng));
    dense.middleRows(dense_.a_offset[w], 3) = c_a.back();
  }
  const Eigen::MatrixXd c_b = NormalMatrix(problem_.q, 2, &rng);
  dense.middleRows(dense_.b_offset, problem_.q) = c_b;
  ExpectNear(solver_.QuadraticForm(windows, c_a, c_b), dense.transpose() * inverse_ * dense);
  // One window alone, no b part.
  const Eigen::MatrixXd zero_b = Eigen::MatrixXd::Zero(problem_.q, 2);
  Eigen::MatrixXd one = Eigen::MatrixXd::Zero(dense_.m.rows(), 2);
  one.middleRows(dense_.a_offset[3], 3) = c_a[1];
  ExpectNear(solver_.QuadraticForm({3}, {c_a[1]}, zero_b), one.transpose() * inverse_ * one);
}

TEST_F(BlockArrowTest, QuadraticFormOfLocalScattersTheSharedRows) {
  // C in windows 0 and 2 given in their local order [a; s]: the s rows land in b at each
  // window's shared_index, both windows' adding up where they share a parameter.
  std::mt19937_64 rng(13);
  const std::vector<int> windows = {0, 2};
  std::vector<Eigen::MatrixXd> local;
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(dense_.m.rows(), 2);
  for (int w : windows) {
    const ArrowBlock& k = problem_.blocks[w];
    local.push_back(NormalMatrix(k.p + k.m(), 2, &rng));
    dense.middleRows(dense_.a_offset[w], k.p) += local.back().topRows(k.p);
    for (int j = 0; j < k.m(); ++j) {
      dense.row(dense_.b_offset + k.shared_index[j]) += local.back().row(k.p + j);
    }
  }
  ExpectNear(solver_.QuadraticFormOfLocal(windows, local), dense.transpose() * inverse_ * dense);
}

TEST_F(BlockArrowTest, RefusesAWindowThatCannotDetermineItsParameters) {
  ArrowProblem bad = problem_;
  bad.blocks[2].h.row(1).setZero();
  bad.blocks[2].h.col(1).setZero();
  bad.blocks[2].prior_information.setZero();
  ArrowSolver solver;
  EXPECT_FALSE(solver.Solve(bad));
}

}  // namespace
}  // namespace fastcal::internal
