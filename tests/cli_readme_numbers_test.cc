// The README's numbers are what the commands print (issue 39): its "Cables as built"
// example is run as written and every number the README quotes from it is compared, at
// the digits the README gives, with the command's own output. A change of the results
// fails here until the README says the new ones.
#include <cmath>
#include <regex>
#include <string>

#include "cli_fixture.h"

namespace fastcal::test {
namespace {

class CliReadmeNumbersTest : public CliTest {
 protected:
  // The estimate and sigma_total (m) of `name` on calibrate's console.
  static std::pair<double, double> Estimate(const std::string& output, const std::string& name) {
    std::smatch m;
    const std::regex row("\n  " + name + R"( +(\S+) \+- (\S+) m)");
    EXPECT_TRUE(std::regex_search(output, m, row)) << name << "\n" << output;
    if (m.empty()) return {NAN, NAN};
    return {std::stod(m[1]), std::stod(m[2])};
  }
  // `value` written with `decimals` decimals, as the README writes it.
  static std::string Fixed(double value, int decimals) {
    char b[32];
    std::snprintf(b, sizeof b, "%.*f", decimals, value);
    return b;
  }
};

TEST_F(CliReadmeNumbersTest, CablesAsBuiltAreAsTheReadmeSays) {
  const std::string readme = ReadFile(Source() + "/README.md");
  const std::string data = Source() + "/calibration_data/";
  ASSERT_EQ(Fastcal("simulate --truth=" + data +
                    "as_built.yaml --trajectory=random --samples=800 "
                    "--mass-centre=0.22,0.11,0.56 --tension-noise-percent=3 "
                    "--sensor-gain-spread-percent=1 --sensor-bias-spread-kN=1.5 --seed=11 --out=" +
                    Path("as_built.csv"))
                .code,
            0);
  const CommandResult uniform =
      Fastcal("calibrate --spec=" + data + "spec_realistic.yaml --data=" + Path("as_built.csv") +
              " --out=" + Path("uniform"));
  const CommandResult built =
      Fastcal("calibrate --model=" + data + "as_built.yaml --spec=" + data +
              "spec_realistic.yaml --data=" + Path("as_built.csv") + " --out=" + Path("as_built"));
  ASSERT_EQ(uniform.code, 0) << uniform.output;
  ASSERT_EQ(built.code, 0) << built.output;
  // "the mass centre's z comes out 0.448 m +- 7.5 mm ... move z by 27 sigma_total"
  const auto [z, sz] = Estimate(uniform.output, "mass_centre_m.z");
  std::smatch m;
  const std::regex quoted_z(R"(z comes out (\S+) m \+- (\S+) mm against)");
  ASSERT_TRUE(std::regex_search(readme, m, quoted_z));
  EXPECT_EQ(m[1].str(), Fixed(z, 3));
  EXPECT_EQ(m[2].str(), Fixed(1e3 * sz, 1));
  const std::regex moved(R"(\(([0-9.]+) sigma_total\): the model lacks)");
  std::smatch n;
  ASSERT_TRUE(std::regex_search(uniform.output, n, moved)) << uniform.output;
  EXPECT_NE(readme.find("move z by " + Fixed(std::stod(n[1]), 0) + " sigma_total"),
            std::string::npos);
  EXPECT_NE(uniform.output.find("verdict: model incomplete"), std::string::npos);
  // "With the attachments in the model: (x, y, z) m +- (sx, sy, sz) mm, verdict ok."
  const std::regex quoted(R"(With the attachments\s+in the model: \((\S+), (\S+), (\S+)\) m \+- \((\S+), (\S+), (\S+)\) mm)");
  ASSERT_TRUE(std::regex_search(readme, m, quoted));
  const char* axes[] = {"mass_centre_m.x", "mass_centre_m.y", "mass_centre_m.z"};
  for (int k = 0; k < 3; ++k) {
    const auto [v, s] = Estimate(built.output, axes[k]);
    EXPECT_EQ(m[1 + k].str(), Fixed(v, 4)) << axes[k];
    EXPECT_EQ(m[4 + k].str(), Fixed(1e3 * s, 1)) << axes[k];
  }
  EXPECT_NE(built.output.find("verdict: ok"), std::string::npos);
}

}  // namespace
}  // namespace fastcal::test
