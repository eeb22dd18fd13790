// Tests of the calibration and evaluation report (fastcal/report.h): Markdown tables with
// formatted numbers, self-contained HTML with inline SVG and no "nan"/"inf", well-formed
// JSON, the evaluation-only report, and the atomic writing of the three files.
#include "fastcal/report.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "fastcal/svg_plot.h"

namespace fastcal {
namespace {

namespace fs = std::filesystem;

constexpr int kNumSamples = 20;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

::testing::AssertionResult Contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "the text does not contain '" << part << "'";
}

int Count(const std::string& text, const std::string& part) {
  int n = 0;
  for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

// Alphanumeric words of `text`, lowercased, that spell a non-finite number.
std::vector<std::string> NonFiniteWords(const std::string& text) {
  std::vector<std::string> found;
  std::string word;
  for (size_t i = 0; i <= text.size(); ++i) {
    const unsigned char c = i < text.size() ? text[i] : ' ';
    if (std::isalnum(c)) {
      word += static_cast<char>(std::tolower(c));
      continue;
    }
    if (word == "nan" || word == "inf" || word == "infinity") found.push_back(word);
    word.clear();
  }
  return found;
}

// A strict recursive-descent JSON checker (RFC 8259 grammar, no extensions).
class JsonChecker {
 public:
  explicit JsonChecker(const std::string& text) : s_(text) {}
  bool Valid() {
    SkipSpace();
    if (!Value()) return false;
    SkipSpace();
    return i_ == s_.size();
  }

 private:
  void SkipSpace() {
    while (i_ < s_.size() && std::strchr(" \t\r\n", s_[i_]) != nullptr) ++i_;
  }
  bool Literal(const char* word) {
    const size_t n = std::strlen(word);
    if (s_.compare(i_, n, word) != 0) return false;
    i_ += n;
    return true;
  }
  bool String() {
    if (i_ >= s_.size() || s_[i_] != '"') return false;
    for (++i_; i_ < s_.size(); ++i_) {
      const unsigned char c = s_[i_];
      if (c == '"') {
        ++i_;
        return true;
      }
      if (c < 0x20) return false;
      if (c == '\\') {
        ++i_;
        if (i_ >= s_.size() || std::strchr("\"\\/bfnrtu", s_[i_]) == nullptr) return false;
      }
    }
    return false;
  }
  bool Number() {
    const size_t start = i_;
    if (i_ < s_.size() && s_[i_] == '-') ++i_;
    const size_t digits = i_;
    while (i_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[i_]))) ++i_;
    if (i_ == digits) return false;
    if (i_ < s_.size() && s_[i_] == '.') {
      ++i_;
      const size_t frac = i_;
      while (i_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[i_]))) ++i_;
      if (i_ == frac) return false;
    }
    if (i_ < s_.size() && (s_[i_] == 'e' || s_[i_] == 'E')) {
      ++i_;
      if (i_ < s_.size() && (s_[i_] == '+' || s_[i_] == '-')) ++i_;
      const size_t exp = i_;
      while (i_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[i_]))) ++i_;
      if (i_ == exp) return false;
    }
    return i_ > start;
  }
  bool Sequence(char close, bool object) {
    ++i_;
    SkipSpace();
    if (i_ < s_.size() && s_[i_] == close) {
      ++i_;
      return true;
    }
    while (true) {
      SkipSpace();
      if (object) {
        if (!String()) return false;
        SkipSpace();
        if (i_ >= s_.size() || s_[i_] != ':') return false;
        ++i_;
        SkipSpace();
      }
      if (!Value()) return false;
      SkipSpace();
      if (i_ >= s_.size()) return false;
      if (s_[i_] == close) {
        ++i_;
        return true;
      }
      if (s_[i_] != ',') return false;
      ++i_;
    }
  }
  bool Value() {
    if (i_ >= s_.size()) return false;
    switch (s_[i_]) {
      case '{':
        return Sequence('}', true);
      case '[':
        return Sequence(']', false);
      case '"':
        return String();
      case 't':
        return Literal("true");
      case 'f':
        return Literal("false");
      case 'n':
        return Literal("null");
      default:
        return Number();
    }
  }
  const std::string& s_;
  size_t i_ = 0;
};

TEST(JsonCheckerTest, AcceptsJsonAndRejectsBrokenText) {
  EXPECT_TRUE(JsonChecker(R"({"a": [1, -2.5e3, null, true], "b": {"c": "x\"y"}})").Valid());
  EXPECT_FALSE(JsonChecker(R"({"a": [1, 2})").Valid());
  EXPECT_FALSE(JsonChecker(R"({"a": nan})").Valid());
  EXPECT_FALSE(JsonChecker(R"({"a": 1,})").Valid());
}

// Statistics of a variant from its predictions, as EvaluateVariant would compute them.
VariantEvaluation MakeVariant(const std::string& name, const Dataset& data,
                              const std::vector<bool>& held_out, double offset_n, double wave_n) {
  VariantEvaluation v;
  v.name = name;
  for (size_t n = 0; n < data.samples.size(); ++n) {
    std::array<double, kNumCables> p{};
    for (int i = 0; i < kNumCables; ++i) {
      p[i] = data.samples[n].tension_n[i] + offset_n * (i + 1) / kNumCables +
             wave_n * std::sin(0.7 * n + i);
    }
    v.predicted_n.push_back(p);
  }
  v.fit = ErrorStats(data, v.predicted_n, held_out, false);
  v.holdout = ErrorStats(data, v.predicted_n, held_out, true);
  return v;
}

class ReportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    model_ = CableRobot::NominalFast();
    data_.path = "circle.csv";
    for (int n = 0; n < kNumSamples; ++n) {
      Sample s;
      s.line = n + 2;
      s.time_s = 10.0 * n;
      // Steps of 0.05 rad, a trajectory: lines join consecutive samples in the plots.
      s.pose.position_m =
          Eigen::Vector3d(71.11 * std::cos(0.05 * n), 71.11 * std::sin(0.05 * n), 156.73);
      for (int i = 0; i < kNumCables; ++i) {
        s.tension_n[i] = 1e3 * (180.0 + 40.0 * std::sin(0.3 * n + i));
      }
      data_.samples.push_back(s);
    }
    held_out_ = HoldoutMask(kNumSamples, 0.2, 1);

    spec_.tension_sigma_percent = 3.0;
    spec_.forward_model = StaticsMethod::kAas;  // its error against exact is in the result
    spec_.holdout_fraction = 0.2;
    spec_.holdout_seed = 1;

    CalibrationResult& r = result_;
    ParameterEstimate x;
    x.name = "mass_centre_m.x";
    x.unit = "m";
    x.free = true;
    x.initial = 0.0;
    x.estimate = 0.2213;
    x.sigma = 0.0031;
    x.sigma_statistical = 0.0040;
    x.sigma_systematic = 0.0030;
    x.sigma_total = 0.0050;
    x.widening = 0.004 / 0.0031;
    x.systematic_by_group = {0.0030};
    ParameterEstimate rho;
    rho.name = "linear_density_kg_per_m";
    rho.unit = "kg/m";
    rho.free = true;
    rho.initial = 11.718;
    rho.estimate = 11.93;
    rho.sigma = 0.12;
    rho.sigma_statistical = 0.12;
    rho.sigma_total = 0.13;
    rho.sigma_systematic = 0.05;
    rho.systematic_by_group = {0.05};
    rho.has_prior = true;
    rho.prior_mean = 11.718;
    rho.prior_sigma = 0.5;
    rho.note = "set mostly by its prior";
    ParameterEstimate mass;
    mass.name = "cabin_mass_kg";
    mass.unit = "kg";
    mass.initial = mass.estimate = 30000.0;
    ParameterEstimate gain;
    gain.name = "sensor_gain[3]";
    gain.unit = "1";
    gain.consider = true;
    gain.initial = gain.estimate = 1.0;
    gain.has_prior = true;
    gain.prior_mean = 1.0;
    gain.prior_sigma = 0.01;
    gain.sigma_total = 0.01;
    r.parameters = {x, mass, rho, gain};
    r.budget.consider_groups = {"sensor_gain"};
    r.budget.misfit_factor = 1.0;
    r.budget.samples = kNumSamples - 4;
    r.budget.correlated = true;
    r.budget.tau = 2.5;
    r.budget.bandwidth = 20;
    r.budget.effective_samples = 6.4;
    r.verdict = FitVerdict::kOk;
    r.verdict_text = "reduced chi-square 0.98 agrees with the stated noise (1 +- 0.435)";
    r.misfit_ranking = {{"sensor_gain[3]", "1", 410.0, 80.0, true, 0.03, false, {}},
                        {"tower_offset_m[2].z", "m", 12.0, 2.0, false, 0.001, false, {}}};
    r.misfit_threshold = 15.1;
    r.excluded.assign(kNumSamples, {});
    r.excluded[7][2] = true;
    ReadingResidual gross;
    gross.sample = 7;
    gross.line = 9;
    gross.cable = 3;
    gross.measured_n = 99999e3;
    gross.predicted_n = 154.342e3;
    gross.residual_sigma = -21563.5;
    r.gross_errors = {gross};
    r.gross_error_summary.enabled = true;
    r.gross_error_summary.threshold_sigmas = 5;
    r.gross_error_summary.count = {0, 0, 1, 0, 0, 0};
    r.gross_error_summary.scale = {1, 1, 1.2, 1, 1, 1};
    r.cross_validation.blocks = 10;
    r.cross_validation.folds_used = 10;
    r.cross_validation.rms_n = {5100, 5200, 5300, 5400, 5500, 5600};
    r.cross_validation.fit_rms_n = {5000, 5100, 5200, 5300, 5400, 5500};
    r.free_names = {"mass_centre_m.x", "linear_density_kg_per_m"};
    r.correlation.resize(2, 2);
    r.correlation << 1.0, 0.95, 0.95, 1.0;
    r.covariance_ok = true;
    r.strong_correlations = {"mass_centre_m.x ~ linear_density_kg_per_m: +0.95"};
    r.before.singular_value_ratios = {1.0, 2e-3};
    r.after.singular_value_ratios = {1.0, 1.5e-3};
    r.data_only.singular_value_ratios = {1.0, 1e-12};
    ParameterDirection d;
    d.singular_value_ratio = 1e-12;
    d.weights = {{"linear_density_kg_per_m", 1.0}};
    r.data_only.undetermined = {d};
    r.calibrated = model_;
    r.held_out = held_out_;
    r.num_fit_samples = kNumSamples - 4;
    r.num_residuals = 6 * r.num_fit_samples + 1;
    r.num_free = 2;
    r.initial_cost = 5123.4;
    r.final_cost = 47.5;
    r.reduced_chi_square = 0.98;
    r.iterations = 7;
    r.converged = true;
    r.termination = "CONVERGENCE";
    r.ceres_full_report = "Solver Summary (v 2.1.0-eigen)\n  <Residual blocks> & more\n";
    r.forward_model_max_rel_error = 2.1e-4;
    r.forward_model_rms_rel_error = 8e-5;
    r.seconds = 1.25;

    // The paper's Table 6, first row, as a variant with fixed statistics.
    VariantEvaluation paper;
    paper.name = "paper nominal";
    paper.fit.samples = kNumSamples - 4;
    paper.fit.rms_n = {22554, 17517, 20078, 18687, 17167, 18190};
    VariantEvaluation before =
        MakeVariant("nominal model, measured attitude", data_, held_out_, 20e3, 8e3);
    VariantEvaluation after =
        MakeVariant("calibrated model, measured attitude", data_, held_out_, 1e3, 4e3);
    after.fit.rms_percent[2] = kNaN;  // a statistic that could not be computed
    after.holdout.mean_n[4] = std::numeric_limits<double>::infinity();

    inputs_.model_path = "";
    inputs_.spec_path = "spec_mass_centre.yaml";
    inputs_.data_path = "circle.csv";
    inputs_.spec_digest = "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef";
    inputs_.data_digest = "fedcba9876543210fedcba9876543210fedcba9876543210fedcba9876543210";
    inputs_.software_version = "0.1.0";
    inputs_.command_line = "fastcal calibrate --spec=spec_mass_centre.yaml --data=circle.csv";
    inputs_.run_utc = "2026-11-22T15:04:05Z";
    inputs_.initial_model = &model_;
    inputs_.spec = &spec_;
    inputs_.data = &data_;
    inputs_.result = &result_;
    inputs_.variants = {paper, before, after};
    inputs_.evaluation_method = "exact";
  }

  ReportInputs EvaluateOnly() const {
    ReportInputs in = inputs_;
    in.spec = nullptr;
    in.spec_path.clear();
    in.spec_digest.clear();
    in.result = nullptr;
    std::vector<bool> none;
    in.variants = {MakeVariant("model, measured attitude", data_, none, 20e3, 8e3)};
    return in;
  }

  CableRobot model_;
  Dataset data_;
  std::vector<bool> held_out_;
  CalibrationSpec spec_;
  CalibrationResult result_;
  ReportInputs inputs_;
};

