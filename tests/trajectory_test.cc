// Tests of the trajectory generators, pose construction and the pose CSV reader.
#include "fastcal/trajectory.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "temp_path.h"

namespace fastcal {
namespace {

constexpr double kPositionTolerance_m = 1e-9;
constexpr double kAngleTolerance_deg = 1e-9;
constexpr double kRotationTolerance = 1e-12;
constexpr double kDegToRad = M_PI / 180.0;

const Eigen::Vector3d kFocalCentre_m(0.0, 0.0, 300.0);
constexpr double kFocalRadius_m = 160.0;

// Off-axis angle of `p` seen from the focal centre, from the downward vertical.
double OffAxisDeg(const Eigen::Vector3d& p) {
  const Eigen::Vector3d d = p - kFocalCentre_m;
  return std::atan2(d.head<2>().norm(), -d.z()) / kDegToRad;
}

double MinPairwiseDistance(const std::vector<Eigen::Vector3d>& points) {
  double min_m = INFINITY;
  for (size_t i = 0; i < points.size(); ++i) {
    for (size_t j = i + 1; j < points.size(); ++j) {
      min_m = std::min(min_m, (points[i] - points[j]).norm());
    }
  }
  return min_m;
}

// ---- Line ----

TEST(LinePositions, PaperLineEndsAndEvenSpacing) {
  const Eigen::Vector3d g1(50.0, 0.0, 150.0), g2(-50.0, 0.0, 150.0);
  std::vector<Eigen::Vector3d> p;
  std::string error;
  ASSERT_TRUE(LinePositions(g1, g2, 101, &p, &error)) << error;
  ASSERT_EQ(p.size(), 101u);
  EXPECT_EQ(p.front(), g1);  // ends exact, not only close
  EXPECT_EQ(p.back(), g2);
  for (size_t k = 0; k < p.size(); ++k) {
    const Eigen::Vector3d expected(50.0 - static_cast<double>(k), 0.0, 150.0);
    EXPECT_LT((p[k] - expected).norm(), kPositionTolerance_m) << "node " << k;
  }
}

TEST(LinePositions, TwoNodesAreTheEnds) {
  const Eigen::Vector3d a(1.0, 2.0, 3.0), b(4.0, -5.0, 6.0);
  std::vector<Eigen::Vector3d> p;
  ASSERT_TRUE(LinePositions(a, b, 2, &p, nullptr));
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[0], a);
  EXPECT_EQ(p[1], b);
}

// ---- Arc ----

// The streams simulate draws its positions from (issue 20) give the vectors' positions bit
// for bit, and a copy of a stream starts where the original stands, so a checking pass over
// a copy leaves the original at its start.
TEST(PositionStream, GivesTheVectorsPositionsAndCopiesKeepTheirPlace) {
  RandomWorkspaceSpec random;
  random.samples = 500;
  random.radial_spread_m = 3.0;
  random.seed = 7;
  ArcSpec arc;
  arc.centre_m = Eigen::Vector3d(0.0, 0.0, 150.0);
  arc.radius_m = 50.0;
  arc.end_deg = 360.0;
  arc.nodes = 77;
  std::vector<Eigen::Vector3d> from_vector[3];
  PositionStream streams[3];
  ASSERT_TRUE(RandomWorkspacePositions(random, &from_vector[0], nullptr));
  ASSERT_TRUE(RandomWorkspacePositionStream(random, &streams[0], nullptr));
  ASSERT_TRUE(ArcPositions(arc, &from_vector[1], nullptr));
  ASSERT_TRUE(ArcPositionStream(arc, &streams[1], nullptr));
  const Eigen::Vector3d from(50.0, 0.0, 150.0), to(-50.0, 0.0, 150.0);
  ASSERT_TRUE(LinePositions(from, to, 101, &from_vector[2], nullptr));
  ASSERT_TRUE(LinePositionStream(from, to, 101, &streams[2], nullptr));
  for (int k = 0; k < 3; ++k) {
    ASSERT_EQ(streams[k].count, static_cast<long long>(from_vector[k].size()));
    PositionStream copy = streams[k];
    for (size_t n = 0; n < from_vector[k].size(); ++n) EXPECT_EQ(copy.next(), from_vector[k][n]);
    for (size_t n = 0; n < from_vector[k].size(); ++n) {
      EXPECT_EQ(streams[k].next(), from_vector[k][n]) << k << " " << n;
    }
  }
  std::string error;
  random.samples = 0;
  EXPECT_FALSE(RandomWorkspacePositionStream(random, &streams[0], &error));
  EXPECT_EQ(error, "samples must be >= 1 (got 0)");
}

TEST(ArcPositions, PaperHalfCircle) {
  ArcSpec spec;
  spec.centre_m = Eigen::Vector3d(0.0, 0.0, 150.0);
  spec.radius_m = 50.0;
  spec.start_deg = 0.0;
  spec.end_deg = 180.0;
  spec.nodes = 101;
  std::vector<Eigen::Vector3d> p;
  std::string error;
  ASSERT_TRUE(ArcPositions(spec, &p, &error)) << error;
  ASSERT_EQ(p.size(), 101u);
  EXPECT_LT((p.front() - Eigen::Vector3d(50.0, 0.0, 150.0)).norm(), kPositionTolerance_m);
  EXPECT_LT((p[50] - Eigen::Vector3d(0.0, 50.0, 150.0)).norm(), kPositionTolerance_m);
  EXPECT_LT((p.back() - Eigen::Vector3d(-50.0, 0.0, 150.0)).norm(), kPositionTolerance_m);
  for (size_t k = 0; k < p.size(); ++k) {
    EXPECT_NEAR(p[k].z(), 150.0, kPositionTolerance_m) << "node " << k;
    EXPECT_NEAR((p[k] - spec.centre_m).norm(), 50.0, kPositionTolerance_m) << "node " << k;
    const double angle_deg = std::atan2(p[k].y(), p[k].x()) / kDegToRad;
    EXPECT_NEAR(angle_deg, 1.8 * k, kAngleTolerance_deg) << "node " << k;
  }
}

TEST(ArcPositions, FullCircleHasDistinctNodesEvenlySpaced) {
  ArcSpec spec;  // the measured circle, 36 nodes
  spec.centre_m = Eigen::Vector3d(0.0, 0.0, 156.73);
  spec.radius_m = 71.11;
  spec.nodes = 36;
  std::vector<Eigen::Vector3d> p;
  std::string error;
  ASSERT_TRUE(ArcPositions(spec, &p, &error)) << error;
  ASSERT_EQ(p.size(), 36u);
  // Neighbours 10 deg apart, including last -> first: no node repeated.
  const double chord_m = 2.0 * spec.radius_m * std::sin(5.0 * kDegToRad);
  EXPECT_NEAR(MinPairwiseDistance(p), chord_m, kPositionTolerance_m);
  EXPECT_NEAR((p.back() - p.front()).norm(), chord_m, kPositionTolerance_m);
  for (const Eigen::Vector3d& q : p) {
    EXPECT_NEAR(q.z(), 156.73, kPositionTolerance_m);
    EXPECT_NEAR((q - spec.centre_m).norm(), 71.11, kPositionTolerance_m);
  }
}

TEST(ArcPositions, NegativeSpanRunsClockwiseAndFullTurnBackwards) {
  ArcSpec spec;
  spec.radius_m = 10.0;
  spec.start_deg = 90.0;
  spec.end_deg = 0.0;
  spec.nodes = 3;
  std::vector<Eigen::Vector3d> p;
  ASSERT_TRUE(ArcPositions(spec, &p, nullptr));
  ASSERT_EQ(p.size(), 3u);
  EXPECT_LT((p[0] - Eigen::Vector3d(0.0, 10.0, 0.0)).norm(), kPositionTolerance_m);
  const double s = 10.0 * std::sqrt(0.5);
  EXPECT_LT((p[1] - Eigen::Vector3d(s, s, 0.0)).norm(), kPositionTolerance_m);
  EXPECT_LT((p[2] - Eigen::Vector3d(10.0, 0.0, 0.0)).norm(), kPositionTolerance_m);

  spec.end_deg = 90.0 - 360.0;
  spec.nodes = 4;
  ASSERT_TRUE(ArcPositions(spec, &p, nullptr));
  ASSERT_EQ(p.size(), 4u);
  EXPECT_LT((p[1] - Eigen::Vector3d(10.0, 0.0, 0.0)).norm(), kPositionTolerance_m);
  EXPECT_LT((p[3] - Eigen::Vector3d(-10.0, 0.0, 0.0)).norm(), kPositionTolerance_m);
}

// ---- Focal sphere grid ----

// ---- The paper's measured circle ----

// The circle the paper measured, and its recognition in a dataset's positions: the
// whole turn within a metre (a measured position scatters by centimetres), in any order;
// not another radius, height or a half turn.
TEST(PaperCircleMatcher, RecognisesTheMeasuredCircleAndNothingElse) {
  const ArcSpec circle = PaperCircleArc();
  EXPECT_EQ(circle.centre_m, Eigen::Vector3d(0.0, 0.0, 156.73));
  EXPECT_EQ(circle.radius_m, 71.11);
  EXPECT_EQ(circle.nodes, 360);
  std::vector<Eigen::Vector3d> p;
  ASSERT_TRUE(ArcPositions(circle, &p, nullptr));
  auto matches = [](const std::vector<Eigen::Vector3d>& positions) {
    PaperCircleMatcher m;
    for (const Eigen::Vector3d& x : positions) m.Add(x);
    return m.Matches();
  };
  EXPECT_TRUE(matches(p));
  std::vector<Eigen::Vector3d> scattered = p;  // measured: +-0.9 m, shuffled
  for (size_t k = 0; k < scattered.size(); ++k) {
    scattered[k] += Eigen::Vector3d(0.9 * std::cos(7.0 * k), 0.0, -0.9 * std::sin(3.0 * k));
  }
  std::reverse(scattered.begin(), scattered.end());
  EXPECT_TRUE(matches(scattered));
  EXPECT_FALSE(matches({}));
  ArcSpec other = circle;
  other.radius_m = 70.0;  // 1.11 m inside
  ASSERT_TRUE(ArcPositions(other, &p, nullptr));
  EXPECT_FALSE(matches(p));
  other = circle;
  other.centre_m.z() = 155.5;
  ASSERT_TRUE(ArcPositions(other, &p, nullptr));
  EXPECT_FALSE(matches(p));
  other = circle;
  other.end_deg = 180.0;  // half a turn
  ASSERT_TRUE(ArcPositions(other, &p, nullptr));
  EXPECT_FALSE(matches(p));
  // One position elsewhere (a stray sample) is not the paper's survey either.
  ASSERT_TRUE(ArcPositions(circle, &p, nullptr));
  p.push_back(Eigen::Vector3d(0.0, 0.0, 140.0));
  EXPECT_FALSE(matches(p));
}

TEST(FocalSpherePositions, DefaultGridCoversTheCap) {
  std::vector<Eigen::Vector3d> p;
  std::string error;
  ASSERT_TRUE(FocalSpherePositions(FocalGridSpec(), &p, &error)) << error;
  ASSERT_EQ(p.size(), 1u + 8u * 24u);
  double max_off_axis_deg = 0.0;
  double min_z_m = INFINITY;
  int on_axis = 0;
  for (const Eigen::Vector3d& q : p) {
    EXPECT_NEAR((q - kFocalCentre_m).norm(), kFocalRadius_m, kPositionTolerance_m);
    max_off_axis_deg = std::max(max_off_axis_deg, OffAxisDeg(q));
    min_z_m = std::min(min_z_m, q.z());
    if (q.head<2>().norm() < kPositionTolerance_m) ++on_axis;
  }
  EXPECT_NEAR(max_off_axis_deg, 40.0, kAngleTolerance_deg);
  EXPECT_NEAR(min_z_m, 140.0, kPositionTolerance_m);
  EXPECT_EQ(on_axis, 1);
  EXPECT_LT((p.front() - Eigen::Vector3d(0.0, 0.0, 140.0)).norm(), kPositionTolerance_m);
  // The outer ring: horizontal radius 160 sin(40 deg), first azimuth along +x.
  const Eigen::Vector3d outer_first(kFocalRadius_m * std::sin(40.0 * kDegToRad), 0.0,
                                    300.0 - kFocalRadius_m * std::cos(40.0 * kDegToRad));
  EXPECT_LT((p[1 + 7 * 24] - outer_first).norm(), kPositionTolerance_m);
  EXPECT_GT(MinPairwiseDistance(p), 1.0);  // no point repeated
}

TEST(FocalSpherePositions, MaxIncludedOnlyWhenAMultipleOfTheStep) {
  FocalGridSpec spec;
  std::vector<Eigen::Vector3d> p;
  spec.max_off_axis_deg = 42.0;  // rings at 5..40
  ASSERT_TRUE(FocalSpherePositions(spec, &p, nullptr));
  EXPECT_EQ(p.size(), 1u + 8u * 24u);
  spec.max_off_axis_deg = 45.0;  // rings at 5..45
  ASSERT_TRUE(FocalSpherePositions(spec, &p, nullptr));
  EXPECT_EQ(p.size(), 1u + 9u * 24u);
  spec.max_off_axis_deg = 0.7 * 3.0;  // 2.0999999999999996: 2.9999999999999996 steps
  spec.off_axis_step_deg = 0.7;
  spec.azimuth_step_deg = 7.0;  // azimuths 0, 7, ..., 357: 52
  ASSERT_TRUE(FocalSpherePositions(spec, &p, nullptr));
  EXPECT_EQ(p.size(), 1u + 3u * 52u);
  spec.max_off_axis_deg = 0.0;
  ASSERT_TRUE(FocalSpherePositions(spec, &p, nullptr));
  EXPECT_EQ(p.size(), 1u);
}

// ---- Random workspace ----

RandomWorkspaceSpec RandomSpec(int samples, std::uint64_t seed) {
  RandomWorkspaceSpec spec;
  spec.samples = samples;
  spec.seed = seed;
  return spec;
}

TEST(RandomWorkspacePositions, SeededAndInsideTheCap) {
  constexpr int kSamples = 500;
  std::vector<Eigen::Vector3d> a, b, c;
  std::string error;
  ASSERT_TRUE(RandomWorkspacePositions(RandomSpec(kSamples, 7), &a, &error)) << error;
  ASSERT_TRUE(RandomWorkspacePositions(RandomSpec(kSamples, 7), &b, &error)) << error;
  ASSERT_TRUE(RandomWorkspacePositions(RandomSpec(kSamples, 8), &c, &error)) << error;
  ASSERT_EQ(a.size(), static_cast<size_t>(kSamples));
  ASSERT_EQ(c.size(), static_cast<size_t>(kSamples));
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  for (const Eigen::Vector3d& q : a) {
    EXPECT_NEAR((q - kFocalCentre_m).norm(), kFocalRadius_m, kPositionTolerance_m);
    EXPECT_LE(OffAxisDeg(q), 40.0 + kAngleTolerance_deg);
  }
}

TEST(RandomWorkspacePositions, UniformOverTheCapArea) {
  // Area fraction of the cap within 20 deg of the axis: (1 - cos 20) / (1 - cos 40) = 0.258
  // (sampling theta uniformly would give 0.5). 20000 samples: sigma = 0.003.
  constexpr int kSamples = 20000;
  constexpr double kFractionTolerance = 0.02;
  std::vector<Eigen::Vector3d> p;
  ASSERT_TRUE(RandomWorkspacePositions(RandomSpec(kSamples, 2024), &p, nullptr));
  int inner = 0;
  Eigen::Vector2d mean_direction = Eigen::Vector2d::Zero();
  for (const Eigen::Vector3d& q : p) {
    if (OffAxisDeg(q) <= 20.0) ++inner;
    mean_direction += q.head<2>().normalized() / kSamples;
  }
  const double expected = (1.0 - std::cos(20.0 * kDegToRad)) / (1.0 - std::cos(40.0 * kDegToRad));
  EXPECT_NEAR(static_cast<double>(inner) / kSamples, expected, kFractionTolerance);
  EXPECT_LT(mean_direction.norm(), kFractionTolerance);  // azimuths cover the full turn
}

TEST(RandomWorkspacePositions, RadialSpreadMovesOnlyAlongTheNormal) {
  constexpr int kSamples = 500;
  constexpr double kSpread_m = 3.0;
  RandomWorkspaceSpec spec = RandomSpec(kSamples, 11);
  std::vector<Eigen::Vector3d> on_sphere, spread;
  ASSERT_TRUE(RandomWorkspacePositions(spec, &on_sphere, nullptr));
  spec.radial_spread_m = kSpread_m;
  ASSERT_TRUE(RandomWorkspacePositions(spec, &spread, nullptr));
  ASSERT_EQ(spread.size(), on_sphere.size());
  double min_m = INFINITY, max_m = -INFINITY;
  for (size_t i = 0; i < spread.size(); ++i) {
    const Eigen::Vector3d d = spread[i] - kFocalCentre_m;
    const Eigen::Vector3d d0 = on_sphere[i] - kFocalCentre_m;
    EXPECT_LT((d.normalized() - d0.normalized()).norm(), kPositionTolerance_m);
    min_m = std::min(min_m, d.norm());
    max_m = std::max(max_m, d.norm());
  }
  EXPECT_GE(min_m, kFocalRadius_m - kSpread_m);
  EXPECT_LE(max_m, kFocalRadius_m + kSpread_m);
  EXPECT_LT(min_m, kFocalRadius_m - 0.9 * kSpread_m);  // the whole band is used
  EXPECT_GT(max_m, kFocalRadius_m + 0.9 * kSpread_m);
}

// ---- Poses ----

// Around the focal law: the positions are RandomWorkspacePositions' own, each attitude
// the law's times a rotation of at most the amplitude per axis (so at most sqrt(3) times
// it in all), not all small; the same spec gives the same poses; bad amplitudes are named.
TEST(RandomPosesAroundFocalLaw, FocalLawTimesABoundedExtraRotation) {
  constexpr int kSamples = 500;
  constexpr double kMaxDeg = 5.0, kMinDeg = 2.0;
  RandomPoseSpec spec;
  spec.positions = RandomSpec(kSamples, 7);
  std::vector<Pose> poses, again;
  std::vector<Eigen::Vector3d> positions;
  std::string error;
  ASSERT_TRUE(RandomPosesAroundFocalLaw(spec, &poses, &error)) << error;
  ASSERT_TRUE(RandomPosesAroundFocalLaw(spec, &again, &error)) << error;
  ASSERT_TRUE(RandomWorkspacePositions(spec.positions, &positions, &error)) << error;
  ASSERT_EQ(poses.size(), static_cast<size_t>(kSamples));
  double largest_deg = 0.0;
  for (int n = 0; n < kSamples; ++n) {
    EXPECT_EQ(poses[n].position_m, positions[n]);
    EXPECT_EQ(poses[n].rotation, again[n].rotation);
    const Eigen::Matrix3d extra =
        FocalAttitude(positions[n], spec.law).transpose() * poses[n].rotation;
    const double angle_deg = Eigen::AngleAxisd(extra).angle() * 180.0 / M_PI;
    EXPECT_LE(angle_deg, std::sqrt(3.0) * kMaxDeg + 1e-9);
    largest_deg = std::max(largest_deg, angle_deg);
  }
  EXPECT_GT(largest_deg, kMaxDeg);  // the three axes add up
  spec.min_extra_rotation_deg = kMaxDeg;
  spec.max_extra_rotation_deg = kMinDeg;
  EXPECT_FALSE(RandomPosesAroundFocalLaw(spec, &poses, &error));
  EXPECT_NE(error.find("min_extra_rotation_deg"), std::string::npos) << error;
}

// Sources tracked at the sidereal rate: every position on the focal sphere within the cap,
// consecutive samples of one source a sidereal turn apart about the celestial pole (the
// feed moves at omega R sin(angle to the pole) <= 11.7 mm/s), a new source after each
// track and at each day's first sample, the same positions for a seed and from a copy of
// the stream.
TEST(SourceTrackPositionStream, SiderealTracksOnTheCap) {
  SourceTrackSpec spec;
  spec.samples = 4 * 1800;
  spec.interval_s = 2.0;
  spec.days = 4;
  spec.min_track_s = 600.0;
  spec.max_track_s = 1200.0;
  spec.max_off_axis_deg = 35.0;
  spec.seed = 5;
  PositionStream stream;
  std::string error;
  ASSERT_TRUE(SourceTrackPositionStream(spec, &stream, &error)) << error;
  PositionStream copy = stream;
  const Eigen::Vector3d centre(0.0, 0.0, 300.0);
  constexpr double kSiderealRate = 2.0 * M_PI / 86164.0905;  // rad/s
  const Eigen::Vector3d pole(0.0, std::cos(spec.latitude_deg * kDegToRad),
                             std::sin(spec.latitude_deg * kDegToRad));
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  int sources = 0, day_starts_new = 0;
  for (int n = 0; n < spec.samples; ++n) {
    const Eigen::Vector3d p = stream.next();
    ASSERT_EQ(p, copy.next()) << "sample " << n;
    const Eigen::Vector3d s = (centre - p) / kFocalRadius_m;  // the source's direction
    EXPECT_NEAR(s.norm(), 1.0, 1e-12);
    EXPECT_GE(s.z(), std::cos(spec.max_off_axis_deg * kDegToRad) - 1e-12) << "sample " << n;
    if (n > 0) {
      const Eigen::Vector3d before = (centre - previous) / kFocalRadius_m;
      // The sidereal step about the pole, or a new source.
      const double expected =
          kSiderealRate * spec.interval_s * kFocalRadius_m * before.cross(pole).norm();
      const bool same = std::abs((p - previous).norm() - expected) < 1e-9;
      sources += !same;
      if (n % 1800 == 0) day_starts_new += !same;
    }
    previous = p;
  }
  EXPECT_EQ(day_starts_new, 3);
  // Tracks of 10-20 minutes (300-600 samples) in 4 days of an hour: 12 to 24 sources.
  EXPECT_GE(sources + 1, 12);
  EXPECT_LE(sources + 1, 28);
  SourceTrackSpec bad = spec;
  bad.min_track_s = 0.0;
  EXPECT_FALSE(SourceTrackPositionStream(bad, &stream, &error));
  EXPECT_NE(error.find("min_track_s"), std::string::npos) << error;
  bad = spec;
  bad.interval_s = -1.0;
  EXPECT_FALSE(SourceTrackPositionStream(bad, &stream, &error));
  EXPECT_NE(error.find("interval_s"), std::string::npos) << error;
}

TEST(PosesWithAttitudeLaw, MatchesFocalAttitude) {
  std::vector<Eigen::Vector3d> positions;
  ASSERT_TRUE(FocalSpherePositions(FocalGridSpec(), &positions, nullptr));
  positions.push_back(Eigen::Vector3d(42.65, 33.73, 149.52));  // K2
  FocalAttitudeLaw law;
  std::vector<Pose> poses;
  std::string error;
  ASSERT_TRUE(PosesWithAttitudeLaw(positions, law, &poses, &error)) << error;
  ASSERT_EQ(poses.size(), positions.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(poses[i].position_m, positions[i]);
    EXPECT_LT((poses[i].rotation - FocalAttitude(positions[i], law)).norm(), kRotationTolerance);
  }
  // Off the axis the law is not the identity: the test would notice a missing attitude.
  EXPECT_GT((poses.back().rotation - Eigen::Matrix3d::Identity()).norm(), 0.1);
}

TEST(PosesWithIdentityAttitude, NeutralAttitude) {
  const std::vector<Eigen::Vector3d> positions = {Eigen::Vector3d(1, 2, 3),
                                                  Eigen::Vector3d(40, -5, 150)};
  std::vector<Pose> poses;
  ASSERT_TRUE(PosesWithIdentityAttitude(positions, &poses, nullptr));
  ASSERT_EQ(poses.size(), 2u);
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(poses[i].position_m, positions[i]);
    EXPECT_EQ(poses[i].rotation, Eigen::Matrix3d::Identity());
  }
}

