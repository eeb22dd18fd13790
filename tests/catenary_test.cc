// Tests of the elastic catenary (catenary.h): round trips, analytic Jacobian against
// central differences, Jet and double paths, the stiff and weightless limits, and the
// failure statuses.
#include "fastcal/catenary.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace fastcal {
namespace {

constexpr double kEaN = 2.4656e7;
constexpr double kWNPerM = 11.718 * -9.8;
constexpr uint64_t kSeed = 20261121;
// Chords met in the FAST workspace (cabin within ~110 m of the axis, 130-175 m high).
constexpr double kMinSpanM = 180.0, kMaxSpanM = 420.0;
constexpr double kMinRiseM = 90.0, kMaxRiseM = 145.0;
// Round-trip tolerances: end point to 1e-9 of the chord, forces to 1e-8 relative.
constexpr double kEndPointRelTol = 1e-9;
constexpr double kForceRelTol = 1e-8;

struct Chord {
  double span_m, rise_m, s0_m;
};

std::vector<Chord> RandomChords(int n, double s0_low, double s0_high) {
  std::mt19937_64 rng(kSeed);
  std::uniform_real_distribution<double> span(kMinSpanM, kMaxSpanM), rise(kMinRiseM, kMaxRiseM),
      frac(s0_low, s0_high);
  std::vector<Chord> chords;
  for (int i = 0; i < n; ++i) {
    Chord c;
    c.span_m = span(rng);
    c.rise_m = rise(rng);
    c.s0_m = frac(rng) * std::hypot(c.span_m, c.rise_m);
    chords.push_back(c);
  }
  return chords;
}

TEST(CatenaryTest, ColdSolveConvergesOverWorkspaceLengthRange) {
  const CatenarySolverOptions options;
  for (const Chord& c : RandomChords(2000, 0.95, 1.05)) {
    CatenaryForces f;
    int iterations = 0;
    ASSERT_EQ(SolveCatenaryForcesDouble(c.span_m, c.rise_m, c.s0_m, kEaN, kWNPerM, options, nullptr,
                                        &f, &iterations),
              CatenaryStatus::kOk)
        << "span " << c.span_m << " rise " << c.rise_m << " s0/k "
        << c.s0_m / std::hypot(c.span_m, c.rise_m);
    EXPECT_GT(f.fl_n, 0.0);
    const CatenaryEnd<double> e = CatenaryEndpoint(f.fl_n, f.fz_n, c.s0_m, kEaN, kWNPerM);
    const double k = std::hypot(c.span_m, c.rise_m);
    EXPECT_NEAR(e.span_m, c.span_m, kEndPointRelTol * k);
    EXPECT_NEAR(e.rise_m, c.rise_m, kEndPointRelTol * k);
  }
}

// A lone fixed-length solve of chord c (its span and s0) with the given rise and load.
CatenaryStatus SolveChord(const Chord& c, double rise_m, double w_n_per_m,
                          const CatenaryForces* guess, CatenaryForces* forces, int* iterations) {
  return SolveCatenaryForcesDouble(c.span_m, rise_m, c.s0_m, kEaN, w_n_per_m,
                                   CatenarySolverOptions(), guess, forces, iterations);
}

// A cold solve's start, computed for the whole batch in lockstep, is CatenaryInitialGuess:
// a solve started there explicitly takes the same steps to the same bits.
TEST(CatenaryTest, ColdStartIsCatenaryInitialGuess) {
  for (const Chord& c : RandomChords(2000, 0.95, 1.05)) {
    CatenaryForces cold, warm;
    int it_cold = 0, it_warm = 0;
    ASSERT_EQ(SolveChord(c, c.rise_m, kWNPerM, nullptr, &cold, &it_cold), CatenaryStatus::kOk);
    const CatenaryForces start = CatenaryInitialGuess(c.span_m, c.rise_m, c.s0_m, kEaN, kWNPerM);
    ASSERT_EQ(SolveChord(c, c.rise_m, kWNPerM, &start, &warm, &it_warm), CatenaryStatus::kOk);
    EXPECT_EQ(cold.fl_n, warm.fl_n);
    EXPECT_EQ(cold.fz_n, warm.fz_n);
    EXPECT_EQ(it_cold, it_warm);
  }
}

// A load pointing up (w > 0) is the mirror image in z of gravity: rise, Fz and w change
// sign. Both cold starts respect that, so both inverse problems give the mirrored
// solution in about the same number of steps.
TEST(CatenaryTest, UpwardLoadMirrorsGravity) {
  constexpr double kMirrorRelTol = 1e-9;
  constexpr int kMaxExtraIterations = 1;
  const CatenarySolverOptions options;
  for (const Chord& c : RandomChords(500, 0.97, 1.03)) {
    CatenaryForces down, up;
    int it_down = 0, it_up = 0;
    ASSERT_EQ(SolveChord(c, c.rise_m, kWNPerM, nullptr, &down, &it_down), CatenaryStatus::kOk);
    ASSERT_EQ(SolveChord(c, -c.rise_m, -kWNPerM, nullptr, &up, &it_up), CatenaryStatus::kOk);
    const double t = std::hypot(down.fl_n, down.fz_n);
    EXPECT_NEAR(up.fl_n, down.fl_n, kMirrorRelTol * t);
    EXPECT_NEAR(up.fz_n, -down.fz_n, kMirrorRelTol * t);
    EXPECT_LE(std::abs(it_up - it_down), kMaxExtraIterations);
    CatenaryCurvePoint p_down, p_up;
    ASSERT_EQ(SolveCatenaryLengthDouble(c.span_m, c.rise_m, down.fl_n, kEaN, kWNPerM, options,
                                        nullptr, &p_down, &it_down),
              CatenaryStatus::kOk);
    ASSERT_EQ(SolveCatenaryLengthDouble(c.span_m, -c.rise_m, down.fl_n, kEaN, -kWNPerM, options,
                                        nullptr, &p_up, &it_up),
              CatenaryStatus::kOk);
    EXPECT_NEAR(p_up.s0_m, p_down.s0_m, kMirrorRelTol * p_down.s0_m);
    EXPECT_NEAR(p_up.fz_n, -p_down.fz_n, kMirrorRelTol * t);
    EXPECT_LE(std::abs(it_up - it_down), kMaxExtraIterations);
  }
}

// The cold start is the parabolic elastic catenary: close to the solution over the
// workspace's lengths (measured max 0.48% within 1% of the chord length, where AAS's
// secant lengths are, and 3.3% over 0.95k..1.05k), so Newton needs at most three
// evaluations at the statics' tolerance near the chord length.
TEST(CatenaryTest, InitialGuessIsCloseOverWorkspaceLengthRange) {
  constexpr double kGuessRelTolNearChord = 1e-2;  // s0 within 1% of the chord length
  constexpr double kGuessRelTolWide = 5e-2;       // s0 anywhere in [0.95 k, 1.05 k]
  constexpr double kStaticsCatenaryTol = 1e-10;
  constexpr int kMaxIterationsNearChord = 3;
  CatenarySolverOptions options;
  options.relative_tolerance = kStaticsCatenaryTol;
  for (const Chord& c : RandomChords(2000, 0.95, 1.05)) {
    const double k = std::hypot(c.span_m, c.rise_m);
    const bool near_chord = std::abs(c.s0_m / k - 1.0) <= 0.01;
    CatenaryForces f;
    int iterations = 0;
    ASSERT_EQ(SolveCatenaryForcesDouble(c.span_m, c.rise_m, c.s0_m, kEaN, kWNPerM, options, nullptr,
                                        &f, &iterations),
              CatenaryStatus::kOk);
    const CatenaryForces g = CatenaryInitialGuess(c.span_m, c.rise_m, c.s0_m, kEaN, kWNPerM);
    const double t0 = std::hypot(f.fl_n, f.fz_n);
    const double error = std::hypot(g.fl_n - f.fl_n, g.fz_n - f.fz_n) / t0;
    EXPECT_LT(error, near_chord ? kGuessRelTolNearChord : kGuessRelTolWide)
        << "span " << c.span_m << " rise " << c.rise_m << " s0/k " << c.s0_m / k;
    if (near_chord) {
      EXPECT_LE(iterations, kMaxIterationsNearChord) << "s0/k " << c.s0_m / k;
    }
  }
}

// ParabolicCatenaryModel's point at H = Fl meets the relation it is defined by
// (catenary.h: s0^2 (1 + c H)^2 - k^2 = b / H^2, c = k/(L EA), b = w^2 L^4 / 12) and the
// inextensible catenary's Fz, computed here with std::tanh; with the chord given it is
// the same model; with an absurd EA (L EA lambda_h beyond double's range, which a merged
// division of its constants would meet) it is still the inextensible limit, not NaN.
TEST(CatenaryTest, ParabolicModelMeetsItsRelation) {
  constexpr double kRelationRelTol = 1e-13;  // rounding of a few operations
  constexpr double kCothRelTol = 1e-6;       // StartCoth's series (catenary.h)
  constexpr double kMinFlN = 5e4, kMaxFlN = 6e5;
  std::mt19937_64 rng(kSeed);
  std::uniform_real_distribution<double> fl_dist(kMinFlN, kMaxFlN);
  for (const Chord& c : RandomChords(500, 1.0, 1.0)) {
    const double k = std::hypot(c.span_m, c.rise_m), h = fl_dist(rng);
    for (const double ea_n : {kEaN, 1e306}) {  // 1e306: L EA lambda_h overflows
      const ParabolicCatenaryModel model(c.span_m, c.rise_m, ea_n, kWNPerM);
      const CatenaryCurvePoint p = model.AtHorizontalForce(h);
      const double cc = k / (c.span_m * ea_n);
      const double b = kWNPerM * kWNPerM * std::pow(c.span_m, 4) / 12.0;
      const double lhs = p.s0_m * p.s0_m * (1.0 + cc * h) * (1.0 + cc * h) - k * k;
      EXPECT_NEAR(lhs, b / (h * h), kRelationRelTol * k * k) << "EA " << ea_n << " H " << h;
      const double lambda = std::abs(kWNPerM) * c.span_m / (2.0 * h);
      const double coth_term = 0.5 * std::abs(kWNPerM) * c.rise_m / std::tanh(lambda);
      EXPECT_NEAR(p.fz_n, -0.5 * kWNPerM * p.s0_m - coth_term, kCothRelTol * coth_term);
      const CatenaryCurvePoint q =
          ParabolicCatenaryModel(c.span_m, c.rise_m, k, ea_n, kWNPerM).AtHorizontalForce(h);
      EXPECT_NEAR(q.s0_m, p.s0_m, kRelationRelTol * p.s0_m);
      EXPECT_NEAR(q.fz_n, p.fz_n, kRelationRelTol * std::abs(p.fz_n));
    }
  }
}

// Asinh (scalar.h) takes the log form above kAsinhLogFormMin and glibc's below: both
// sides of the switch, signs and large arguments agree with std::asinh to a few ulp.
TEST(CatenaryTest, AsinhMatchesStdAsinhOnBothSidesOfItsSwitch) {
  constexpr double kAsinhRelTol = 1e-14;
  std::mt19937_64 rng(kSeed);
  std::uniform_real_distribution<double> log10_x(-12.0, 200.0);
  std::vector<double> xs = {
      0.0, kAsinhLogFormMin, std::nextafter(kAsinhLogFormMin, 0.0), 0.1, 1.0, 1e150, 1e300};
  for (int i = 0; i < 5000; ++i) xs.push_back(std::pow(10.0, log10_x(rng) / 10.0 - 2.0));
  for (double x : xs) {
    for (double v : {x, -x}) {
      const double expected = std::asinh(v);
      EXPECT_NEAR(Asinh(v), expected, kAsinhRelTol * std::abs(expected)) << v;
    }
  }
}

// The double end point takes eq. 14's bracket D = asinh(Fz1/Fl) - asinh(Fz/Fl) as the log
// of a ratio when Fz and Fz1 share a sign and |D| >= 1/16, else through Asinh (as a Jet
// always does). Both agree with the bracket evaluated directly in long double, for cables
// pulled down, up and with their low point inside, and for D down to ~1e-6.
TEST(CatenaryTest, EndPointAngleDifferenceMatchesLongDouble) {
  constexpr double kSpanRelTol = 1e-13;
  std::mt19937_64 rng(kSeed);
  std::uniform_real_distribution<double> log10_fl(3.0, 6.0), fz_over_fl(-3.0, 3.0), s0(10.0, 500.0),
      log10_w(0.0, 2.5);
  constexpr double kEa = 2.4656e7;
  int ratio_form = 0, asinh_form = 0;
  for (int i = 0; i < 20000; ++i) {
    const double fl = std::pow(10.0, log10_fl(rng)), fz = fz_over_fl(rng) * fl;
    const double s = s0(rng), w = -std::pow(10.0, log10_w(rng));
    const double fz1 = fz + w * s;
    // The reference takes Fz1 = Fz + w s0 without the rounding of the double sum, which
    // the end point's x = w s0 Q / Fl^2 avoids too.
    const long double fz1_exact = static_cast<long double>(fz) + static_cast<long double>(w) * s;
    const long double d =
        std::asinh(fz1_exact / fl) - std::asinh(static_cast<long double>(fz) / fl);
    const long double span = static_cast<long double>(fl) * s / kEa + fl / w * d;
    const CatenaryEnd<double> e = CatenaryEndpoint(fl, fz, s, kEa, w);
    EXPECT_NEAR(e.span_m, static_cast<double>(span), kSpanRelTol * std::abs(e.span_m))
        << "fl " << fl << " fz " << fz << " s0 " << s << " w " << w;
    const bool same_sign = (fz >= 0.0) == (fz1 >= 0.0);
    (same_sign && std::abs(d) >= 1.0 / 16 ? ratio_form : asinh_form)++;
  }
  // Both forms were exercised.
  EXPECT_GT(ratio_form, 1000);
  EXPECT_GT(asinh_form, 1000);
}

// The batch solvers take exactly the iterations of one-at-a-time solves, so results,
// iteration counts and statuses are identical, bit for bit, also with failing problems
// (invalid input, vertical chord) and far-off starts (limited, backtracked steps) in the
// batch.
TEST(CatenaryTest, BatchSolvesEqualSingleSolvesExactly) {
  const CatenarySolverOptions options;
  const std::vector<Chord> chords = RandomChords(kMaxCatenaryBatch - 3, 0.95, 1.05);
  std::vector<CatenaryProblem> problems;
  std::vector<CatenaryLengthProblem> length_problems;
  for (const Chord& c : chords) {
    problems.push_back({c.span_m, c.rise_m, c.s0_m, kEaN, kWNPerM, nullptr});
    length_problems.push_back({c.span_m, c.rise_m, 1e5, kEaN, kWNPerM, nullptr});
  }
  problems.push_back({250.0, 120.0, -1.0, kEaN, kWNPerM, nullptr});  // invalid s0
  problems.push_back({0.0, 120.0, 130.0, kEaN, kWNPerM, nullptr});   // vertical chord
  // Far-off starts: Newton needs limited and backtracked steps (8 and 12 iterations).
  const CatenaryForces bad_forces{1.0, -1e6};
  const CatenaryCurvePoint bad_point{5e5, 0.5 * std::hypot(250.0, 120.0)};
  problems.push_back({250.0, 120.0, 1.05 * std::hypot(250.0, 120.0), kEaN, kWNPerM, &bad_forces});
  length_problems.push_back({250.0, 120.0, -5.0, kEaN, kWNPerM, nullptr});  // invalid Fl
  length_problems.push_back({0.0, 120.0, 1e5, kEaN, kWNPerM, nullptr});     // vertical chord
  length_problems.push_back({250.0, 120.0, 5e4, kEaN, kWNPerM, &bad_point});
  const int n = static_cast<int>(problems.size());
  ASSERT_EQ(n, kMaxCatenaryBatch);

  std::vector<CatenaryForces> forces(n);
  std::vector<CatenaryStatus> statuses(n);
  std::vector<int> iterations(n);
  SolveCatenaryForcesBatch(n, problems.data(), options, forces.data(), statuses.data(),
                           iterations.data());
  std::vector<CatenaryCurvePoint> points(n);
  std::vector<CatenaryStatus> length_statuses(n);
  std::vector<int> length_iterations(n);
  SolveCatenaryLengthBatch(n, length_problems.data(), options, points.data(),
                           length_statuses.data(), length_iterations.data());
  int ok = 0;
  for (int j = 0; j < n; ++j) {
    const CatenaryProblem& c = problems[j];
    CatenaryForces f;
    int it = -1;
    EXPECT_EQ(SolveCatenaryForcesDouble(c.span_m, c.rise_m, c.s0_m, c.ea_n, c.w_n_per_m, options,
                                        c.guess, &f, &it),
              statuses[j])
        << j;
    EXPECT_EQ(it, iterations[j]) << j;
    if (statuses[j] == CatenaryStatus::kOk) {
      ++ok;
      EXPECT_EQ(f.fl_n, forces[j].fl_n) << j;
      EXPECT_EQ(f.fz_n, forces[j].fz_n) << j;
    }
    const CatenaryLengthProblem& l = length_problems[j];
    CatenaryCurvePoint point;
    EXPECT_EQ(SolveCatenaryLengthDouble(l.span_m, l.rise_m, l.fl_n, l.ea_n, l.w_n_per_m, options,
                                        l.guess, &point, &it),
              length_statuses[j])
        << j;
    EXPECT_EQ(it, length_iterations[j]) << j;
    if (length_statuses[j] == CatenaryStatus::kOk) {
      ++ok;
      EXPECT_EQ(point.fz_n, points[j].fz_n) << j;
      EXPECT_EQ(point.s0_m, points[j].s0_m) << j;
    }
  }
  // The batch must hold the failures it was given and real solutions besides.
  EXPECT_EQ(statuses[n - 3], CatenaryStatus::kInvalidInput);
  EXPECT_EQ(statuses[n - 2], CatenaryStatus::kVerticalChord);
  EXPECT_EQ(length_statuses[n - 3], CatenaryStatus::kInvalidInput);
  EXPECT_EQ(length_statuses[n - 2], CatenaryStatus::kVerticalChord);
  EXPECT_GE(ok, 2 * (n - 2));
  EXPECT_GE(iterations[n - 1], 5);
  EXPECT_GE(length_iterations[n - 1], 5);
}

TEST(CatenaryTest, ForwardThenInverseRecoversForces) {
  std::mt19937_64 rng(kSeed + 1);
  std::uniform_real_distribution<double> fl(2e4, 4e5), slope(-1.2, -0.1), len(250.0, 450.0);
  const CatenarySolverOptions options;
  for (int i = 0; i < 500; ++i) {
    const double fl_n = fl(rng), fz_n = slope(rng) * fl_n, s0_m = len(rng);
    const CatenaryEnd<double> e = CatenaryEndpoint(fl_n, fz_n, s0_m, kEaN, kWNPerM);
    CatenaryForces f;
    int it = 0;
    ASSERT_EQ(SolveCatenaryForcesDouble(e.span_m, e.rise_m, s0_m, kEaN, kWNPerM, options, nullptr,
                                        &f, &it),
              CatenaryStatus::kOk);
    EXPECT_NEAR(f.fl_n, fl_n, kForceRelTol * fl_n);
    EXPECT_NEAR(f.fz_n, fz_n, kForceRelTol * fl_n);
    // The other inverse problem: the length that yields fl.
    CatenaryCurvePoint p;
    ASSERT_EQ(SolveCatenaryLengthDouble(e.span_m, e.rise_m, fl_n, kEaN, kWNPerM, options, nullptr,
                                        &p, &it),
              CatenaryStatus::kOk);
    EXPECT_NEAR(p.s0_m, s0_m, kForceRelTol * s0_m);
    EXPECT_NEAR(p.fz_n, fz_n, kForceRelTol * fl_n);
  }
}

TEST(CatenaryTest, AnalyticJacobianMatchesCentralDifferences) {
  // Relative step and agreement for central differences of smooth functions.
  constexpr double kRelStep = 1e-6;
  constexpr double kRelTol = 1e-6;
  std::mt19937_64 rng(kSeed + 2);
  std::uniform_real_distribution<double> fl(1e4, 5e5), slope(-1.5, 0.3), len(100.0, 450.0);
  for (int i = 0; i < 200; ++i) {
    const double x[3] = {fl(rng), 0.0, len(rng)};
    double u[3] = {x[0], slope(rng) * x[0], x[2]};
    const CatenaryEnd<double> e = CatenaryEndpoint(u[0], u[1], u[2], kEaN, kWNPerM);
    for (int j = 0; j < 3; ++j) {
      const double h = kRelStep * std::max(std::abs(u[j]), 1.0);
      double up[3] = {u[0], u[1], u[2]}, dn[3] = {u[0], u[1], u[2]};
      up[j] += h;
      dn[j] -= h;
      const CatenaryEnd<double> a = CatenaryEndpoint(up[0], up[1], up[2], kEaN, kWNPerM);
      const CatenaryEnd<double> b = CatenaryEndpoint(dn[0], dn[1], dn[2], kEaN, kWNPerM);
      const double dspan = (a.span_m - b.span_m) / (2 * h);
      const double drise = (a.rise_m - b.rise_m) / (2 * h);
      const double scale_span =
          std::abs(e.dspan[0]) + std::abs(e.dspan[1]) * u[0] / u[2] + std::abs(e.dspan[j]);
      const double scale_rise = std::abs(e.drise[j]) + std::abs(e.drise[1]);
      EXPECT_NEAR(e.dspan[j], dspan, kRelTol * scale_span) << "dspan/du" << j;
      EXPECT_NEAR(e.drise[j], drise, kRelTol * scale_rise) << "drise/du" << j;
    }
  }
}

TEST(CatenaryTest, JetAndDoubleAgree) {
  using Jet = ceres::Jet<double, 3>;
  constexpr double kTol = 1e-12;
  const double fl = 1.2e5, fz = -6e4, s0 = 321.0;
  const CatenaryEnd<double> d = CatenaryEndpoint(fl, fz, s0, kEaN, kWNPerM);
  const CatenaryEnd<Jet> j =
      CatenaryEndpoint(Jet(fl, 0), Jet(fz, 1), Jet(s0, 2), Jet(kEaN), Jet(kWNPerM));
  EXPECT_NEAR(j.span_m.a, d.span_m, kTol * s0);
  EXPECT_NEAR(j.rise_m.a, d.rise_m, kTol * s0);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(j.span_m.v[k], d.dspan[k], kTol * (std::abs(d.dspan[k]) + 1e-3));
    EXPECT_NEAR(j.rise_m.v[k], d.drise[k], kTol * (std::abs(d.drise[k]) + 1e-3));
  }
}