// An exact fit has no forward model error to quote: the provenance says so instead of "max
// 0 %", which read like a measurement that found nothing.
TEST_F(ReportTest, AnExactFitSaysItHasNoForwardModelError) {
  EXPECT_TRUE(Contains(ReportMarkdown(inputs_), "max 0.021 %, RMS 0.008 %"));
  spec_.forward_model = StaticsMethod::kExact;
  const std::string md = ReportMarkdown(inputs_);
  EXPECT_TRUE(Contains(md,
                       "| Forward model error vs exact | none: the fit's forward model is "
                       "exact |"))
      << md;
  EXPECT_FALSE(Contains(md, "max 0.021 %")) << md;
}

TEST_F(ReportTest, MarkdownHasEstimatesAndRmsTables) {
  const std::string md = ReportMarkdown(inputs_);
  EXPECT_TRUE(Contains(md, "# fastcal calibration report"));
  // Estimates: names, units, values to the precision sigma_total supports, sigma_total,
  // the formal sigma and the widening, prior, note; a fixed and a consider parameter say so.
  EXPECT_TRUE(Contains(md,
                       "| `mass_centre_m.x` | m | 0 | **0.22130** | **0.005** | 0.0031 | "
                       "× 1.29 | - |"));
  EXPECT_TRUE(Contains(md,
                       "| `linear_density_kg_per_m` | kg/m | 11.718 | **11.930** | **0.13** | 0.12 "
                       "| × 1 | 11.718 ± 0.5 | set mostly by its prior |"));
  EXPECT_TRUE(Contains(md, "| `cabin_mass_kg` | kg | 30000 | 30000 | fixed |"));
  EXPECT_TRUE(Contains(md, "| `sensor_gain[3]` | 1 | 1 | 1 | 0.01 (consider) |"));
  // RMS table: the paper's numbers in kN with three decimals.
  EXPECT_TRUE(Contains(md,
                       "| paper nominal | 16 | 22.554 | 17.517 | 20.078 | 18.687 | 17.167 | "
                       "18.190 |"));
  EXPECT_TRUE(Contains(md, "RMS of model - measured [kN], fitted samples (n = 16)"));
  EXPECT_TRUE(Contains(md, "held-out samples (n = 4"));
  EXPECT_TRUE(Contains(md, "RMS of 100 (model - measured) / model [%]"));
  EXPECT_TRUE(Contains(md, "Largest |model - measured| [kN]"));
  // Verdict, provenance, identifiability, calibrated model, Ceres report.
  EXPECT_TRUE(Contains(md, "**Converged** (termination: `CONVERGENCE`) after 7 iterations"));
  EXPECT_TRUE(Contains(md, "5123.4 → 47.5"));
  EXPECT_TRUE(Contains(md, "χ²/ν = **0.98**"));
  EXPECT_TRUE(Contains(md, "the residuals scatter as the noise model says"));
  EXPECT_TRUE(Contains(md, "16 fitted, 4 held out (20 in the dataset)"));
  EXPECT_TRUE(Contains(md, "nominal FAST model (built in)"));
  EXPECT_TRUE(Contains(md, "| Run (UTC) | 2026-11-22T15:04:05Z |"));
  EXPECT_TRUE(Contains(md,
                       "`spec_mass_centre.yaml` (SHA-256 "
                       "`0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef`)"));
  EXPECT_TRUE(Contains(md, "max 0.021 %, RMS 0.008 %"));
  EXPECT_TRUE(Contains(md, "The data alone cannot determine `linear_density_kg_per_m (+1.00)`"));
  EXPECT_TRUE(Contains(md, "the prior holds it"));
  EXPECT_TRUE(Contains(md, "`mass_centre_m.x ~ linear_density_kg_per_m: +0.95`"));
  EXPECT_TRUE(Contains(md, "| `mass_centre_m.x` | +1.00 | +0.95 |"));
  EXPECT_TRUE(
      Contains(md, "fastcal evaluate --model=DIR/model_calibrated.yaml --data=OTHER_DATA.csv"));
  EXPECT_TRUE(Contains(md, "```\nSolver Summary (v 2.1.0-eigen)\n  <Residual blocks> & more\n```"));
  EXPECT_TRUE(NonFiniteWords(md).empty()) << NonFiniteWords(md).front();
  EXPECT_TRUE(Contains(md, "n/a"));
}

TEST_F(ReportTest, ChiSquareBandSaysHowItIsComputed) {
  // nu = 6 * 16 + 1 - 2 = 95 residuals minus free parameters; 3 sqrt(2 / 95) = 0.435.
  const std::string md = ReportMarkdown(inputs_);
  EXPECT_TRUE(Contains(md,
                       "(expected 1 ± 3·√(2/ν) = 1 ± 0.435: within 3 standard deviations of "
                       "χ²/ν for a correct noise model, ν = 95 degrees of freedom)"));
  result_.num_residuals = 6 * 16 + 2;  // nu = 96 -> 0.433
  result_.reduced_chi_square = 1.5;
  EXPECT_TRUE(Contains(ReportMarkdown(inputs_), "1 ± 3·√(2/ν) = 1 ± 0.433:"));
}

TEST_F(ReportTest, ChiSquareInterpretation) {
  result_.reduced_chi_square = 9.0;
  EXPECT_TRUE(Contains(ReportMarkdown(inputs_),
                       "model error the free parameters cannot absorb, "
                       "or noise underestimated"));
  EXPECT_TRUE(Contains(ReportMarkdown(inputs_), "√(χ²/ν) = 3"));
  result_.reduced_chi_square = 0.1;
  EXPECT_TRUE(Contains(ReportMarkdown(inputs_), "the noise is overestimated"));
  result_.converged = false;
  result_.termination = "NO_CONVERGENCE";
  EXPECT_TRUE(Contains(ReportMarkdown(inputs_), "**Did not converge**"));
}

std::string SvgTitled(const std::string& html, const std::string& title);

