// The tension readings' scale against the cabin's weight (fastcal/tension_scale.h):
// FAST's tensions pass, the same read 1000x small or large, or in tonne-force, are
// refused naming the slip,
// and a lengths file without tensions is not judged.
#include "fastcal/tension_scale.h"

#include <gtest/gtest.h>

#include <cmath>

namespace fastcal {
namespace {

// n samples whose six tensions are `tension_n` each.
Dataset Uniform(double tension_n, int n = 5) {
  Dataset d;
  d.path = "data.csv";
  for (int k = 0; k < n; ++k) {
    Sample s;
    s.tension_n.fill(tension_n);
    d.samples.push_back(s);
  }
  return d;
}

TEST(TensionScaleTest, FastsTensionsPassAndAUnitSlipIsNamed) {
  const CableRobot fast = CableRobot::NominalFast();
  constexpr double kCableN = 180e3;  // FAST's cables at the home pose
  std::string error;
  EXPECT_TRUE(CheckTensionScale(Uniform(kCableN), fast, &error)) << error;
  EXPECT_FALSE(CheckTensionScale(Uniform(kCableN / 1e3), fast, &error));
  EXPECT_NE(error.find("data.csv: the six tensions sum to 1.08 kN a sample (median)"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("read 1000x small"), std::string::npos) << error;
  EXPECT_FALSE(CheckTensionScale(Uniform(kCableN * 1e3), fast, &error));
  EXPECT_NE(error.find("read 1000x large"), std::string::npos) << error;
  // Tonne-force read as kN (9.8x small: a sum of ~0.37 of the weight; a review found it
  // passed the former floor of a third) is named as such.
  constexpr double kNPerTonneForce = 9806.65;
  EXPECT_FALSE(CheckTensionScale(Uniform(kCableN / kNPerTonneForce * 1e3), fast, &error));
  EXPECT_NE(error.find("tonne-force"), std::string::npos) << error;
  // The bounds: 0.8 of the weight passes (sensors 20% low), a little less does not.
  EXPECT_DOUBLE_EQ(kMinWeightFraction, 0.8);
  const double weight_n = fast.cabin_mass_kg * std::abs(fast.gravity_m_per_s2);
  EXPECT_TRUE(CheckTensionScale(Uniform(weight_n * kMinWeightFraction / 6 * 1.001), fast, &error));
  EXPECT_FALSE(CheckTensionScale(Uniform(weight_n * kMinWeightFraction / 6 * 0.999), fast, &error));
  Dataset lengths = Uniform(0.0);
  lengths.has_tensions = false;
  EXPECT_TRUE(CheckTensionScale(lengths, fast, &error));
}

}  // namespace
}  // namespace fastcal