// ---- Argument errors ----

// Expects `ok` false and the message to name `parameter`.
void ExpectError(bool ok, const std::string& error, const std::string& parameter) {
  EXPECT_FALSE(ok);
  EXPECT_NE(error.find(parameter), std::string::npos) << "error: " << error;
}

TEST(TrajectoryArguments, LineErrorsNameTheParameter) {
  const Eigen::Vector3d a(0, 0, 150), b(1, 0, 150);
  std::vector<Eigen::Vector3d> p = {Eigen::Vector3d(9, 9, 9)};
  std::string error;
  ExpectError(LinePositions(a, b, 1, &p, &error), error, "nodes must be >= 2 (got 1)");
  // A count that would exhaust memory is refused before anything is allocated.
  constexpr int kTooMany = 10000001;
  ExpectError(LinePositions(a, b, kTooMany, &p, &error), error, "nodes must be at most 10000000");
  ExpectError(LinePositions(Eigen::Vector3d(NAN, 0, 0), b, 5, &p, &error), error, "from_m");
  ExpectError(LinePositions(a, Eigen::Vector3d(0, INFINITY, 0), 5, &p, &error), error, "to_m");
  ExpectError(LinePositions(a, b, 5, nullptr, &error), error, "positions");
  ASSERT_EQ(p.size(), 1u);  // output untouched on failure
  EXPECT_EQ(p[0], Eigen::Vector3d(9, 9, 9));
}