TEST(CatenaryTest, JetInverseSolveCarriesImplicitDerivatives) {
  // d(Fl, Fz)/d(span, rise, s0, EA, w) from the Jet path against central differences of
  // the double solve.
  using Jet = ceres::Jet<double, 5>;
  constexpr double kRelTol = 1e-5;
  const double in[5] = {290.0, 130.0, 318.0, kEaN, kWNPerM};
  const CatenarySolverOptions options;
  Jet fl, fz;
  ASSERT_EQ(SolveCatenaryForces(Jet(in[0], 0), Jet(in[1], 1), Jet(in[2], 2), Jet(in[3], 3),
                                Jet(in[4], 4), options, nullptr, &fl, &fz),
            CatenaryStatus::kOk);
  for (int k = 0; k < 5; ++k) {
    const double h = 1e-6 * std::abs(in[k]);
    double up[5], dn[5];
    std::copy(in, in + 5, up);
    std::copy(in, in + 5, dn);
    up[k] += h;
    dn[k] -= h;
    double fl_up = 0, fz_up = 0, fl_dn = 0, fz_dn = 0;
    ASSERT_EQ(
        SolveCatenaryForces(up[0], up[1], up[2], up[3], up[4], options, nullptr, &fl_up, &fz_up),
        CatenaryStatus::kOk);
    ASSERT_EQ(
        SolveCatenaryForces(dn[0], dn[1], dn[2], dn[3], dn[4], options, nullptr, &fl_dn, &fz_dn),
        CatenaryStatus::kOk);
    const double dfl = (fl_up - fl_dn) / (2 * h), dfz = (fz_up - fz_dn) / (2 * h);
    EXPECT_NEAR(fl.v[k], dfl, kRelTol * (std::abs(dfl) + std::abs(fl.a) / std::abs(in[k])))
        << "input " << k;
    EXPECT_NEAR(fz.v[k], dfz, kRelTol * (std::abs(dfz) + std::abs(fl.a) / std::abs(in[k])))
        << "input " << k;
  }
}

