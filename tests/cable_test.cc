// Tests of the cable unit (cable.h): the inverse against the end point (uniform and as
// built), the end point's partials against central differences, the tension at the upper
// end, the mass on the cable, the lumped chain's ends and tensions, a segment's
// stiffness along and across its chord, and refusals.
#include "fastcal/cable.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>
#include <vector>

namespace fastcal {
namespace {

constexpr double kGravity = -9.8;
// FAST's cable (docs/model.md) over a typical span: 270 m towers, the cabin ~150 m up.
constexpr double kEaN = 2.4656e7;
constexpr double kDensity = 11.718;
constexpr double kSpanM = 250.0;
constexpr double kRiseM = 120.0;
constexpr double kS0M = 277.0;
// The inverse closes to 1e-12 of the chord; checked at 1e-9 m.
constexpr double kClosureM = 1e-9;
// Central differences of the end point with relative steps of 1e-6: agree to 1e-6.
constexpr double kRelativeStep = 1e-6;
constexpr double kDerivativeTolerance = 1e-6;

Cable AsBuilt() {
  return Cable(
      kEaN, kDensity,
      {CableAttachment::PointMass(3.0, 450.0), CableAttachment::AddedDensity(0.0, 150.0, 1.2)});
}

TEST(CableTest, ForcesPutTheEndWhereAsked) {
  for (const Cable& cable : {Cable(kEaN, kDensity), AsBuilt()}) {
    CatenaryForces f;
    int iterations = 0;
    ASSERT_EQ(cable.Forces(kSpanM, kRiseM, kS0M, kGravity, CatenarySolverOptions(), nullptr, &f,
                           &iterations),
              CatenaryStatus::kOk);
    const CatenaryEnd<double> e = cable.End(f.fl_n, f.fz_n, kS0M, kGravity);
    EXPECT_NEAR(e.span_m, kSpanM, kClosureM);
    EXPECT_NEAR(e.rise_m, kRiseM, kClosureM);
    EXPECT_GT(f.fl_n, 0.0);
  }
}

// The attachments pull the lower end's vertical force down by about their weight's lower
// share: the as-built cable's Fz differs from the bare one's, and with zero-mass
// attachments it is the bare one's.
TEST(CableTest, AttachmentsOfNoMassAreTheBareCable) {
  const Cable bare(kEaN, kDensity);
  const Cable weightless(
      kEaN, kDensity,
      {CableAttachment::PointMass(3.0, 0.0), CableAttachment::AddedDensity(0.0, 150.0, 0.0)});
  CatenaryForces a, b, c;
  int iterations = 0;
  const CatenarySolverOptions o;
  ASSERT_EQ(bare.Forces(kSpanM, kRiseM, kS0M, kGravity, o, nullptr, &a, &iterations),
            CatenaryStatus::kOk);
  ASSERT_EQ(weightless.Forces(kSpanM, kRiseM, kS0M, kGravity, o, nullptr, &b, &iterations),
            CatenaryStatus::kOk);
  ASSERT_EQ(AsBuilt().Forces(kSpanM, kRiseM, kS0M, kGravity, o, nullptr, &c, &iterations),
            CatenaryStatus::kOk);
  EXPECT_NEAR(b.fl_n, a.fl_n, 1e-6 * a.fl_n);
  EXPECT_NEAR(b.fz_n, a.fz_n, 1e-6 * std::abs(a.fz_n));
  EXPECT_GT(std::abs(c.fz_n - a.fz_n), 1e3);  // 450 kg and 180 kg of lines: kN, not N
}

TEST(CableTest, EndPartialsMatchCentralDifferences) {
  const Cable cable = AsBuilt();
  const double x[3] = {6.0e5, -5.0e5, kS0M};
  const CatenaryEnd<double> e = cable.End(x[0], x[1], x[2], kGravity);
  for (int k = 0; k < 3; ++k) {
    double plus[3] = {x[0], x[1], x[2]}, minus[3] = {x[0], x[1], x[2]};
    const double h = kRelativeStep * std::abs(x[k]);
    plus[k] += h;
    minus[k] -= h;
    const CatenaryEnd<double> p = cable.End(plus[0], plus[1], plus[2], kGravity);
    const CatenaryEnd<double> m = cable.End(minus[0], minus[1], minus[2], kGravity);
    const double dspan = (p.span_m - m.span_m) / (2 * h);
    const double drise = (p.rise_m - m.rise_m) / (2 * h);
    EXPECT_NEAR(e.dspan[k], dspan, kDerivativeTolerance * (std::abs(dspan) + 1e-12)) << k;
    EXPECT_NEAR(e.drise[k], drise, kDerivativeTolerance * (std::abs(drise) + 1e-12)) << k;
  }
}

TEST(CableTest, TensionAtTheTopIsTheEndsUpperTension) {
  for (const Cable& cable : {Cable(kEaN, kDensity), AsBuilt()}) {
    const CatenaryEnd<double> e = cable.End(6.0e5, -5.0e5, kS0M, kGravity);
    EXPECT_NEAR(cable.Tension(6.0e5, -5.0e5, kS0M, kGravity), e.upper_tension_n, 1e-6);
    EXPECT_NEAR(cable.Tension(6.0e5, -5.0e5, 0.0, kGravity), e.lower_tension_n, 1e-6);
  }
}

TEST(CableTest, MassCountsWhatIsOnTheCable) {
  EXPECT_DOUBLE_EQ(Cable(kEaN, kDensity).MassKg(kS0M), kDensity * kS0M);
  EXPECT_DOUBLE_EQ(AsBuilt().MassKg(kS0M), kDensity * kS0M + 450.0 + 1.2 * 150.0);
  // At s0 = 100 m the added density reaches beyond the end: 100 m of it count.
  EXPECT_DOUBLE_EQ(AsBuilt().MassKg(100.0), kDensity * 100.0 + 450.0 + 1.2 * 100.0);
  // At s0 = 2 m the point mass at 3 m is not on the cable.
  EXPECT_DOUBLE_EQ(AsBuilt().MassKg(2.0), kDensity * 2.0 + 1.2 * 2.0);
}

TEST(CableTest, LumpedChainSpansTheEndsWithTheCatenarysTensions) {
  const Cable cable(kEaN, kDensity);
  CatenaryForces f;
  int iterations = 0;
  ASSERT_EQ(cable.Forces(kSpanM, kRiseM, kS0M, kGravity, CatenarySolverOptions(), nullptr, &f,
                         &iterations),
            CatenaryStatus::kOk);
  const Eigen::Vector3d lower(10.0, -5.0, 150.0);
  const Eigen::Vector3d upper = lower + Eigen::Vector3d(0.6 * kSpanM, 0.8 * kSpanM, kRiseM);
  constexpr int kSegments = 24;
  LumpedChain chain;
  std::string error;
  ASSERT_TRUE(cable.Lumped(lower, upper, f.fl_n, f.fz_n, kS0M, kGravity, kSegments, &chain, &error))
      << error;
  ASSERT_EQ(chain.segments(), kSegments);
  EXPECT_LT((chain.nodes_m.front() - lower).norm(), kClosureM);
  EXPECT_LT((chain.nodes_m.back() - upper).norm(), 1e-6);
  EXPECT_DOUBLE_EQ(chain.segment_length_m, kS0M / kSegments);
  EXPECT_DOUBLE_EQ(chain.node_mass_kg * kSegments, cable.MassKg(kS0M));
  // Tension grows toward the top (the cable's weight), between the ends' tensions.
  const CatenaryEnd<double> e = cable.End(f.fl_n, f.fz_n, kS0M, kGravity);
  for (int j = 0; j < kSegments; ++j) {
    EXPECT_GT(chain.tension_n[j], e.lower_tension_n);
    EXPECT_LT(chain.tension_n[j], e.upper_tension_n);
    if (j > 0) EXPECT_GT(chain.tension_n[j], chain.tension_n[j - 1]);
  }
  // Forces that do not belong to s0 do not close on the upper end: refused.
  EXPECT_FALSE(
      cable.Lumped(lower, upper, 1.01 * f.fl_n, f.fz_n, kS0M, kGravity, kSegments, &chain, &error));
  EXPECT_NE(error.find("misses its upper end"), std::string::npos) << error;
  EXPECT_FALSE(
      AsBuilt().Lumped(lower, upper, f.fl_n, f.fz_n, kS0M, kGravity, kSegments, &chain, &error));
  EXPECT_NE(error.find("uniform"), std::string::npos) << error;
}

// Along the chord the axial stiffness EA/l0, across it the string's T/l (twice).
TEST(CableTest, SegmentStiffnessIsAxialAlongAndGeometricAcross) {
  const Eigen::Vector3d chord(3.0, 4.0, 12.0);  // l = 13 m
  const double tension_n = 5e5, l0_m = 12.99;
  const Eigen::Matrix3d k = Cable::SegmentStiffness(chord, tension_n, kEaN, l0_m);
  EXPECT_LT((k - k.transpose()).norm(), 1e-9 * k.norm());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(k);
  EXPECT_NEAR(eigen.eigenvalues()[0], tension_n / 13.0, 1e-9 * kEaN);
  EXPECT_NEAR(eigen.eigenvalues()[1], tension_n / 13.0, 1e-9 * kEaN);
  EXPECT_NEAR(eigen.eigenvalues()[2], kEaN / l0_m, 1e-9 * kEaN);
  EXPECT_LT((k * chord - (kEaN / l0_m) * chord).norm(), 1e-9 * kEaN);
}

TEST(CableTest, BadCablesAreRefused) {
  std::string error;
  EXPECT_FALSE(Cable(0.0, kDensity).IsValid(&error));
  EXPECT_NE(error.find("EA and linear density"), std::string::npos) << error;
  EXPECT_FALSE(Cable(kEaN, std::nan("")).IsValid(&error));
  EXPECT_FALSE(Cable(kEaN, kDensity, {CableAttachment::PointMass(-1.0, 10.0)}).IsValid(&error));
  EXPECT_NE(error.find("attachment 1"), std::string::npos) << error;
  EXPECT_TRUE(AsBuilt().IsValid(&error)) << error;
  CatenaryForces f;
  int iterations = 0;
  EXPECT_EQ(AsBuilt().Forces(kSpanM, kRiseM, -1.0, kGravity, CatenarySolverOptions(), nullptr, &f,
                             &iterations),
            CatenaryStatus::kInvalidInput);
}

}  // namespace
}  // namespace fastcal