TEST(TrajectoryArguments, ArcErrorsNameTheParameter) {
  ArcSpec good;
  good.radius_m = 50.0;
  std::vector<Eigen::Vector3d> p;
  std::string error;
  ASSERT_TRUE(ArcPositions(good, &p, &error)) << error;
  ArcSpec s = good;
  s.radius_m = 0.0;
  ExpectError(ArcPositions(s, &p, &error), error, "radius_m must be > 0 and finite");
  s = good;
  s.radius_m = NAN;
  ExpectError(ArcPositions(s, &p, &error), error, "radius_m must be > 0 and finite");
  s = good;
  s.nodes = 1;
  ExpectError(ArcPositions(s, &p, &error), error, "nodes must be >= 2 (got 1)");
  s.nodes = 10000001;
  ExpectError(ArcPositions(s, &p, &error), error, "nodes must be at most 10000000");
  s = good;
  s.centre_m.x() = NAN;
  ExpectError(ArcPositions(s, &p, &error), error, "centre_m");
  s = good;
  s.start_deg = INFINITY;
  ExpectError(ArcPositions(s, &p, &error), error, "start_deg");
  s = good;
  s.end_deg = NAN;
  ExpectError(ArcPositions(s, &p, &error), error, "end_deg");
  s = good;
  s.end_deg = s.start_deg;
  ExpectError(ArcPositions(s, &p, &error), error, "end_deg");
  s = good;
  s.end_deg = 540.0;
  ExpectError(ArcPositions(s, &p, &error), error, "end_deg - start_deg");
}