TEST(CatenaryTest, VeryStiffCableTendsToInextensibleCatenary) {
  // Inextensible catenary identity: s0^2 = Z^2 + (2H/|w| sinh(|w| L / (2H)))^2.
  constexpr double kStiffEaN = 1e16;
  constexpr double kRelTol = 1e-7;
  const CatenarySolverOptions options;
  for (const Chord& c : RandomChords(50, 1.001, 1.05)) {
    CatenaryForces f;
    int it = 0;
    ASSERT_EQ(SolveCatenaryForcesDouble(c.span_m, c.rise_m, c.s0_m, kStiffEaN, kWNPerM, options,
                                        nullptr, &f, &it),
              CatenaryStatus::kOk);
    const double h = f.fl_n, w = std::abs(kWNPerM);
    const double arc =
        std::sqrt(c.rise_m * c.rise_m + std::pow(2 * h / w * std::sinh(w * c.span_m / (2 * h)), 2));
    EXPECT_NEAR(arc, c.s0_m, kRelTol * c.s0_m);
  }
}

TEST(CatenaryTest, WeightlessCableTendsToStraightElasticBar) {
  // T = EA (k/s0 - 1), along the chord, when the density -> 0.
  constexpr double kTinyWNPerM = -1e-9;
  constexpr double kRelTol = 1e-7;
  const CatenarySolverOptions options;
  for (const Chord& c : RandomChords(50, 0.96, 0.999)) {
    CatenaryForces f;
    int it = 0;
    ASSERT_EQ(SolveCatenaryForcesDouble(c.span_m, c.rise_m, c.s0_m, kEaN, kTinyWNPerM, options,
                                        nullptr, &f, &it),
              CatenaryStatus::kOk);
    const double k = std::hypot(c.span_m, c.rise_m);
    const double tension = kEaN * (k / c.s0_m - 1.0);
    EXPECT_NEAR(std::hypot(f.fl_n, f.fz_n), tension, kRelTol * tension);
    EXPECT_NEAR(f.fz_n / f.fl_n, -c.rise_m / c.span_m, kRelTol);  // pulled along the chord
  }
}