// The verdict opens with the calibration's own: good, misfit scaled, noise overstated or
// failed, with its text; the band's numbers stay in summary.json.
TEST_F(ReportTest, VerdictOpensWithTheCalibrationsVerdict) {
  std::string md = ReportMarkdown(inputs_);  // 0.98, within 1 +- 0.435
  EXPECT_TRUE(Contains(md, "## Verdict\n\n> **Good fit:** reduced chi-square 0.98 agrees"));
  EXPECT_TRUE(Contains(SummaryJson(inputs_), "\"reduced_chi_square_within_band\": true"));
  result_.reduced_chi_square = 17.5;
  result_.verdict = FitVerdict::kMisfit;
  result_.verdict_text = "reduced chi-square 17.5 is above 1 + 0.435: the residuals are 4.18 times";
  md = ReportMarkdown(inputs_);
  EXPECT_TRUE(Contains(md,
                       "## Verdict\n\n> **Misfit, scaled into the uncertainties:** reduced "
                       "chi-square 17.5 is above 1 + 0.435"))
      << md;
  const std::string json = SummaryJson(inputs_);
  EXPECT_TRUE(Contains(json, "\"reduced_chi_square_within_band\": false")) << json;
  EXPECT_TRUE(Contains(json, "\"reduced_chi_square_band_half_width\": 0.435")) << json;
  EXPECT_TRUE(Contains(json, "\"status\": \"misfit scaled\"")) << json;
  result_.verdict = FitVerdict::kFailed;
  result_.verdict_text = "do not use the estimates";
  EXPECT_TRUE(Contains(ReportHtml(inputs_), "<strong>The fit failed:</strong> do not use"));
  result_.verdict = FitVerdict::kNoiseOverstated;
  EXPECT_TRUE(Contains(ReportMarkdown(inputs_), "**Noise overstated:**"));
}

// The budget's parts per parameter, what each consider group adds, the residuals'
// memory; the gross errors by line and cable; the misfit ranking; cross-validation.
TEST_F(ReportTest, DiagnosticSectionsNameTheirNumbers) {
  const std::string md = ReportMarkdown(inputs_);
  EXPECT_TRUE(Contains(md, "## Uncertainty budget"));
  EXPECT_TRUE(Contains(md,
                       "| formal σ | misfit × | correlation × | statistical σ | systematic: "
                       "`sensor_gain` | systematic σ | **σ\\_total** |"));
  EXPECT_TRUE(Contains(md,
                       "| `mass_centre_m.x` | m | 0.0031 | 1 | 1.29 | 0.004 | 0.003 | 0.003 "
                       "| **0.005** |"))
      << md;
  EXPECT_TRUE(Contains(md,
                       "- `sensor_gain`: 3 mm on `mass_centre_m.x`, 0.05 kg/m on "
                       "`linear_density_kg_per_m`"));
  EXPECT_TRUE(Contains(md, "carry about 6.4 independent pieces of information"));
  EXPECT_TRUE(Contains(md, "## Gross errors and worst readings"));
  EXPECT_TRUE(Contains(md, "| 9 | 3 | 99999.000 | 154.342 | -21563.5 |\n"));  // none held out
  EXPECT_TRUE(Contains(md, "| gross errors | 0 | 0 | 1 | 0 | 0 | 0 |"));
  EXPECT_TRUE(Contains(md,
                       "**The misfit is best explained by freeing:** `sensor_gain[3]` "
                       "(about 410)."));
  // Only the significant candidate is tabled; the other is counted, not listed.
  EXPECT_TRUE(Contains(md, "| 1 | `sensor_gain[3]` | 410 | 80 | 0.03 | - |")) << md;
  EXPECT_FALSE(Contains(md, "| 2 | `tower_offset_m[2].z`"));
  EXPECT_TRUE(Contains(md, "1 more candidate (not significant) in summary.json"));
  EXPECT_TRUE(Contains(md, "| **calibrated, cross-validated** | 5.100 | 5.200 |"));
  const std::string json = SummaryJson(inputs_);
  EXPECT_TRUE(JsonChecker(json).Valid());
  EXPECT_TRUE(Contains(json,
                       "\"outliers\": [\n    {\n      \"line\": 9,\n      \"cable\": 3,\n"
                       "      \"measured_kN\": 99999,\n      \"predicted_kN\": 154.342,\n"
                       "      \"residual_sigma\": -21563.5,"))
      << json;
  EXPECT_TRUE(Contains(json, "\"sigma_total\": 0.005,"));
  EXPECT_TRUE(Contains(json, "\"systematic_by_group\": {\n          \"sensor_gain\": 0.003\n"));
  EXPECT_TRUE(Contains(json, "\"run_utc\": \"2026-11-22T15:04:05Z\""));
  EXPECT_TRUE(Contains(json,
                       "\"name\": \"sensor_gain[3]\",\n      "
                       "\"expected_chi_square_decrease\": 410,"));
}

// The gross error is a red dot on its cable's tension plot, held at the plot's edge (at
// 99999 kN it would flatten it), and said so; an unordered set of samples is drawn as
// dots, a trajectory with lines; the page prints with its details open and long lines
// wrapped.
TEST_F(ReportTest, PlotsSuitTheDataAndShowGrossErrorsOnScale) {
  std::string html = ReportHtml(inputs_);
  EXPECT_TRUE(Contains(html, "Gross errors (kept out of the fit) are the red dots"));
  const std::string cable3 = SvgTitled(html, "Cable 3: tension");
  EXPECT_TRUE(Contains(cable3, "stroke=\"#C00000\"")) << cable3;
  EXPECT_TRUE(Contains(cable3, ">gross error<"));
  EXPECT_FALSE(Contains(cable3, "e+0")) << "an axis up to 99999 kN";
  EXPECT_FALSE(Contains(SvgTitled(html, "Cable 1: tension"), "#C00000"));
  // A circle keeps its off-axis angle (issue 17): that plot is left out, and said so.
  EXPECT_FALSE(Contains(html, "<title>Residual against off-axis angle</title>"));
  EXPECT_TRUE(Contains(html,
                       "Not drawn against the off-axis angle from the focal centre: the "
                       "data span only 26.4"));
  EXPECT_TRUE(Contains(html, "<title>Residual against azimuth</title>"));
  EXPECT_TRUE(Contains(html, "<title>Predicted against measured</title>"));
  EXPECT_TRUE(Contains(html, "@media print"));
  EXPECT_TRUE(Contains(html, "details::details-content { content-visibility: visible;"));
  EXPECT_TRUE(Contains(html, "lines on top; dashed: before calibration"));
  for (size_t n = 0; n < data_.samples.size(); ++n) {  // random order: not a trajectory
    data_.samples[n].pose.position_m =
        Eigen::Vector3d(71.11 * std::cos(2.4 * n), 71.11 * std::sin(2.4 * n), 156.73);
  }
  html = ReportHtml(inputs_);
  EXPECT_TRUE(Contains(html, "dots on top: the samples are not a trajectory"));
  const std::string svg = SvgTitled(html, "Cable 1: tension");
  const std::string after = "stroke=\"" + PlotSeriesColour(2) + "\"";
  EXPECT_TRUE(Contains(svg, after + " stroke-width=\"3.6\" stroke-linecap=\"round\"")) << svg;
}