TEST(TrajectoryArguments, GridErrorsNameTheParameter) {
  std::vector<Eigen::Vector3d> p;
  std::string error;
  FocalGridSpec s;
  s.max_off_axis_deg = 91.0;
  ExpectError(FocalSpherePositions(s, &p, &error), error, "max_off_axis_deg");
  s = FocalGridSpec();
  s.off_axis_step_deg = 0.0;
  ExpectError(FocalSpherePositions(s, &p, &error), error, "off_axis_step_deg");
  s = FocalGridSpec();
  s.azimuth_step_deg = -15.0;
  ExpectError(FocalSpherePositions(s, &p, &error), error, "azimuth_step_deg");
  s = FocalGridSpec();
  s.focal_radius_m = -160.0;
  ExpectError(FocalSpherePositions(s, &p, &error), error, "focal_radius_m");
  s = FocalGridSpec();
  s.focal_centre_m.z() = NAN;
  ExpectError(FocalSpherePositions(s, &p, &error), error, "focal_centre_m");
  s = FocalGridSpec();
  s.off_axis_step_deg = 1e-12;  // absurdly many points
  ExpectError(FocalSpherePositions(s, &p, &error), error, "off_axis_step_deg");
}

TEST(TrajectoryArguments, RandomErrorsNameTheParameter) {
  std::vector<Eigen::Vector3d> p;
  std::string error;
  RandomWorkspaceSpec s = RandomSpec(0, 1);
  ExpectError(RandomWorkspacePositions(s, &p, &error), error, "samples must be >= 1 (got 0)");
  s = RandomSpec(10000001, 1);
  ExpectError(RandomWorkspacePositions(s, &p, &error), error, "samples must be at most 10000000");
  s = RandomSpec(10, 1);
  s.max_off_axis_deg = -1.0;
  ExpectError(RandomWorkspacePositions(s, &p, &error), error, "max_off_axis_deg");
  s = RandomSpec(10, 1);
  s.radial_spread_m = -1.0;
  ExpectError(RandomWorkspacePositions(s, &p, &error), error, "radial_spread_m");
  s = RandomSpec(10, 1);
  s.radial_spread_m = kFocalRadius_m;
  ExpectError(RandomWorkspacePositions(s, &p, &error), error, "radial_spread_m");
  s = RandomSpec(10, 1);
  s.sphere.focal_radius_m = INFINITY;
  ExpectError(RandomWorkspacePositions(s, &p, &error), error, "sphere.focal_radius_m");
}