TEST(CatenaryTest, ShapeEndsOnChordAndTensionMatchesEnds) {
  constexpr double kTol = 1e-9;
  const double fl = 1.3e5, fz = -7e4, s0 = 330.0;
  const CatenaryEnd<double> e = CatenaryEndpoint(fl, fz, s0, kEaN, kWNPerM);
  const std::vector<CatenaryPoint> shape = CatenaryShape(fl, fz, s0, kEaN, kWNPerM, 11);
  ASSERT_EQ(shape.size(), 11u);
  EXPECT_EQ(shape.front().span_m, 0.0);
  EXPECT_NEAR(shape.back().span_m, e.span_m, kTol * s0);
  EXPECT_NEAR(shape.back().rise_m, e.rise_m, kTol * s0);
  EXPECT_NEAR(shape.front().tension_n, std::hypot(fl, fz), kTol * fl);
  EXPECT_NEAR(shape.back().tension_n, CatenaryTension(fl, fz, s0, kWNPerM), kTol * fl);
  for (size_t i = 1; i < shape.size(); ++i) {
    // Fz < 0 at the bottom: the cable rises and its tension grows toward the top.
    EXPECT_GT(shape[i].rise_m, shape[i - 1].rise_m);
    EXPECT_GT(shape[i].tension_n, shape[i - 1].tension_n);
  }
}