// The verdict stands apart by colour: green, blue, amber, red by what it means for using
// the result; Markdown quotes it.
TEST_F(ReportTest, TheVerdictIsABannerColouredByItsMeaning) {
  const std::vector<std::pair<FitVerdict, std::string>> tones = {
      {FitVerdict::kOk, "banner-good"},
      {FitVerdict::kNoiseOverstated, "banner-info"},
      {FitVerdict::kMisfit, "banner-caution"},
      {FitVerdict::kModelIncomplete, "banner-bad"},
      {FitVerdict::kFailed, "banner-bad"}};
  for (const auto& [verdict, tone] : tones) {
    result_.verdict = verdict;
    const std::string html = ReportHtml(inputs_);
    EXPECT_TRUE(Contains(html, "<div class=\"banner " + tone + "\"><strong>")) << tone;
    EXPECT_EQ(Count(html, "<div class=\"banner "), 1);
  }
  EXPECT_TRUE(Contains(ReportHtml(inputs_), ".banner-bad { background: #fde8e6;"));
}

// No significant candidate: one sentence with the largest, no table of shifts that would
// read as evidence.
TEST_F(ReportTest, AGoodFitsMisfitRankingIsOneSentence) {
  for (MisfitCandidate& c : result_.misfit_ranking) c.significant = false;
  const std::string md = ReportMarkdown(inputs_);
  EXPECT_TRUE(Contains(md,
                       "No fixed parameter explains the misfit beyond the residuals' own noise: "
                       "the largest statistic, 80 (from freeing `sensor_gain[3]`; expected χ² "
                       "decrease 410), is below the threshold 15.1. All 2 candidates are in "
                       "summary.json"))
      << md;
  EXPECT_FALSE(Contains(md, "| Freed, moves |"));
  EXPECT_TRUE(Contains(SummaryJson(inputs_), "\"name\": \"tower_offset_m[2].z\""));
}

// Eighteen alike consider parameters (every tower offset 0 +- 0.01 m) are one row.
TEST_F(ReportTest, AlikeFixedParametersAreOneRow) {
  for (int t = 1; t <= 6; ++t) {
    for (const char* axis : {"x", "y", "z"}) {
      ParameterEstimate p;
      p.name = "tower_offset_m[" + std::to_string(t) + "]." + axis;
      p.unit = "m";
      p.consider = p.has_prior = true;
      p.prior_sigma = p.sigma_total = 0.01;
      result_.parameters.push_back(p);
    }
  }
  result_.parameters.back().prior_sigma = 0.02;  // the last one differs: its own row
  const std::string md = ReportMarkdown(inputs_);
  EXPECT_TRUE(Contains(md,
                       "| `tower_offset_m[1].x` … `tower_offset_m[6].y` (17, all alike) | m | 0 "
                       "| 0 | 0.01 (consider) |  |  | 0 ± 0.01 |  |"))
      << md;
  EXPECT_TRUE(Contains(md, "| `tower_offset_m[6].z` | m |"));
  EXPECT_FALSE(Contains(md, "tower_offset_m[3].y"));
  EXPECT_TRUE(Contains(SummaryJson(inputs_), "\"name\": \"tower_offset_m[3].y\""));
}

// On the paper's measured circle (the whole turn) its Table 6 follows the RMS table; on a
// part of it, not.
TEST_F(ReportTest, ThePapersTable6FollowsTheRmsTableOnItsCircle) {
  EXPECT_FALSE(Contains(ReportMarkdown(inputs_), "The paper's Table 6"));  // 1 rad of it
  // 40 more samples round the whole turn (the tables' statistics are the variants', made
  // before): every 10-degree sector visited.
  for (int k = 0; k < 40; ++k) {
    Sample s = data_.samples.front();
    const double a = 2.0 * M_PI * (k + 0.5) / 40.0;
    s.pose.position_m = Eigen::Vector3d(71.11 * std::cos(a), 71.11 * std::sin(a), 156.73);
    data_.samples.push_back(s);
  }
  const std::string md = ReportMarkdown(inputs_);
  EXPECT_TRUE(Contains(md, "**The paper's Table 6, the same circle on the telescope: RMS [kN]**"))
      << md;
  EXPECT_TRUE(Contains(md,
                       "| AAS | initial model, planned attitude | 22.554 | 17.517 | 20.078 | "
                       "18.687 | 17.167 | 18.190 |"));
}

// Issue 59: a report on data fastcal simulate made says so before anything else, and
// sets the paper's Table 6 beside its RMS only with that caveat.
TEST_F(ReportTest, AReportOnSimulatedDataSaysSoFirst) {
  for (int k = 0; k < 40; ++k) {  // the paper's whole circle, as above
    Sample s = data_.samples.front();
    const double a = 2.0 * M_PI * (k + 0.5) / 40.0;
    s.pose.position_m = Eigen::Vector3d(71.11 * std::cos(a), 71.11 * std::sin(a), 156.73);
    data_.samples.push_back(s);
  }
  EXPECT_FALSE(Contains(ReportMarkdown(inputs_), "Simulated data"));
  inputs_.simulated_provenance =
      "Simulated by fastcal 0.2.0\nfastcal simulate --seed=1 --out=c.csv\nTruth model: c.yaml";
  const std::string md = ReportMarkdown(inputs_);
  const size_t note = md.find(
      "**Simulated data.** The data file says it was made by fastcal "
      "simulate (`Simulated by fastcal 0.2.0`");
  ASSERT_NE(note, std::string::npos) << md.substr(0, 1500);
  EXPECT_LT(note, md.find("## Provenance"));
  EXPECT_TRUE(Contains(md,
                       "| Data's header | simulated: `Simulated by fastcal 0.2.0`; `fastcal "
                       "simulate --seed=1 --out=c.csv`; `Truth model: c.yaml` |"))
      << md;
  EXPECT_TRUE(Contains(md,
                       "**The paper's Table 6, the same circle on the real telescope (these "
                       "data are simulated): RMS [kN]**"))
      << md;
  EXPECT_TRUE(Contains(md, "**These data are simulated** (made by fastcal simulate"));
  EXPECT_TRUE(Contains(ReportHtml(inputs_), "Simulated data."));
}