TEST(TrajectoryArguments, PoseErrorsNameTheParameter) {
  std::vector<Pose> poses;
  std::string error;
  FocalAttitudeLaw law;
  const std::vector<Eigen::Vector3d> bad = {Eigen::Vector3d(0, 0, 150),
                                            Eigen::Vector3d(NAN, 0, 150)};
  ExpectError(PosesWithAttitudeLaw(bad, law, &poses, &error), error, "positions[1]");
  ExpectError(PosesWithIdentityAttitude(bad, &poses, &error), error, "positions[1]");
  const std::vector<Eigen::Vector3d> at_centre = {Eigen::Vector3d(0, 0, 150), kFocalCentre_m};
  ExpectError(PosesWithAttitudeLaw(at_centre, law, &poses, &error), error, "positions[1]");
  for (double fraction : {static_cast<double>(NAN), -0.1, 1.5}) {
    law.tilt_fraction = fraction;
    ExpectError(PosesWithAttitudeLaw({Eigen::Vector3d(0, 0, 150)}, law, &poses, &error), error,
                "law.tilt_fraction must be in [0, 1]");
  }
  EXPECT_TRUE(poses.empty());
}

// ---- Pose CSV ----

std::string WriteTempFile(const std::string& name, const std::string& content) {
  const size_t dot = name.rfind('.');
  const std::string path = dot == std::string::npos
                               ? test::TempPath(name)
                               : test::TempPath(name.substr(0, dot), name.substr(dot));
  std::ofstream out(path, std::ios::binary);
  out << content;
  return path;
}

