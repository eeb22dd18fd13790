// Tests of the chain of catenary segments (catenary_chain.h): it reduces to the uniform
// cable, its identities (added density over the whole cable, a point mass at s = 0), its
// partials against central differences, and its end point against an independent
// quadrature of the cable's differential equations, segment by segment.
#include "fastcal/catenary_chain.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace fastcal {
namespace {

constexpr double kGravity = -9.8;
constexpr double kEa = 2.4656e7;
constexpr double kRho = 11.718;
constexpr double kW = kRho * kGravity;
// FAST-like lower-end forces and length: Fl ~ 100 kN, Fz ~ -120 kN, s0 ~ 300 m.
constexpr double kFl = 1.0e5, kFz = -1.2e5, kS0 = 300.0;
// Relative agreement of two closed-form evaluations of the same cable (rounding of a
// few dozen operations on ~1e2 m).
constexpr double kRoundingTol = 1e-12;

CableAttachment Point(double at_m, double mass_kg) {
  return CableAttachment::PointMass(at_m, mass_kg);
}

CableAttachment Range(double from_m, double to_m, double density) {
  return CableAttachment::AddedDensity(from_m, to_m, density);
}

CatenaryEnd<double> Chain(const std::vector<CableAttachment>& attachments, double fl = kFl,
                          double fz = kFz, double s0 = kS0) {
  return CatenaryChainEndpoint(fl, fz, s0, kEa, kW, MakeCatenaryChain(attachments), kGravity);
}

TEST(CatenaryChainTest, WithoutAttachmentsIsTheUniformCableExactly) {
  const CatenaryEnd<double> u = CatenaryEndpoint(kFl, kFz, kS0, kEa, kW);
  const CatenaryEnd<double> c = Chain({});
  EXPECT_EQ(c.span_m, u.span_m);
  EXPECT_EQ(c.rise_m, u.rise_m);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(c.dspan[k], u.dspan[k]);
    EXPECT_EQ(c.drise[k], u.drise[k]);
  }
  EXPECT_EQ(c.upper_tension_n, u.upper_tension_n);
}

// Cutting a uniform cable into segments changes nothing: massless attachments.
TEST(CatenaryChainTest, MasslessAttachmentsCutTheCableWithoutChangingIt) {
  const CatenaryEnd<double> u = CatenaryEndpoint(kFl, kFz, kS0, kEa, kW);
  const CatenaryEnd<double> c = Chain({Point(3.0, 0.0), Range(10.0, 200.0, 0.0), Point(150, 0)});
  EXPECT_NEAR(c.span_m, u.span_m, kRoundingTol * kS0);
  EXPECT_NEAR(c.rise_m, u.rise_m, kRoundingTol * kS0);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(c.dspan[k], u.dspan[k], 1e-10 * std::abs(u.dspan[k]) + 1e-20) << k;
    EXPECT_NEAR(c.drise[k], u.drise[k], 1e-10 * std::abs(u.drise[k]) + 1e-20) << k;
  }
  EXPECT_NEAR(c.upper_tension_n, u.upper_tension_n, kRoundingTol * u.upper_tension_n);
}

// methods.md: extra weight over the whole length equals the uniform cable of the summed
// density. A range reaching beyond s0 covers the rest of the cable.
TEST(CatenaryChainTest, AddedDensityOverTheWholeCableIsAHeavierUniformCable) {
  const double added = 1.3;
  const CatenaryEnd<double> u = CatenaryEndpoint(kFl, kFz, kS0, kEa, (kRho + added) * kGravity);
  for (double to_m : {kS0 * 1.5, 1e4}) {
    const CatenaryEnd<double> c = Chain({Range(0.0, to_m, added)});
    EXPECT_NEAR(c.span_m, u.span_m, kRoundingTol * kS0);
    EXPECT_NEAR(c.rise_m, u.rise_m, kRoundingTol * kS0);
    EXPECT_NEAR(c.dspan[2], u.dspan[2], 1e-10 * std::abs(u.dspan[2]));
    EXPECT_NEAR(c.upper_tension_n, u.upper_tension_n, kRoundingTol * u.upper_tension_n);
  }
}