// A pose axis the data move along is plotted (a spiral: the off-axis angle varies).
TEST_F(ReportTest, APlotAgainstAnAxisThatVariesIsDrawn) {
  for (size_t n = 0; n < data_.samples.size(); ++n) data_.samples[n].pose.position_m.z() += 3.0 * n;
  const std::string html = ReportHtml(inputs_);
  EXPECT_TRUE(Contains(html, "<title>Residual against off-axis angle</title>"));
  EXPECT_FALSE(Contains(html, "Not drawn against"));
}

// The "check it on other data" commands name this run's directory and another dataset,
// never the fitted file and a literal DIR (issue 17); an empty column is not drawn, and
// the misfit table's headers are short enough for a 900 px window.
TEST_F(ReportTest, CalibratedModelCommandsNameRealFilesAndTablesStayNarrow) {
  std::string md = ReportMarkdown(inputs_);
  EXPECT_TRUE(Contains(md, "--data=OTHER_DATA.csv"));
  EXPECT_TRUE(Contains(md, "stands for such a file"));
  EXPECT_FALSE(Contains(md, "--data=circle.csv\n"));
  inputs_.out_dir = "out/circle";
  inputs_.other_data_path = "calibration_data/workspace_multi_zenith.csv";
  md = ReportMarkdown(inputs_);
  EXPECT_TRUE(Contains(md,
                       "fastcal evaluate --model=out/circle/model_calibrated.yaml "
                       "--data=calibration_data/workspace_multi_zenith.csv"));
  EXPECT_FALSE(Contains(md, "DIR/"));
  // No listed reading is held out here: no "Held out" column.
  for (ReadingResidual& e : result_.worst_readings) e.held_out = false;
  for (ReadingResidual& e : result_.gross_errors) e.held_out = false;
  md = ReportMarkdown(inputs_);
  EXPECT_FALSE(Contains(md, "| Held out |"));
  ASSERT_FALSE(result_.gross_errors.empty());
  result_.gross_errors.front().held_out = true;
  EXPECT_TRUE(Contains(ReportMarkdown(inputs_), "| Held out |"));
  EXPECT_TRUE(Contains(md,
                       "| # | Parameter | Expected χ² decrease | Statistic | Freed, moves | "
                       "Moves most |"));
}

// "Nothing is poorly determined" only when no estimate leans on its prior either.
TEST_F(ReportTest, SaysSoWhenNothingIsPoorlyDetermined) {
  result_.data_only.undetermined.clear();
  EXPECT_TRUE(Contains(ReportMarkdown(inputs_),
                       "No combination of parameters is poorly determined by the data alone, "
                       "but 1 estimate(s) are set mostly by their prior"));
  result_.parameters[2].note.clear();
  EXPECT_TRUE(Contains(ReportMarkdown(inputs_), "Nothing is poorly determined"));
}

// A long set of samples that is not a trajectory is thinned evenly, not by min/max per
// bucket (which keeps only each bucket's extremes of an unordered cloud: two false bands).
TEST_F(ReportTest, UnorderedSamplesAreThinnedEvenly) {
  constexpr int kLong = 5000;
  Sample s = data_.samples.back();
  data_.samples.clear();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI);
  for (int n = 0; n < kLong; ++n) {
    s.line = n + 2;
    s.time_s = n;
    const double a = angle(rng);
    s.pose.position_m = Eigen::Vector3d(71.11 * std::cos(a), 71.11 * std::sin(a), 156.73);
    data_.samples.push_back(s);
  }
  result_.held_out = held_out_ = HoldoutMask(kLong, 0.2, 1);
  result_.excluded.clear();
  result_.gross_errors.clear();
  inputs_.variants[1] =
      MakeVariant("nominal model, measured attitude", data_, held_out_, 20e3, 8e3);
  inputs_.variants[2] =
      MakeVariant("calibrated model, measured attitude", data_, held_out_, 1e3, 4e3);
  const std::string html = ReportHtml(inputs_);
  EXPECT_TRUE(Contains(html, "Thinned for drawing: one point in 3 of the 5000 samples, evenly"));
  EXPECT_FALSE(Contains(html, "min/max per bucket"));
}

TEST_F(ReportTest, HtmlIsSelfContainedWithPlotsAndNoNonFiniteNumbers) {
  const std::string html = ReportHtml(inputs_);
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_TRUE(Contains(html, "<meta charset=\"utf-8\">"));
  EXPECT_TRUE(Contains(html, "</html>"));
  // Heatmap, RMS bars (fitted and held out), tension per cable, histogram, residual per
  // cable, residual against azimuth, predicted against measured (not against the
  // off-axis angle, which a circle keeps).
  EXPECT_GE(Count(html, "<svg"), 4);
  EXPECT_EQ(Count(html, "<svg"), 1 + 2 + 6 + 1 + 6 + 2);
  EXPECT_TRUE(Contains(html, "<details>\n<summary>Ceres full report</summary>"));
  EXPECT_TRUE(Contains(html, "&lt;Residual blocks&gt; &amp; more"));
  EXPECT_TRUE(Contains(html, "<td class=\"num\">22.554</td>"));
  const std::vector<std::string> bad = NonFiniteWords(html);
  EXPECT_TRUE(bad.empty()) << bad.front();
  EXPECT_FALSE(Contains(html, "<script"));
  // No external resources: the only URL is the SVG namespace name, which is not fetched.
  std::string stripped = html;
  const std::string ns = "xmlns=\"http://www.w3.org/2000/svg\"";
  for (size_t at; (at = stripped.find(ns)) != std::string::npos;) stripped.erase(at, ns.size());
  EXPECT_FALSE(Contains(stripped, "http://"));
  EXPECT_FALSE(Contains(stripped, "https://"));
  EXPECT_FALSE(Contains(stripped, "src="));
  EXPECT_FALSE(Contains(stripped, "href="));
  EXPECT_FALSE(Contains(stripped, "url("));
}