TEST(ReadPosesCsv, RollPitchYawAndTimes) {
  const std::string path = WriteTempFile("trajectory_test_rpy.csv",
                                         "time_s, yaw_deg,x_m,y_m,z_m,roll_deg,pitch_deg\n"
                                         "0.5, 30, 1.5, -2, 150, 1, 2\n"
                                         "1.0,-10,0,0,140,0,-3.5\n");
  std::vector<Pose> poses;
  std::vector<double> times;
  std::string error;
  ASSERT_TRUE(ReadPosesCsv(path, &poses, &times, &error)) << error;
  ASSERT_EQ(poses.size(), 2u);
  ASSERT_EQ(times.size(), 2u);
  EXPECT_EQ(times[0], 0.5);
  EXPECT_EQ(times[1], 1.0);
  EXPECT_EQ(poses[0].position_m, Eigen::Vector3d(1.5, -2.0, 150.0));
  EXPECT_EQ(poses[1].position_m, Eigen::Vector3d(0.0, 0.0, 140.0));
  EXPECT_LT((poses[0].rotation - RotationFromRpyDeg(1.0, 2.0, 30.0)).norm(), kRotationTolerance);
  EXPECT_LT((poses[1].rotation - RotationFromRpyDeg(0.0, -3.5, -10.0)).norm(), kRotationTolerance);
}