TEST(CatenaryTest, BadInputGivesStatusNotNan) {
  const CatenarySolverOptions options;
  CatenaryForces f;
  int it = 0;
  EXPECT_EQ(SolveCatenaryForcesDouble(0.0, 150.0, 160.0, kEaN, kWNPerM, options, nullptr, &f, &it),
            CatenaryStatus::kVerticalChord);
  EXPECT_EQ(SolveCatenaryForcesDouble(NAN, 150.0, 160.0, kEaN, kWNPerM, options, nullptr, &f, &it),
            CatenaryStatus::kInvalidInput);
  EXPECT_EQ(SolveCatenaryForcesDouble(300.0, 150.0, -1.0, kEaN, kWNPerM, options, nullptr, &f, &it),
            CatenaryStatus::kInvalidInput);
  EXPECT_EQ(SolveCatenaryForcesDouble(300.0, 150.0, 330.0, 0.0, kWNPerM, options, nullptr, &f, &it),
            CatenaryStatus::kInvalidInput);
  CatenaryCurvePoint p;
  EXPECT_EQ(SolveCatenaryLengthDouble(300.0, 150.0, -5.0, kEaN, kWNPerM, options, nullptr, &p, &it),
            CatenaryStatus::kInvalidInput);
  CatenarySolverOptions one_step;
  one_step.max_iterations = 1;
  EXPECT_EQ(SolveCatenaryForcesDouble(300.0, 130.0, 0.95 * std::hypot(300.0, 130.0), kEaN, kWNPerM,
                                      one_step, nullptr, &f, &it),
            CatenaryStatus::kNotConverged);
}

}  // namespace
}  // namespace fastcal