// The <svg> element of `html` with the title `title`, or "".
std::string SvgTitled(const std::string& html, const std::string& title) {
  const size_t at = html.find("<title>" + title + "</title>");
  if (at == std::string::npos) return "";
  const size_t begin = html.rfind("<svg", at);
  return html.substr(begin, html.find("</svg>", at) + 6 - begin);
}

TEST_F(ReportTest, TensionPlotsDrawMeasuredDotsUnderTheModelLines) {
  const std::string svg = SvgTitled(ReportHtml(inputs_), "Cable 1: tension");
  ASSERT_FALSE(svg.empty());
  // Colours: a variant's index in the RMS table; measured (fitted) black, held out sky blue.
  const std::string before = "stroke=\"" + PlotSeriesColour(1) + "\"";
  const std::string after = "stroke=\"" + PlotSeriesColour(2) + "\"";
  const std::string held = "stroke=\"" + PlotSeriesColour(5) + "\"";
  const std::string measured = "stroke=\"" + PlotSeriesColour(6) + "\"";
  ASSERT_NE(svg.find(measured), std::string::npos);
  ASSERT_NE(svg.find(held), std::string::npos);
  ASSERT_NE(svg.find(before), std::string::npos);
  ASSERT_NE(svg.find(after), std::string::npos);
  // Both measured series come before (under) both model lines.
  EXPECT_LT(svg.find(measured), svg.find(before));
  EXPECT_LT(svg.find(measured), svg.find(after));
  EXPECT_LT(svg.find(held), svg.find(before));
  EXPECT_LT(svg.find(held), svg.find(after));
  // Small translucent dots; the lines opaque; the legend names all four series.
  EXPECT_TRUE(Contains(svg, measured + " stroke-width=\"3.6\" stroke-linecap=\"round\" "
                                       "stroke-opacity=\"0.45\""));
  EXPECT_TRUE(Contains(svg, held + " stroke-width=\"3.6\" stroke-linecap=\"round\" "
                                   "stroke-opacity=\"0.7\""));
  EXPECT_EQ(Count(svg, "stroke-opacity"), 2);
  for (const char* name :
       {">nominal model, measured attitude<", ">calibrated model, measured attitude<",
        ">measured (fitted)<", ">measured (held out)<"}) {
    EXPECT_TRUE(Contains(svg, name));
  }
  EXPECT_TRUE(Contains(ReportHtml(inputs_),
                       "Measured lower-end tension (translucent dots, drawn "
                       "underneath"));
  // 20 samples: nothing is thinned, and no caption says so.
  EXPECT_FALSE(Contains(ReportHtml(inputs_), "Thinned"));
}

// A long dataset: the plots are thinned, with outliers kept, and the report stays small.
TEST_F(ReportTest, LongDatasetsAreThinnedInThePlotsOnly) {
  constexpr int kLong = 60000;
  constexpr size_t kMaxHtmlBytes = 1500000;  // 1.5 MB; 31 MB before thinning.
  Sample s = data_.samples.back();
  data_.samples.clear();
  for (int n = 0; n < kLong; ++n) {
    s.line = n + 2;
    s.time_s = 0.1 * n;
    for (int i = 0; i < kNumCables; ++i) {
      s.tension_n[i] = 1e3 * (180.0 + 40.0 * std::sin(1e-4 * n + i) + 3.0 * std::sin(7.3 * n));
    }
    data_.samples.push_back(s);
  }
  data_.samples[31337].tension_n[0] = 620e3;  // An outlier, far above the rest (< 225 kN).
  result_.excluded.clear();                   // not flagged as a gross error: drawn
  result_.gross_errors.clear();
  held_out_ = HoldoutMask(kLong, 0.2, 1);
  result_.held_out = held_out_;
  result_.num_fit_samples =
      kLong - static_cast<int>(std::count(held_out_.begin(), held_out_.end(), true));
  inputs_.variants[0].fit.samples = result_.num_fit_samples;  // The paper's row.
  inputs_.variants[1] =
      MakeVariant("nominal model, measured attitude", data_, held_out_, 20e3, 8e3);
  inputs_.variants[2] =
      MakeVariant("calibrated model, measured attitude", data_, held_out_, 1e3, 4e3);
  const std::string html = ReportHtml(inputs_);
  EXPECT_LT(html.size(), kMaxHtmlBytes);
  // Both time-plot figures say they were thinned and how.
  EXPECT_EQ(Count(html,
                  "Thinned for drawing (min/max per bucket): each series of more than 2000 "
                  "points is cut into 1000 buckets of consecutive samples (about 60 per bucket "
                  "for all 60000 samples)"),
            2);
  // No series has more than 2000 points.
  for (size_t p = html.find("<path d=\""); p != std::string::npos;
       p = html.find("<path d=\"", p + 1)) {
    const std::string d = html.substr(p, html.find('"', p + 9) - p);
    EXPECT_LE(Count(d, "M") + Count(d, "L"), 2000);
  }
  // The outlier is still drawn: cable 1's tension axis reaches 600 kN.
  EXPECT_TRUE(Contains(SvgTitled(html, "Cable 1: tension"), ">600<"));
  EXPECT_FALSE(Contains(SvgTitled(html, "Cable 2: tension"), ">600<"));
  // The tables and the histogram use every sample.
  const int fitted = result_.num_fit_samples;
  EXPECT_TRUE(Contains(html, "fitted samples (n = " + std::to_string(fitted) + ")"));
  EXPECT_TRUE(Contains(html, "held-out samples (n = " + std::to_string(kLong - fitted)));
  EXPECT_TRUE(Contains(html, "(n=" + std::to_string(6 * kLong) + ")"));
  EXPECT_TRUE(NonFiniteWords(html).empty());
}