// methods.md: a point mass at s = 0 acts on the cable above it as that weight added to
// the lower end's vertical force; the lower-end tension (the sensor's) excludes it.
TEST(CatenaryChainTest, PointMassAtTheLowerEndShiftsTheLowerForce) {
  const double mass_kg = 480.0;
  const CatenaryEnd<double> u = CatenaryEndpoint(kFl, kFz + mass_kg * kGravity, kS0, kEa, kW);
  const CatenaryEnd<double> c = Chain({Point(0.0, mass_kg)});
  EXPECT_NEAR(c.span_m, u.span_m, kRoundingTol * kS0);
  EXPECT_NEAR(c.rise_m, u.rise_m, kRoundingTol * kS0);
  EXPECT_NEAR(c.upper_tension_n, u.upper_tension_n, kRoundingTol * u.upper_tension_n);
  EXPECT_DOUBLE_EQ(c.lower_tension_n, std::hypot(kFl, kFz));
}

// The end point by quadrature of the cable's equations, independent of the closed form:
//   dL/ds = Fl (1/EA + 1/T(s)),  dZ/ds = -V(s) (1/EA + 1/T(s)),  T = sqrt(Fl^2 + V^2),
// V(s) the vertical force on the cable at s from below, stepping at each point mass.
// Composite Simpson over each stretch between cuts, n_per_stretch intervals.
void Quadrature(const std::vector<CableAttachment>& attachments, double fl, double fz, double s0,
                double* span_m, double* rise_m) {
  std::vector<double> cuts = {0.0, s0};
  for (const CableAttachment& a : attachments) {
    for (double s : {a.StartM(), a.kind == AttachmentKind::kPointMass ? a.at_m : a.to_m}) {
      if (s > 0.0 && s < s0) cuts.push_back(s);
    }
  }
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  auto density = [&](double s) {  // weight per length at s (inside a stretch)
    double w = kW;
    for (const CableAttachment& a : attachments) {
      if (a.kind == AttachmentKind::kAddedDensity && s > a.from_m && s < a.to_m) {
        w += a.added_density_kg_per_m * kGravity;
      }
    }
    return w;
  };
  double v = fz;
  *span_m = *rise_m = 0.0;
  for (size_t k = 0; k + 1 < cuts.size(); ++k) {
    for (const CableAttachment& a : attachments) {
      if (a.kind == AttachmentKind::kPointMass && a.at_m == cuts[k]) v += a.mass_kg * kGravity;
    }
    const double length = cuts[k + 1] - cuts[k];
    if (length <= 0.0) continue;
    const double w = density(cuts[k] + 0.5 * length);
    constexpr int kIntervals = 2000;  // even
    const double h = length / kIntervals;
    double sl = 0.0, sz = 0.0;
    for (int j = 0; j <= kIntervals; ++j) {
      const double vj = v + w * j * h;
      const double f = 1.0 / kEa + 1.0 / std::hypot(fl, vj);
      const double weight = (j == 0 || j == kIntervals) ? 1.0 : (j % 2 ? 4.0 : 2.0);
      sl += weight * fl * f;
      sz += weight * -vj * f;
    }
    *span_m += sl * h / 3.0;
    *rise_m += sz * h / 3.0;
    v += w * length;
  }
}

TEST(CatenaryChainTest, EndPointMatchesAnIndependentQuadrature) {
  // Simpson's error with 2000 intervals per stretch on these smooth integrands: < 1e-9 m.
  constexpr double kQuadratureTolM = 1e-7;
  const std::vector<std::vector<CableAttachment>> cases = {
      {Point(4.0, 450.0)},
      {Point(2.5, 650.0), Range(0.0, 160.0, 1.6)},
      {Range(20.0, 140.0, 0.6), Point(140.0, 30.0), Point(4.0, 250.0), Range(100.0, 400.0, 0.4)},
  };
  for (const auto& attachments : cases) {
    double span = 0.0, rise = 0.0;
    Quadrature(attachments, kFl, kFz, kS0, &span, &rise);
    const CatenaryEnd<double> c = Chain(attachments);
    EXPECT_NEAR(c.span_m, span, kQuadratureTolM);
    EXPECT_NEAR(c.rise_m, rise, kQuadratureTolM);
  }
}

