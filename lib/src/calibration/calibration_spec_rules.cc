// The calibration spec's rules (calibration_spec_rules.h): the parameter groups' names,
// the checks of each value shared by the reader and CalibrationSpec::IsValid, and the
// writer's exact number text. Values are checked against the plausible ranges of
// plausibility.h and parameter_plausibility.h.
#include "calibration/calibration_spec_rules.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <system_error>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/quote.h"
#include "fastcal/parameter_plausibility.h"
#include "fastcal/plausibility.h"
#include "util/yaml_document.h"

namespace fastcal::spec_rules {

using internal::ShortestNumber;

// ---------------------------------------------------------------------------------------
// Facts about each parameter group, in canonical order (the order of ParameterKind).

AttachmentKind AttachmentKindOf(ParameterKind kind) {
  return kind == ParameterKind::kAttachmentMass ? AttachmentKind::kPointMass
                                                : AttachmentKind::kAddedDensity;
}

AttachmentShape ShapeOf(const CableRobot& model) {
  AttachmentShape shape;
  for (int i = 0; i < kNumCables; ++i) {
    for (const CableAttachment& a : model.cables[i].attachments) shape[i].push_back(a.kind);
  }
  return shape;
}

std::string MeasuredOffsetName(int component) {
  return std::string(kMeasuredFrameKey) + ".offset_m." +
         std::string(1, kAxes[component < 0 ? 0 : component]);
}

std::string PartParameterName(const std::string& part, ParameterKind kind, int component) {
  std::string name = std::string(kMovingPartsKey) + "." + part;
  if (kind == ParameterKind::kPartMass) return name + ".mass_kg";
  return name + ".first_moment_kg_m." + std::string(1, kAxes[component < 0 ? 0 : component]);
}

std::string PartOfParameterName(const std::string& name) {
  const std::string prefix = std::string(kMovingPartsKey) + ".";
  if (name.compare(0, prefix.size(), prefix) != 0) return "";
  const size_t end = name.find('.', prefix.size());
  return name.substr(prefix.size(), end == std::string::npos ? end : end - prefix.size());
}

// "mass_centre_m.x", "cabin_mass_kg", "ea_n[3]", "anchor_offset_m[2].z",
// "attachment_mass_kg[3][1]" (1-based).
std::string ParameterName(const ParameterKindInfo& g, int index, int component) {
  std::string name = g.key;
  if (IsAttachment(g.kind)) {
    return name + "[" + std::to_string(index + 1) + "][" + std::to_string(component + 1) + "]";
  }
  if (index >= 0) name += "[" + std::to_string(index + 1) + "]";
  if (component >= 0 && component < 3) name += std::string(".") + kAxes[component];
  return name;
}

// ---------------------------------------------------------------------------------------
// Checks shared by the reader and CalibrationSpec::IsValid. Each returns what is wrong,
// or an empty string.

// "" for a value within the plausible range of its kind (plausibility.h), else why not.
std::string CheckPlausible(ParameterKind kind, double value_si) {
  std::string why;
  return CheckParameterValue(kind, value_si, PlausibilityLimits(), &why) ? "" : why;
}

std::string CheckInitial(ParameterKind kind, double initial_si) {
  if (!std::isfinite(initial_si)) return "must be finite";
  const ParameterKindInfo* row = FindParameterKind(kind);
  const char* what = row != nullptr ? row->positive : nullptr;
  if (what != nullptr && !(initial_si > 0.0)) {
    return std::string("must be > 0 (") + what + " is positive)";
  }
  if (row != nullptr && row->non_negative && !(initial_si >= 0.0)) {
    return "must be >= 0 (an attachment adds weight)";
  }
  return CheckPlausible(kind, initial_si);
}

std::string CheckPriorMean(ParameterKind kind, double mean) {
  return std::isfinite(mean) ? CheckPlausible(kind, mean) : "must be finite";
}

// A prior's sigma: > 0, and not wider than the parameter's plausible range (a sigma of
// 2000 on sensor_bias_kN is 2000 N written as kN).
//
// Nor narrower than kTightestPriorFraction of that range (issue 29: a sigma of 1e-200
// made the fit's weights infinite, NaN in the fit and Ceres' dumps on stderr): a prior
// that tight is the parameter held fixed, which the spec says with free: false.
std::string CheckPriorSigma(ParameterKind kind, double sigma_si) {
  constexpr double kTightestPriorFraction = 1e-9;
  if (!(std::isfinite(sigma_si) && sigma_si > 0.0)) return "must be > 0";
  ModelQuantity quantity;
  if (!QuantityOfParameter(kind, &quantity)) return "";
  const QuantityRange range = PlausibleRange(quantity, PlausibilityLimits());
  const double width = range.max - range.min;
  const std::string unit = range.file_unit;
  auto shown = [&](double v) {
    return internal::FormatDouble("%.6g", v / range.si_per_file_unit) +
           (unit.empty() ? "" : " " + unit);
  };
  if (sigma_si < kTightestPriorFraction * width) {
    return shown(sigma_si) + " is below " + shown(kTightestPriorFraction * width) +
           " (1e-9 of the parameter's plausible range): a prior this tight holds the "
           "parameter fixed; say so with free: false (and initial: its value)";
  }
  if (sigma_si <= width) return "";
  return shown(sigma_si) + " is wider than the whole plausible range of the parameter (" +
         shown(range.min) + " to " + shown(range.max) + ")";
}

// The noise's sigmas: >= 0 and plausible (a tension sigma of 3000 kN is 3000 N).
// A part that is not 0 (none) must be at least what a sensor could resolve (issue 29: a
// tension sigma of 1e-160 kN made the weights infinite and the fit NaN).
std::string CheckNoiseSigma(ModelQuantity quantity, double value_si) {
  if (!(std::isfinite(value_si) && value_si >= 0.0)) return "must be >= 0";
  const PlausibilityLimits limits;
  const bool absolute = quantity == ModelQuantity::kTensionSigmaN;
  const double floor = absolute ? limits.min_tension_sigma_n : limits.min_tension_sigma_percent;
  if (value_si > 0.0 && value_si < floor) {
    return absolute ? internal::FormatDouble("%.6g kN", value_si / kNPerKn) + " is below " +
                          internal::FormatDouble("%g kN", floor / kNPerKn) +
                          ", finer than any tension sensor resolves (0 means no absolute part)"
                    : internal::FormatDouble("%.6g %%", value_si) + " is below " +
                          internal::FormatDouble("%g %%", floor) +
                          ", finer than any tension sensor resolves (0 means no relative part)";
  }
  std::string why;
  return CheckQuantity(quantity, value_si, limits, &why) ? "" : why;
}

// A slow error's time constant: > 0 and shorter than a year (a longer memory is a
// constant offset: the sensors' biases).
std::string CheckTimeConstant(double value_s) {
  constexpr double kYearS = 365.25 * 86400.0;
  if (!(std::isfinite(value_s) && value_s > 0.0)) return "must be > 0 (seconds)";
  return value_s <= kYearS ? "" : "must be at most a year (31557600 s)";
}

std::string CheckPositive(double value) {
  return std::isfinite(value) && value > 0.0 ? "" : "must be > 0";
}

// The lengths' sigma: > 0 when given (leave it out for no lengths) and plausible.
std::string CheckLengthSigma(double value_m) {
  if (!(std::isfinite(value_m) && value_m > 0.0)) {
    return "must be > 0 (leave it out to fit without the lengths)";
  }
  // Not CheckNoiseSigma: its floor is the tension sensors'; an encoder may resolve 0.1 mm.
  std::string why;
  return CheckQuantity(ModelQuantity::kLengthSigmaM, value_m, PlausibilityLimits(), &why) ? ""
                                                                                          : why;
}

// Lengths in the fit need exact's s0 (aas's are not solved in a fit), and a free or
// consider length_offset_m needs the lengths in the fit.
std::string LengthsProblem(const CalibrationSpec& s) {
  if (s.UsesLengths() && s.forward_model != StaticsMethod::kExact) {
    return "length_sigma_m: the lengths need forward_model: exact (the other methods' "
           "unstretched lengths are approximate)";
  }
  if (s.UsesLengths()) return "";
  for (const ParameterSpec& p : s.parameters) {
    if (p.kind == ParameterKind::kLengthOffset && (p.free || p.IsConsider())) {
      return p.name +
             ": the lengths are not in the fit, so nothing determines it: give "
             "noise.length_sigma_m (the dataset's s0_<i>_m columns then count)";
    }
  }
  return "";
}

std::string CheckHoldoutFraction(double fraction) {
  return std::isfinite(fraction) && fraction >= 0.0 && fraction < 1.0 ? "" : "must be in [0, 1)";
}

std::string CheckAtLeastOne(int value) { return value >= 1 ? "" : "must be >= 1"; }

std::string CheckThreads(int value) {
  return value >= 1 && value <= kMaxCalibrationThreads
             ? ""
             : "must be 1 to " + std::to_string(kMaxCalibrationThreads) + ", got " +
                   std::to_string(value);
}

std::string CheckAtLeastTwo(int value) { return value >= 2 ? "" : "must be >= 2"; }

// The change scan's family-wise false-alarm probability: strictly between 0 and 0.5
// (its critical values are tabulated down to 1e-4: change_scan.cc).
std::string CheckSignificance(double p) {
  return p >= 1e-4 && p <= 0.5 ? "" : "must be between 0.0001 and 0.5";
}

// A group (or one parameter, by its name) named by sessions.separate or
// change_scan.parameters must have a free parameter: only free parameters can differ
// between sessions or step.
std::string GroupWithoutFreeParameter(const CalibrationSpec& spec, const std::string& group) {
  for (const ParameterSpec& p : spec.parameters) {
    // A joint fit's copies are named NAME@SESSION (sessions.h).
    const std::string name = p.name.substr(0, p.name.find('@'));
    if (p.free && (group == ParameterGroupName(p.kind) || group == name)) return "";
  }
  return group + " has no free parameter in this spec (free: true under parameters)";
}

std::string CheckFraction(double fraction) {
  return std::isfinite(fraction) && fraction > 0.0 && fraction <= 1.0 ? "" : "must be in (0, 1]";
}

bool IsKnownMethod(StaticsMethod method) {
  StaticsMethod parsed;
  return ParseStaticsMethod(StaticsMethodName(method), &parsed) && parsed == method;
}

// ---------------------------------------------------------------------------------------
// Number text.

// A value stored in SI, as text in a unit `to_si` times larger: the shortest text t with
// parse(t) * to_si == si when there is one, so that writing and reading back is exact.
// For values the reader produced (si = file value * to_si) si / to_si already is such a
// t; the search of the neighbours is a guard for values set in code.
std::string NumInUnit(double si, double to_si) {
  constexpr int kMaxUlpSteps = 4;
  const double guess = si / to_si;
  if (!std::isfinite(guess) || guess * to_si == si) return ShortestNumber(guess);
  double down = guess;
  double up = guess;
  for (int step = 0; step < kMaxUlpSteps; ++step) {
    down = std::nextafter(down, -HUGE_VAL);
    up = std::nextafter(up, HUGE_VAL);
    if (down * to_si == si) return ShortestNumber(down);
    if (up * to_si == si) return ShortestNumber(up);
  }
  return ShortestNumber(guess);  // no exact preimage: the nearest
}

ParameterSpec MakeParameter(const ParameterKindInfo& g, int index, int component,
                            const EntryText& e) {
  ParameterSpec p;
  p.kind = g.kind;
  p.index = index;
  p.component = component;
  p.name = ParameterName(g, index, component);
  p.unit = g.unit;
  p.to_si = g.to_si;
  p.free = e.free.value_or(false);
  p.has_initial = e.initial.has_value();
  p.initial_si = p.has_initial ? *e.initial * g.to_si : 0.0;
  p.has_prior = e.prior.has_value();
  if (p.has_prior) {
    p.prior_mean_si = e.prior->first * g.to_si;
    p.prior_sigma_si = e.prior->second * g.to_si;
  }
  return p;
}

}  // namespace fastcal::spec_rules