TEST_F(ReportTest, JsonIsWellFormedWithTheSummary) {
  const std::string json = SummaryJson(inputs_);
  EXPECT_TRUE(JsonChecker(json).Valid()) << json;
  EXPECT_TRUE(Contains(json, "\"reduced_chi_square\": 0.98"));
  EXPECT_TRUE(Contains(json, "\"software_version\": \"0.1.0\""));
  EXPECT_TRUE(Contains(
      json, "\"sha256\": \"fedcba9876543210fedcba9876543210fedcba9876543210fedcba9876543210\""));
  EXPECT_TRUE(Contains(json, "\"spec_yaml\": \""));
  EXPECT_TRUE(Contains(json, "\"rms_kN\": [22.554, 17.517, 20.078, 18.687, 17.167, 18.19]"));
  EXPECT_TRUE(Contains(json, "\"prior\": null"));
  EXPECT_TRUE(Contains(json, "\"matrix\": ["));
  EXPECT_TRUE(Contains(json, "\"data_only\": {"));
  EXPECT_TRUE(Contains(json,
                       "\"samples\": {\n    \"total\": 20,\n    \"fitted\": 16,\n"
                       "    \"held_out\": 4,\n    \"skipped\": 0,\n    \"skipped_rows\": [],\n"
                       "    \"time_first_s\": "))
      << json;
  EXPECT_TRUE(Contains(json, "null"));  // the NaN statistic
  EXPECT_TRUE(NonFiniteWords(json).empty());
}

// Rows skipped under --skip-invalid-rows (malformed or unsolvable) are counted and listed
// in every report file, never dropped silently.
TEST_F(ReportTest, SkippedRowsAreCountedAndListed) {
  data_.skipped = {"circle.csv:7: column 'T3_kN': 'x' is not a number",
                   "circle.csv:9: the model cannot solve this pose (measured attitude, exact): "
                   "cable 1 is slack"};
  const std::string md = ReportMarkdown(inputs_);
  EXPECT_TRUE(Contains(md, "2 rows skipped: malformed, or a pose the model cannot solve")) << md;
  EXPECT_TRUE(Contains(md, "circle.csv:9: the model cannot solve this pose")) << md;
  EXPECT_TRUE(Contains(ReportHtml(inputs_), "circle.csv:9: the model cannot solve this pose"));
  const std::string json = SummaryJson(inputs_);
  EXPECT_TRUE(JsonChecker(json).Valid()) << json;
  EXPECT_TRUE(Contains(json,
                       "\"skipped\": 2,\n    \"skipped_rows\": [\n      \"circle.csv:7: column "
                       "'T3_kN': 'x' is not a number\",\n      \"circle.csv:9: the model cannot"))
      << json;
}

TEST_F(ReportTest, EvaluateOnlyReport) {
  const ReportInputs in = EvaluateOnly();
  const std::string md = ReportMarkdown(in);
  const std::string html = ReportHtml(in);
  const std::string json = SummaryJson(in);
  EXPECT_TRUE(Contains(md, "# fastcal evaluation report"));
  EXPECT_TRUE(Contains(md, "RMS of model - measured [kN], all samples (n = 20)"));
  EXPECT_FALSE(Contains(md, "## Estimates"));
  EXPECT_FALSE(Contains(md, "Calibration spec"));
  EXPECT_FALSE(Contains(md, "model_calibrated.yaml"));
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_GE(Count(html, "<svg"), 4);
  EXPECT_TRUE(NonFiniteWords(html).empty());
  EXPECT_TRUE(JsonChecker(json).Valid()) << json;
  EXPECT_TRUE(Contains(json, "\"report\": \"evaluation\""));
  EXPECT_TRUE(Contains(json, "\"solver\": null"));
  EXPECT_TRUE(Contains(json, "\"holdout\": null"));
}

TEST_F(ReportTest, DegenerateInputsStillGiveAReport) {
  ReportInputs in;
  EXPECT_TRUE(Contains(ReportMarkdown(in), "No model variant was evaluated."));
  EXPECT_EQ(ReportHtml(in).rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_TRUE(JsonChecker(SummaryJson(in)).Valid());
  // A result without covariance and variants without predictions.
  result_.covariance_ok = false;
  result_.correlation.resize(0, 0);
  for (VariantEvaluation& v : inputs_.variants) v.predicted_n.clear();
  const std::string html = ReportHtml(inputs_);
  EXPECT_TRUE(Contains(html, "The covariance could not be computed"));
  EXPECT_TRUE(NonFiniteWords(html).empty());
  EXPECT_TRUE(JsonChecker(SummaryJson(inputs_)).Valid());
  EXPECT_TRUE(Contains(SummaryJson(inputs_), "\"correlation\": null"));
}

class ReportFilesTest : public ReportTest {
 protected:
  void SetUp() override {
    ReportTest::SetUp();
    std::string pattern = ::testing::TempDir() + "report_test_XXXXXX";
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  std::vector<std::string> Entries(const fs::path& dir) const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir)) {
      names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }
  static std::string ReadFile(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }
  fs::path dir_;
};

// Rendered on the spec's threads (issue 41), each file is the one rendering gives alone.
TEST_F(ReportFilesTest, WritesThreeFilesTheSameOnAnyNumberOfThreads) {
  for (int threads : {1, 2, 3, 8}) {
    CalibrationSpec spec = spec_;
    spec.num_threads = threads;
    ReportInputs inputs = inputs_;
    inputs.spec = &spec;
    std::string error;
    ASSERT_TRUE(WriteReportFiles(dir_.string(), inputs, &error)) << error;
    EXPECT_EQ(Entries(dir_),
              (std::vector<std::string>{"report.html", "report.md", "summary.json"}));
    EXPECT_EQ(ReadFile(dir_ / "report.md"), ReportMarkdown(inputs)) << threads;
    EXPECT_EQ(ReadFile(dir_ / "report.html"), ReportHtml(inputs)) << threads;
    EXPECT_EQ(ReadFile(dir_ / "summary.json"), SummaryJson(inputs)) << threads;
  }
}

TEST_F(ReportFilesTest, MissingDirectoryFailsAndLeavesNothing) {
  std::string error;
  EXPECT_FALSE(WriteReportFiles((dir_ / "missing").string(), inputs_, &error));
  EXPECT_TRUE(Contains(error, "missing/report.md"));
  EXPECT_TRUE(Entries(dir_).empty());
  EXPECT_FALSE(WriteReportFiles("", inputs_, &error));
}

TEST_F(ReportFilesTest, FailureHalfwayRemovesWhatItWrote) {
  // summary.json cannot replace a directory: the two files written before are removed.
  fs::create_directory(dir_ / "summary.json");
  std::string error;
  EXPECT_FALSE(WriteReportFiles(dir_.string(), inputs_, &error));
  EXPECT_TRUE(Contains(error, "summary.json"));
  EXPECT_EQ(Entries(dir_), std::vector<std::string>{"summary.json"});
  EXPECT_TRUE(fs::is_directory(dir_ / "summary.json"));
}

}  // namespace
}  // namespace fastcal