TEST(CatenaryChainTest, PartialsMatchCentralDifferences) {
  // Relative agreement of analytic partials with central differences of step h x scale:
  // truncation ~h^2 and rounding ~1e-16 / h on these smooth functions.
  constexpr double kStep = 1e-6;
  constexpr double kTol = 1e-6;
  std::mt19937_64 rng(20261124);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const double fl = 5e4 + 2e5 * u01(rng), fz = -2e5 + 2.5e5 * u01(rng);
    const double s0 = 200.0 + 150.0 * u01(rng);
    const std::vector<CableAttachment> attachments = {
        Point(6.0 * u01(rng), 650.0 * u01(rng)),
        Range(0.0, 120.0 + 80.0 * u01(rng), 1.6 * u01(rng)),
        Point(50.0 + 100.0 * u01(rng), 100.0 * u01(rng))};
    const CatenaryEnd<double> c = Chain(attachments, fl, fz, s0);
    const double x[3] = {fl, fz, s0};
    for (int k = 0; k < 3; ++k) {
      double up[3] = {x[0], x[1], x[2]}, dn[3] = {x[0], x[1], x[2]};
      const double h = kStep * (k == 2 ? s0 : std::hypot(fl, fz));
      up[k] += h;
      dn[k] -= h;
      const CatenaryEnd<double> eu = Chain(attachments, up[0], up[1], up[2]);
      const CatenaryEnd<double> ed = Chain(attachments, dn[0], dn[1], dn[2]);
      const double dspan = (eu.span_m - ed.span_m) / (2 * h);
      const double drise = (eu.rise_m - ed.rise_m) / (2 * h);
      const double scale_span = std::max(std::abs(c.dspan[k]), 1e-3 * std::abs(c.dspan[2]) / s0);
      EXPECT_NEAR(c.dspan[k], dspan, kTol * std::max(scale_span, std::abs(dspan)))
          << "trial " << trial << " partial " << k;
      EXPECT_NEAR(c.drise[k], drise, kTol * std::max(std::abs(c.drise[k]), std::abs(drise)))
          << "trial " << trial << " partial " << k;
    }
  }
}

TEST(CatenaryChainTest, AttachmentsBeyondTheCableAreFound) {
  const CatenaryChain<double> chain =
      MakeCatenaryChain({Point(4.0, 400.0), Range(10.0, 1000.0, 1.0), Point(310.0, 5.0)});
  double start_m = 0.0;
  EXPECT_EQ(CatenaryChainBeyond(chain, 320.0, &start_m), -1);  // the range may reach beyond
  EXPECT_EQ(CatenaryChainBeyond(chain, 300.0, &start_m), 2);
  EXPECT_EQ(start_m, 310.0);
  EXPECT_EQ(CatenaryChainBeyond(chain, 8.0, &start_m), 1);  // the range starts beyond
  EXPECT_EQ(start_m, 10.0);
}

TEST(CatenaryChainTest, AttachmentValidation) {
  std::string why;
  EXPECT_TRUE(Point(0.0, 0.0).IsValid(&why));
  EXPECT_FALSE(Point(-1.0, 10.0).IsValid(&why));
  EXPECT_EQ(why.substr(0, 4), "at_m");
  EXPECT_FALSE(Point(1.0, -10.0).IsValid(&why));
  EXPECT_EQ(why.substr(0, 7), "mass_kg");
  EXPECT_FALSE(Range(5.0, 5.0, 1.0).IsValid(&why));
  EXPECT_EQ(why.substr(0, 4), "to_m");
  EXPECT_FALSE(Range(-1.0, 5.0, 1.0).IsValid(&why));
  EXPECT_EQ(why.substr(0, 6), "from_m");
  EXPECT_FALSE(Range(0.0, 5.0, -1.0).IsValid(&why));
  EXPECT_EQ(why.substr(0, 22), "added_density_kg_per_m");
  EXPECT_FALSE(Point(std::nan(""), 1.0).IsValid(&why));
}

}  // namespace
}  // namespace fastcal