TEST(ReadPosesCsv, QuaternionWithDatasetColumnsAndComments) {
  const double c = std::cos(15.0 * kDegToRad), s = std::sin(15.0 * kDegToRad);
  const std::string row1 =
      "2," + std::to_string(c) + ",10,0,20,0,150," + std::to_string(s) + ",159.17\r\n";
  const std::string path = WriteTempFile("trajectory_test_quaternion.csv",
                                         "# recorded on the measured circle\r\n"
                                         "\r\n"
                                         "planned_yaw_deg,qw,x_m,qx,y_m,qy,z_m,qz,T1_kN\r\n"
                                         "   # a comment between rows\r\n" +
                                             row1 +
                                             "\r\n"
                                             "b,1,0,0,0,0,140,0,not-a-number-but-unused\r\n");
  std::vector<Pose> poses;
  std::vector<double> times = {42.0};
  std::string error;
  ASSERT_TRUE(ReadPosesCsv(path, &poses, &times, &error)) << error;
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_TRUE(times.empty());  // no time_s column
  EXPECT_EQ(poses[0].position_m, Eigen::Vector3d(10.0, 20.0, 150.0));
  const Eigen::Matrix3d rz30 =
      Eigen::AngleAxisd(30.0 * kDegToRad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  constexpr double kSixDigitTolerance = 1e-5;  // std::to_string keeps six decimals
  EXPECT_LT((poses[0].rotation - rz30).norm(), kSixDigitTolerance);
  EXPECT_LT((poses[1].rotation - Eigen::Matrix3d::Identity()).norm(), kRotationTolerance);
  ASSERT_TRUE(ReadPosesCsv(path, &poses, nullptr, &error)) << error;  // times optional
}

TEST(ReadPosesCsv, NoAttitudeColumnsMeansIdentity) {
  const std::string path = WriteTempFile("trajectory_test_identity.csv", "z_m,y_m,x_m\n150,2,1\n");
  std::vector<Pose> poses;
  std::string error;
  ASSERT_TRUE(ReadPosesCsv(path, &poses, nullptr, &error)) << error;
  ASSERT_EQ(poses.size(), 1u);
  EXPECT_EQ(poses[0].position_m, Eigen::Vector3d(1.0, 2.0, 150.0));
  EXPECT_EQ(poses[0].rotation, Eigen::Matrix3d::Identity());
}

// Reads a bad file; expects failure, untouched outputs and a message containing `expected`.
void ExpectCsvError(const std::string& name, const std::string& content,
                    const std::string& expected) {
  const std::string path = WriteTempFile(name, content);
  std::vector<Pose> poses(3);
  std::vector<double> times(3);
  std::string error;
  EXPECT_FALSE(ReadPosesCsv(path, &poses, &times, &error)) << name;
  EXPECT_NE(error.find(path + expected), std::string::npos) << name << ": " << error;
  EXPECT_EQ(poses.size(), 3u) << name;
  EXPECT_EQ(times.size(), 3u) << name;
}

TEST(ReadPosesCsv, BadFilesReportFileLineAndColumn) {
  ExpectCsvError("trajectory_test_missing.csv", "x_m,y_m,time_s\n1,2,3\n",
                 ":1: missing column 'z_m'");
  ExpectCsvError("trajectory_test_text.csv", "x_m,y_m,z_m\n1,2,150\n# c\n1,abc,150\n",
                 ":4: column 'y_m': 'abc' is not a number");
  ExpectCsvError("trajectory_test_trailing.csv", "x_m,y_m,z_m\n1,2,150x\n",
                 ":2: column 'z_m': '150x' is not a number");
  ExpectCsvError("trajectory_test_nan.csv", "x_m,y_m,z_m\nnan,2,150\n",
                 ":2: column 'x_m': value is not finite");
  ExpectCsvError("trajectory_test_inf.csv", "x_m,y_m,z_m,time_s\n1,2,150,1e999\n",
                 ":2: column 'time_s': '1e999' is out of the range of a double");
  ExpectCsvError("trajectory_test_empty_field.csv", "x_m,y_m,z_m\n1,,150\n",
                 ":2: column 'y_m': missing value");
  // The same number rules and plausibility limits as a dataset (plausibility.h).
  ExpectCsvError("trajectory_test_hex.csv", "x_m,y_m,z_m\n0x10,2,150\n",
                 ":2: column 'x_m': '0x10' is not a decimal number (hexadecimal is not accepted)");
  ExpectCsvError("trajectory_test_below.csv", "x_m,y_m,z_m\n0,0,-50\n",
                 ":2: columns 'x_m,y_m,z_m': z = -50 m is below the reflector");
  ExpectCsvError("trajectory_test_angle.csv",
                 "x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n0,0,150,0,0,1e300\n",
                 ":2: column 'yaw_deg': 1e+300 deg is beyond the plausible +-360 deg");
  ExpectCsvError("trajectory_test_both.csv",
                 "x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,qw,qx,qy,qz\n1,2,3,0,0,0,1,0,0,0\n",
                 ":1: both roll/pitch/yaw and quaternion");
  ExpectCsvError("trajectory_test_partial_rpy.csv", "x_m,y_m,z_m,roll_deg,pitch_deg\n1,2,3,0,0\n",
                 ":1: missing column 'yaw_deg'");
  ExpectCsvError("trajectory_test_short.csv", "x_m,y_m,z_m\n1,2,150\n1,2\n",
                 ":3: expected 3 fields (as in the header), got 2");
  ExpectCsvError("trajectory_test_long.csv", "x_m,y_m,z_m\n1,2,150,\n",
                 ":2: expected 3 fields (as in the header), got 4");
  ExpectCsvError("trajectory_test_quaternion_norm.csv", "x_m,y_m,z_m,qw,qx,qy,qz\n1,2,3,2,0,0,0\n",
                 ":2: columns 'qw,qx,qy,qz': quaternion (w,x,y,z) must be unit");
  ExpectCsvError("trajectory_test_duplicate.csv", "x_m,y_m,z_m,x_m\n1,2,3,4\n",
                 ":1: duplicate column 'x_m'");
  ExpectCsvError("trajectory_test_duplicate_unused.csv", "x_m,y_m,z_m,T1_kN,T1_kN\n1,2,3,4,5\n",
                 ":1: duplicate column 'T1_kN'");
  ExpectCsvError("trajectory_test_empty_name.csv", "x_m,y_m,z_m,\n1,2,3,\n",
                 ":1: column 4: empty column name");
  ExpectCsvError("trajectory_test_empty.csv", "", ": no header line");
  ExpectCsvError("trajectory_test_comments_only.csv", "# nothing\n\n", ": no header line");
  ExpectCsvError("trajectory_test_header_only.csv", "x_m,y_m,z_m\n# no rows\n", ": no data rows");
  ExpectCsvError("trajectory_test_does_not_exist_dir/poses.csv", "",
                 ": cannot open: No such file or directory");
}

// A misspelt attitude column must not silently give R = I: every column is either used,
// one of a dataset's (not used), or an error naming the file, line, column and name.
TEST(ReadPosesCsv, UnknownColumnIsAnErrorListingTheAcceptedNames) {
  const std::string path =
      WriteTempFile("trajectory_test_unknown.csv", "x_m,y_m,z_m,roll,pitch,yaw\n0,0,150,1,2,3\n");
  std::vector<Pose> poses;
  std::string error;
  EXPECT_FALSE(ReadPosesCsv(path, &poses, nullptr, &error));
  EXPECT_TRUE(poses.empty());
  EXPECT_NE(error.find(path + ":1: column 4 'roll': unknown column name"), std::string::npos)
      << error;
  for (const char* accepted : {"x_m", "roll_deg", "pitch_deg", "yaw_deg", "qw", "qz", "time_s",
                               "planned_roll_deg", "T1_kN", "s0_1_m"}) {
    EXPECT_NE(error.find(accepted), std::string::npos) << accepted << ": " << error;
  }
  // After comment lines the header's own line is named.
  ExpectCsvError("trajectory_test_unknown_after_comment.csv",
                 "# exported\nx_m,y_m,z_m,Roll_deg\n0,0,150,1\n",
                 ":2: column 4 'Roll_deg': unknown column name (accepted: x_m, y_m, z_m, ");
}

// A spreadsheet export with ';' or tabs is not one long unknown column name.
TEST(ReadPosesCsv, SemicolonOrTabSeparatorIsNamed) {
  ExpectCsvError("trajectory_test_semicolon.csv", "# exported\nx_m;y_m;z_m\n0;0;150\n",
                 ":2: the header is separated by ';': fields must be separated by commas");
  ExpectCsvError("trajectory_test_tab.csv", "x_m\ty_m\tz_m\n0\t0\t150\n",
                 ":1: the header is separated by tabs: fields must be separated by commas");
}

// A whole dataset (every column it may have) reads as a pose file.
TEST(ReadPosesCsv, DatasetColumnsAreAccepted) {
  std::string header =
      "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,planned_roll_deg,"
      "planned_pitch_deg,planned_yaw_deg";
  std::string row = "0,1,2,150,0,0,10,0,0,9";
  for (int i = 1; i <= 6; ++i) {
    header += ",T" + std::to_string(i) + "_kN";
    row += ",150";
  }
  for (int i = 1; i <= 6; ++i) {
    header += ",s0_" + std::to_string(i) + "_m";
    row += ",250";
  }
  const std::string path = WriteTempFile("trajectory_test_dataset.csv", header + "\n" + row + "\n");
  std::vector<Pose> poses;
  std::string error;
  ASSERT_TRUE(ReadPosesCsv(path, &poses, nullptr, &error)) << error;
  ASSERT_EQ(poses.size(), 1u);
  EXPECT_LT((poses[0].rotation - RotationFromRpyDeg(0.0, 0.0, 10.0)).norm(), kRotationTolerance);
}

}  // namespace
}  // namespace fastcal
