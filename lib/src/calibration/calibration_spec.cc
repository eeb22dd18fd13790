// The calibration spec: YAML reading, validation and writing (format: docs/calibration.md).
//
// The spec is edited by hand, so the reader is strict in the way the model reader is
// (cable_robot_yaml.cc): unknown keys and unknown parameter names are errors, and every
// error reads "<file>:<line>: <key path>: <what>". Parameters come out in the canonical
// order of calibration_spec.h, which is the order of ParameterKind, whatever the order of
// the keys in the file. Values in the file are in the unit the key names (kN for the
// sensor bias and the absolute tension noise); they are stored in SI. The checks of
// CalibrationSpec::IsValid and of the reader share one set of functions, so a spec built
// in code and a spec read from a file are held to the same rules.
#include "fastcal/calibration_spec.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <charconv>
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
#include "fastcal/model_plausibility.h"
#include "fastcal/plausibility.h"
#include "util/yaml_document.h"

namespace fastcal {
namespace {

constexpr char kFormatName[] = "fastcal-calibration-spec-1";
constexpr char kRootPath[] = "(top level)";
constexpr double kNewtonsPerKilonewton = 1e3;
constexpr char kAxes[] = "xyz";

// ---------------------------------------------------------------------------------------
// Facts about each parameter group, in canonical order (the order of ParameterKind).

struct GroupInfo {
  ParameterKind kind;
  const char* key;   // key under `parameters:` and stem of the parameter names
  const char* unit;  // unit of the values in the file
  double to_si;      // SI value = file value * to_si
};

constexpr GroupInfo kGroups[] = {
    {ParameterKind::kMassCentre, "mass_centre_m", "m", 1.0},
    {ParameterKind::kCabinMass, "cabin_mass_kg", "kg", 1.0},
    {ParameterKind::kLinearDensity, "linear_density_kg_per_m", "kg/m", 1.0},
    {ParameterKind::kEa, "ea_n", "N", 1.0},
    {ParameterKind::kAnchorOffset, "anchor_offset_m", "m", 1.0},
    {ParameterKind::kTowerOffset, "tower_offset_m", "m", 1.0},
    {ParameterKind::kSensorGain, "sensor_gain", "1", 1.0},
    {ParameterKind::kSensorBias, "sensor_bias_kN", "kN", kNewtonsPerKilonewton},
    {ParameterKind::kAttachmentMass, "attachment_mass_kg", "kg", 1.0},
    {ParameterKind::kAttachmentDensity, "attachment_density_kg_per_m", "kg/m", 1.0},
};

bool IsAttachment(ParameterKind kind) {
  return kind == ParameterKind::kAttachmentMass || kind == ParameterKind::kAttachmentDensity;
}

AttachmentKind AttachmentKindOf(ParameterKind kind) {
  return kind == ParameterKind::kAttachmentMass ? AttachmentKind::kPointMass
                                                : AttachmentKind::kAddedDensity;
}

// What the model's cables carry, as the spec reader needs it: each cable's attachment kinds.
using AttachmentShape = std::array<std::vector<AttachmentKind>, kNumCables>;

AttachmentShape ShapeOf(const CableRobot& model) {
  AttachmentShape shape;
  for (int i = 0; i < kNumCables; ++i) {
    for (const CableAttachment& a : model.cables[i].attachments) shape[i].push_back(a.kind);
  }
  return shape;
}

// Null for a kind outside the enum (a spec built in code from a bad cast).
const GroupInfo* InfoOf(ParameterKind kind) {
  for (const GroupInfo& g : kGroups) {
    if (g.kind == kind) return &g;
  }
  return nullptr;
}

// Groups that are either one parameter for all cables or one per cable.
bool IsPerCableCapable(ParameterKind kind) {
  return kind == ParameterKind::kLinearDensity || kind == ParameterKind::kEa ||
         kind == ParameterKind::kSensorGain || kind == ParameterKind::kSensorBias;
}

bool IsVector(ParameterKind kind) {
  return kind == ParameterKind::kMassCentre || kind == ParameterKind::kAnchorOffset ||
         kind == ParameterKind::kTowerOffset;
}

// "mass_centre_m.x", "cabin_mass_kg", "ea_n[3]", "anchor_offset_m[2].z",
// "attachment_mass_kg[3][1]" (1-based).
std::string ParameterName(const GroupInfo& g, int index, int component) {
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
  const char* what = nullptr;
  switch (kind) {
    case ParameterKind::kCabinMass:
      what = "a mass";
      break;
    case ParameterKind::kLinearDensity:
      what = "a linear density";
      break;
    case ParameterKind::kEa:
      what = "an axial stiffness EA";
      break;
    case ParameterKind::kSensorGain:
      what = "a sensor gain";
      break;
    default:
      break;
  }
  if (what != nullptr && !(initial_si > 0.0)) {
    return std::string("must be > 0 (") + what + " is positive)";
  }
  if (IsAttachment(kind) && !(initial_si >= 0.0)) {
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
    return absolute
               ? internal::FormatDouble("%.6g kN", value_si / kNewtonsPerKilonewton) +
                     " is below " + internal::FormatDouble("%g kN", floor / kNewtonsPerKilonewton) +
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

constexpr char kBothNoiseZero[] =
    "tension_sigma_kN and tension_sigma_percent are both 0 (the residuals could not be "
    "weighted)";

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

// Shortest decimal text that reads back to exactly `value`.
std::string Num(double value) {
  if (std::isnan(value)) return ".nan";
  if (std::isinf(value)) return value > 0 ? ".inf" : "-.inf";
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

// A value stored in SI, as text in a unit `to_si` times larger: the shortest text t with
// parse(t) * to_si == si when there is one, so that writing and reading back is exact.
// For values the reader produced (si = file value * to_si) si / to_si already is such a
// t; the search of the neighbours is a guard for values set in code.
std::string NumInUnit(double si, double to_si) {
  constexpr int kMaxUlpSteps = 4;
  const double guess = si / to_si;
  if (!std::isfinite(guess) || guess * to_si == si) return Num(guess);
  double down = guess;
  double up = guess;
  for (int step = 0; step < kMaxUlpSteps; ++step) {
    down = std::nextafter(down, -HUGE_VAL);
    up = std::nextafter(up, HUGE_VAL);
    if (down * to_si == si) return Num(down);
    if (up * to_si == si) return Num(up);
  }
  return Num(guess);  // no exact preimage: the nearest
}

// ---------------------------------------------------------------------------------------
// Reader.

std::string Join(const std::string& parent, const std::string& key) {
  return parent.empty() || parent == kRootPath ? key : parent + "." + key;
}
// Key paths number list elements from 1, like the parameter names.
std::string Element(const std::string& parent, size_t i) {
  return parent + "[" + std::to_string(i + 1) + "]";
}

int LineOf(const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  return mark.line < 0 ? 0 : mark.line + 1;
}

std::string ListOf(const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  return list;
}

// A key of a mapping and its value.
struct KeyValue {
  YAML::Node key;
  YAML::Node value;
  int line = 0;  // of the key
};
using KeyMap = std::map<std::string, KeyValue>;

// An entry as written in the file; fields not given stay empty, so that a per-cable
// entry can override its group field by field.
struct EntryText {
  std::optional<bool> free;
  std::optional<double> initial;                   // file unit
  std::optional<std::pair<double, double>> prior;  // mean, sigma; file unit
};

EntryText Override(const EntryText& base, const EntryText& over) {
  EntryText e = base;
  if (over.free) e.free = over.free;
  if (over.initial) e.initial = over.initial;
  if (over.prior) e.prior = over.prior;
  return e;
}

ParameterSpec MakeParameter(const GroupInfo& g, int index, int component, const EntryText& e) {
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

class Reader {
 public:
  Reader(const std::string& source, int num_anchor_points, AttachmentShape attachments)
      : source_(source),
        num_anchor_points_(num_anchor_points),
        attachments_(std::move(attachments)) {}

  const std::string& error() const { return error_; }

  // Records "<source>:<line>: <path>: <what>" (":<line>" left out when 0).
  bool Fail(int line, const std::string& path, const std::string& what) {
    error_ = source_;
    if (line > 0) error_ += ":" + std::to_string(line);
    // Key names come from the file: escaped like the values (internal/quote.h).
    error_ += ": " + internal::Escape(path) + ": " + what;
    return false;
  }

  bool ReadRoot(const YAML::Node& root, CalibrationSpec* spec) {
    KeyMap keys;
    if (!ReadMap(
            root, LineOf(root), kRootPath,
            {"format", "forward_model", "noise", "robust_loss", "gross_errors", "holdout",
             "cross_validation", "attitude", "solver", "parameters", "sessions", "change_scan"},
            &keys)) {
      return false;
    }
    if (const KeyValue* kv = Find(keys, "format")) {
      const YAML::Node& v = kv->value;
      if (!v.IsScalar() || v.Scalar() != kFormatName) {
        return Fail(
            kv->line, "format",
            std::string("must be ") + kFormatName + (v.IsScalar() ? ", got " + v.Scalar() : ""));
      }
    }
    if (const KeyValue* kv = Find(keys, "forward_model")) {
      std::string name;
      if (!ReadText(*kv, "forward_model", &name)) return false;
      if (!ParseStaticsMethod(name, &spec->forward_model)) {
        return Fail(kv->line, "forward_model",
                    "unknown forward model \"" + name + "\" (accepted: aas, aas-refined, exact)");
      }
    }
    if (const KeyValue* kv = Find(keys, "attitude")) {
      int choice = 0;
      if (!ReadChoice(*kv, "attitude", {"measured", "planned"}, &choice)) return false;
      spec->use_planned_attitude = choice == 1;
    }
    if (const KeyValue* kv = Find(keys, "noise"); kv != nullptr && !ReadNoise(*kv, spec)) {
      return false;
    }
    if (const KeyValue* kv = Find(keys, "robust_loss");
        kv != nullptr && !ReadRobustLoss(*kv, spec)) {
      return false;
    }
    if (const KeyValue* kv = Find(keys, "gross_errors");
        kv != nullptr && !ReadGrossErrors(*kv, spec)) {
      return false;
    }
    if (const KeyValue* kv = Find(keys, "holdout"); kv != nullptr && !ReadHoldout(*kv, spec)) {
      return false;
    }
    if (const KeyValue* kv = Find(keys, "cross_validation");
        kv != nullptr && !ReadCrossValidation(*kv, spec)) {
      return false;
    }
    if (const KeyValue* kv = Find(keys, "solver"); kv != nullptr && !ReadSolver(*kv, spec)) {
      return false;
    }
    if (const KeyValue* kv = Find(keys, "parameters");
        kv != nullptr && !ReadParameters(*kv, spec)) {
      return false;
    }
    // After the parameters: a group named here must have a free parameter.
    if (const KeyValue* kv = Find(keys, "sessions"); kv != nullptr && !ReadSessions(*kv, spec)) {
      return false;
    }
    if (const KeyValue* kv = Find(keys, "change_scan");
        kv != nullptr && !ReadChangeScan(*kv, spec)) {
      return false;
    }
    return true;
  }

 private:
  static const KeyValue* Find(const KeyMap& keys, const std::string& name) {
    const auto it = keys.find(name);
    return it == keys.end() ? nullptr : &it->second;
  }

  // Reads a mapping (a missing value counts as an empty one), rejecting duplicate keys
  // and keys not in `allowed`; `unknown` says what an unknown key is.
  bool ReadMap(const YAML::Node& node, int line, const std::string& path,
               const std::vector<std::string>& allowed, KeyMap* keys,
               const std::string& unknown = "unknown key (allowed here: ") {
    if (!node.IsDefined() || node.IsNull()) return true;
    if (!node.IsMap()) return Fail(line, path, "expected a mapping of keys");
    for (const auto& kv : node) {
      if (!kv.first.IsScalar()) return Fail(LineOf(kv.first), path, "keys must be plain names");
      const std::string name = kv.first.Scalar();
      const std::string key_path = Join(path, name);
      bool known = false;
      for (const std::string& a : allowed) known = known || a == name;
      if (!known) return Fail(LineOf(kv.first), key_path, unknown + ListOf(allowed) + ")");
      if (keys->count(name) != 0) return Fail(LineOf(kv.first), key_path, "duplicate key");
      const int key_line = LineOf(kv.first) > 0 ? LineOf(kv.first) : line;
      (*keys)[name] = KeyValue{kv.first, kv.second, key_line};
    }
    return true;
  }

  bool ReadMap(const KeyValue& kv, const std::string& path, const std::vector<std::string>& allowed,
               KeyMap* keys) {
    return ReadMap(kv.value, kv.line, path, allowed, keys);
  }

  bool ReadText(const KeyValue& kv, const std::string& path, std::string* text) {
    if (kv.value.IsNull()) return Fail(kv.line, path, "has no value");
    if (!kv.value.IsScalar()) return Fail(kv.line, path, "expected a name");
    *text = kv.value.Scalar();
    return true;
  }

  bool ReadChoice(const KeyValue& kv, const std::string& path,
                  const std::vector<std::string>& choices, int* choice) {
    std::string text;
    if (!ReadText(kv, path, &text)) return false;
    for (size_t k = 0; k < choices.size(); ++k) {
      if (text == choices[k]) {
        *choice = static_cast<int>(k);
        return true;
      }
    }
    return Fail(kv.line, path,
                "unknown value \"" + text + "\" (accepted: " + ListOf(choices) + ")");
  }

  // A finite number; quoted text, .nan and .inf are refused.
  bool ReadDouble(const KeyValue& kv, const std::string& path, double* value) {
    const YAML::Node& node = kv.value;
    if (node.IsNull()) return Fail(kv.line, path, "has no value (expected a number)");
    if (!node.IsScalar()) return Fail(kv.line, path, "expected a number");
    const std::string& text = node.Scalar();
    if (node.Tag() == "!") {
      return Fail(kv.line, path, "expected a number, got the quoted text " + internal::Quote(text));
    }
    for (const char* special : {".nan", ".NaN", ".NAN", ".inf", ".Inf", ".INF", "+.inf", "+.Inf",
                                "+.INF", "-.inf", "-.Inf", "-.INF"}) {
      if (text == special)
        return Fail(kv.line, path, "must be finite, got " + internal::Quote(text));
    }
    const char* begin = text.data();
    const char* end = text.data() + text.size();
    if (begin != end && *begin == '+') ++begin;  // YAML allows it, from_chars does not
    double parsed = 0.0;
    const auto [ptr, ec] = std::from_chars(begin, end, parsed);
    if (ec == std::errc::result_out_of_range)
      return Fail(kv.line, path, "out of range: " + internal::Quote(text));
    if (ec != std::errc() || ptr != end || begin == end) {
      return Fail(kv.line, path, "expected a number, got " + internal::Quote(text));
    }
    if (!std::isfinite(parsed))
      return Fail(kv.line, path, "must be finite, got " + internal::Quote(text));
    *value = parsed;
    return true;
  }

  template <typename Int>
  bool ReadInteger(const KeyValue& kv, const std::string& path, Int* value) {
    const YAML::Node& node = kv.value;
    if (node.IsNull()) return Fail(kv.line, path, "has no value (expected an integer)");
    if (!node.IsScalar() || node.Tag() == "!") return Fail(kv.line, path, "expected an integer");
    const std::string& text = node.Scalar();
    Int parsed = 0;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), parsed);
    if (ec != std::errc() || ptr != text.data() + text.size() || text.empty()) {
      return Fail(kv.line, path,
                  std::string("expected ") +
                      (std::is_signed<Int>::value ? "an integer" : "an integer >= 0") + ", got " +
                      internal::Quote(text));
    }
    *value = parsed;
    return true;
  }

  bool ReadBool(const KeyValue& kv, const std::string& path, bool* value) {
    const YAML::Node& node = kv.value;
    if (node.IsNull()) return Fail(kv.line, path, "has no value (expected true or false)");
    if (node.IsScalar() && node.Tag() != "!") {
      const std::string& t = node.Scalar();
      if (t == "true" || t == "True" || t == "TRUE" || t == "false" || t == "False" ||
          t == "FALSE") {
        *value = t[0] == 't' || t[0] == 'T';
        return true;
      }
    }
    return Fail(kv.line, path,
                "expected true or false" +
                    (node.IsScalar() ? ", got " + internal::Quote(node.Scalar()) : std::string()));
  }

  // Fails with `what` unless it is empty.
  bool Check(const std::string& what, int line, const std::string& path) {
    return what.empty() || Fail(line, path, what);
  }

  bool ReadNoise(const KeyValue& noise, CalibrationSpec* spec) {
    KeyMap keys;
    if (!ReadMap(noise, "noise", {"tension_sigma_kN", "tension_sigma_percent", "slow_error"},
                 &keys)) {
      return false;
    }
    if (const KeyValue* kv = Find(keys, "slow_error");
        kv != nullptr && !ReadSlowError(*kv, &spec->slow_error)) {
      return false;
    }
    if (const KeyValue* kv = Find(keys, "tension_sigma_kN")) {
      const std::string path = "noise.tension_sigma_kN";
      double kn = 0.0;
      if (!ReadDouble(*kv, path, &kn) ||
          !Check(CheckNoiseSigma(ModelQuantity::kTensionSigmaN, kn * kNewtonsPerKilonewton),
                 kv->line, path)) {
        return false;
      }
      spec->tension_sigma_n = kn * kNewtonsPerKilonewton;
    }
    if (const KeyValue* kv = Find(keys, "tension_sigma_percent")) {
      const std::string path = "noise.tension_sigma_percent";
      if (!ReadDouble(*kv, path, &spec->tension_sigma_percent) ||
          !Check(CheckNoiseSigma(ModelQuantity::kTensionSigmaPercent, spec->tension_sigma_percent),
                 kv->line, path)) {
        return false;
      }
    }
    if (spec->tension_sigma_n == 0.0 && spec->tension_sigma_percent == 0.0) {
      return Fail(noise.line, "noise", kBothNoiseZero);
    }
    return true;
  }

  // noise.slow_error: none, estimate, or {sigma_percent, sigma_kN, time_constant_s}, each a
  // number or "estimate" (slow_error.h).
  bool ReadSlowError(const KeyValue& kv, SlowErrorSpec* slow) {
    const std::string path = "noise.slow_error";
    *slow = SlowErrorSpec();
    if (kv.value.IsScalar()) {
      int choice = 0;
      if (!ReadChoice(kv, path, {"none", "estimate"}, &choice)) return false;
      slow->enabled = choice == 1;
      slow->estimate_amplitude = slow->estimate_time_constant = slow->enabled;
      return true;
    }
    KeyMap keys;
    if (!ReadMap(kv, path, {"sigma_percent", "sigma_kN", "time_constant_s"}, &keys)) return false;
    slow->enabled = true;
    // Each part: a number (with its check), or "estimate".
    const auto part = [&](const char* key, double to_si, bool* estimated, double* value_si,
                          const std::function<std::string(double)>& check) {
      const KeyValue* p = Find(keys, key);
      if (p == nullptr) return true;
      const std::string key_path = Join(path, key);
      if (p->value.IsScalar() && p->value.Scalar() == "estimate") {
        *estimated = true;
        return true;
      }
      double v = 0.0;
      if (!ReadDouble(*p, key_path, &v) || !Check(check(v * to_si), p->line, key_path)) {
        return false;
      }
      *value_si = v * to_si;
      return true;
    };
    bool percent_estimated = false, kn_estimated = false;
    if (!part("sigma_percent", 1.0, &percent_estimated, &slow->stated.sigma_percent,
              [](double v) { return CheckNoiseSigma(ModelQuantity::kTensionSigmaPercent, v); }) ||
        !part("sigma_kN", kNewtonsPerKilonewton, &kn_estimated, &slow->stated.sigma_n,
              [](double v) { return CheckNoiseSigma(ModelQuantity::kTensionSigmaN, v); }) ||
        !part("time_constant_s", 1.0, &slow->estimate_time_constant,
              &slow->stated.time_constant_s, CheckTimeConstant)) {
      return false;
    }
    if (percent_estimated && kn_estimated) {
      return Fail(kv.line, path,
                  "sigma_percent and sigma_kN are both \"estimate\"; estimate one of them (the "
                  "other a number, or left out)");
    }
    slow->estimate_amplitude = percent_estimated || kn_estimated;
    slow->amplitude_in_percent = !kn_estimated;
    if (Find(keys, "time_constant_s") == nullptr) {
      return Fail(kv.line, path, "time_constant_s is missing (a number of seconds, or estimate)");
    }
    if (!slow->estimate_amplitude && slow->stated.sigma_percent == 0.0 &&
        slow->stated.sigma_n == 0.0) {
      return Fail(kv.line, path,
                  "no amplitude: give sigma_percent or sigma_kN (a number, or estimate), or "
                  "write slow_error: none");
    }
    return true;
  }

  bool ReadRobustLoss(const KeyValue& loss, CalibrationSpec* spec) {
    KeyMap keys;
    if (!ReadMap(loss, "robust_loss", {"type", "scale"}, &keys)) return false;
    if (const KeyValue* kv = Find(keys, "type")) {
      int choice = 0;
      if (!ReadChoice(*kv, "robust_loss.type", {"none", "huber", "cauchy"}, &choice)) {
        return false;
      }
      const RobustLoss kLosses[] = {RobustLoss::kNone, RobustLoss::kHuber, RobustLoss::kCauchy};
      spec->robust_loss = kLosses[choice];
    }
    if (const KeyValue* kv = Find(keys, "scale")) {
      const std::string path = "robust_loss.scale";
      if (!ReadDouble(*kv, path, &spec->robust_loss_scale) ||
          !Check(CheckPositive(spec->robust_loss_scale), kv->line, path)) {
        return false;
      }
    }
    return true;
  }

  bool ReadGrossErrors(const KeyValue& gross, CalibrationSpec* spec) {
    KeyMap keys;
    if (!ReadMap(gross, "gross_errors", {"detect", "threshold_sigmas", "max_fraction"}, &keys)) {
      return false;
    }
    if (const KeyValue* kv = Find(keys, "detect")) {
      if (!ReadBool(*kv, "gross_errors.detect", &spec->detect_gross_errors)) return false;
    }
    if (const KeyValue* kv = Find(keys, "threshold_sigmas")) {
      const std::string path = "gross_errors.threshold_sigmas";
      if (!ReadDouble(*kv, path, &spec->gross_error_threshold_sigmas) ||
          !Check(CheckPositive(spec->gross_error_threshold_sigmas), kv->line, path)) {
        return false;
      }
    }
    if (const KeyValue* kv = Find(keys, "max_fraction")) {
      const std::string path = "gross_errors.max_fraction";
      if (!ReadDouble(*kv, path, &spec->max_gross_error_fraction) ||
          !Check(CheckFraction(spec->max_gross_error_fraction), kv->line, path)) {
        return false;
      }
    }
    return true;
  }

  bool ReadCrossValidation(const KeyValue& cv, CalibrationSpec* spec) {
    KeyMap keys;
    if (!ReadMap(cv, "cross_validation", {"blocks"}, &keys)) return false;
    if (const KeyValue* kv = Find(keys, "blocks")) {
      const std::string path = "cross_validation.blocks";
      if (!ReadInteger(*kv, path, &spec->cross_validation_blocks) ||
          !Check(CheckAtLeastTwo(spec->cross_validation_blocks), kv->line, path)) {
        return false;
      }
    }
    return true;
  }

  bool ReadHoldout(const KeyValue& holdout, CalibrationSpec* spec) {
    KeyMap keys;
    if (!ReadMap(holdout, "holdout", {"fraction", "seed", "blocks"}, &keys)) return false;
    if (const KeyValue* kv = Find(keys, "blocks")) {
      const std::string path = "holdout.blocks";
      if (!ReadInteger(*kv, path, &spec->holdout_blocks) ||
          !Check(CheckAtLeastTwo(spec->holdout_blocks), kv->line, path)) {
        return false;
      }
    }
    if (const KeyValue* kv = Find(keys, "fraction")) {
      const std::string path = "holdout.fraction";
      if (!ReadDouble(*kv, path, &spec->holdout_fraction) ||
          !Check(CheckHoldoutFraction(spec->holdout_fraction), kv->line, path)) {
        return false;
      }
    }
    if (const KeyValue* kv = Find(keys, "seed")) {
      if (!ReadInteger(*kv, "holdout.seed", &spec->holdout_seed)) return false;
    }
    return true;
  }

  // A list of parameter groups (`[mass_centre_m, sensor_gain]`), each with a free
  // parameter in `spec`, none twice.
  bool ReadGroupList(const KeyValue& kv, const std::string& path, const CalibrationSpec& spec,
                     std::vector<std::string>* groups) {
    if (!kv.value.IsSequence()) return Fail(kv.line, path, "expected a list of parameter groups");
    std::vector<std::string> keys;
    for (const GroupInfo& g : kGroups) keys.push_back(g.key);
    for (const YAML::Node& item : kv.value) {
      const int line = LineOf(item) > 0 ? LineOf(item) : kv.line;
      if (!item.IsScalar()) return Fail(line, path, "expected a parameter group name");
      const std::string name = item.Scalar();
      const bool parameter = std::any_of(spec.parameters.begin(), spec.parameters.end(),
                                         [&](const ParameterSpec& p) { return p.name == name; });
      if (std::find(keys.begin(), keys.end(), name) == keys.end() && !parameter) {
        return Fail(line, path,
                    "unknown parameter group " + internal::Quote(name) +
                        " (accepted: " + ListOf(keys) +
                        ", or one parameter's name, e.g. sensor_bias_kN[3])");
      }
      if (std::find(groups->begin(), groups->end(), name) != groups->end()) {
        return Fail(line, path, name + " is listed twice");
      }
      if (const std::string w = GroupWithoutFreeParameter(spec, name); !w.empty()) {
        return Fail(line, path, w);
      }
      groups->push_back(name);
    }
    return true;
  }

  bool ReadSessions(const KeyValue& sessions, CalibrationSpec* spec) {
    KeyMap keys;
    if (!ReadMap(sessions, "sessions", {"separate"}, &keys)) return false;
    if (const KeyValue* kv = Find(keys, "separate")) {
      return ReadGroupList(*kv, "sessions.separate", *spec, &spec->separate_groups);
    }
    return true;
  }

  bool ReadChangeScan(const KeyValue& scan, CalibrationSpec* spec) {
    KeyMap keys;
    if (!ReadMap(scan, "change_scan",
                 {"parameters", "min_segment_samples", "significance", "max_changes"}, &keys)) {
      return false;
    }
    if (const KeyValue* kv = Find(keys, "min_segment_samples")) {
      const std::string path = "change_scan.min_segment_samples";
      if (!ReadInteger(*kv, path, &spec->change_scan_min_segment) ||
          !Check(CheckAtLeastTwo(spec->change_scan_min_segment), kv->line, path)) {
        return false;
      }
    }
    if (const KeyValue* kv = Find(keys, "significance")) {
      const std::string path = "change_scan.significance";
      if (!ReadDouble(*kv, path, &spec->change_scan_significance) ||
          !Check(CheckSignificance(spec->change_scan_significance), kv->line, path)) {
        return false;
      }
    }
    if (const KeyValue* kv = Find(keys, "max_changes")) {
      const std::string path = "change_scan.max_changes";
      if (!ReadInteger(*kv, path, &spec->change_scan_max_changes) ||
          !Check(CheckAtLeastOne(spec->change_scan_max_changes), kv->line, path)) {
        return false;
      }
    }
    const KeyValue* kv = Find(keys, "parameters");
    if (kv == nullptr) {
      return Fail(LineOf(scan.value) > 0 ? LineOf(scan.value) : scan.line, "change_scan",
                  "needs parameters: [group, ...], the groups whose step is searched for");
    }
    return ReadGroupList(*kv, "change_scan.parameters", *spec, &spec->change_scan_groups);
  }

  bool ReadSolver(const KeyValue& solver, CalibrationSpec* spec) {
    KeyMap keys;
    if (!ReadMap(solver, "solver",
                 {"max_iterations", "function_tolerance", "gradient_tolerance",
                  "parameter_tolerance", "threads"},
                 &keys)) {
      return false;
    }
    const std::tuple<const char*, int*, std::string (*)(int)> kInts[] = {
        {"max_iterations", &spec->max_iterations, &CheckAtLeastOne},
        {"threads", &spec->num_threads, &CheckThreads}};
    for (const auto& [name, field, check] : kInts) {
      const std::string path = Join("solver", name);
      if (const KeyValue* kv = Find(keys, name)) {
        if (!ReadInteger(*kv, path, field) || !Check(check(*field), kv->line, path)) {
          return false;
        }
      }
    }
    const std::pair<const char*, double*> kDoubles[] = {
        {"function_tolerance", &spec->function_tolerance},
        {"gradient_tolerance", &spec->gradient_tolerance},
        {"parameter_tolerance", &spec->parameter_tolerance}};
    for (const auto& [name, field] : kDoubles) {
      const std::string path = Join("solver", name);
      if (const KeyValue* kv = Find(keys, name)) {
        if (!ReadDouble(*kv, path, field) || !Check(CheckPositive(*field), kv->line, path)) {
          return false;
        }
      }
    }
    return true;
  }

  // The entry keys free / initial / prior out of `keys` (already read as a mapping).
  bool ReadEntryKeys(const KeyMap& keys, const GroupInfo& g, const std::string& path,
                     EntryText* entry) {
    if (const KeyValue* kv = Find(keys, "free")) {
      bool free = false;
      if (!ReadBool(*kv, Join(path, "free"), &free)) return false;
      entry->free = free;
    }
    if (const KeyValue* kv = Find(keys, "initial")) {
      const std::string initial_path = Join(path, "initial");
      double initial = 0.0;
      if (!ReadDouble(*kv, initial_path, &initial) ||
          !Check(CheckInitial(g.kind, initial * g.to_si), kv->line, initial_path)) {
        return false;
      }
      entry->initial = initial;
    }
    if (const KeyValue* kv = Find(keys, "prior")) {
      const std::string prior_path = Join(path, "prior");
      KeyMap prior;
      if (kv->value.IsNull())
        return Fail(kv->line, prior_path, "has no value (expected {mean, sigma})");
      if (!ReadMap(*kv, prior_path, {"mean", "sigma"}, &prior)) return false;
      double mean = 0.0;
      double sigma = 0.0;
      for (const char* name : {"mean", "sigma"}) {
        if (Find(prior, name) == nullptr) {
          return Fail(kv->line, Join(prior_path, name),
                      "missing (a prior needs both mean and sigma)");
        }
      }
      const KeyValue& mean_kv = prior.at("mean");
      const KeyValue& sigma_kv = prior.at("sigma");
      const std::string mean_path = Join(prior_path, "mean");
      const std::string sigma_path = Join(prior_path, "sigma");
      if (!ReadDouble(mean_kv, mean_path, &mean) ||
          !Check(CheckPriorMean(g.kind, mean * g.to_si), mean_kv.line, mean_path) ||
          !ReadDouble(sigma_kv, sigma_path, &sigma) ||
          !Check(CheckPriorSigma(g.kind, sigma * g.to_si), sigma_kv.line, sigma_path)) {
        return false;
      }
      entry->prior = std::make_pair(mean, sigma);
    }
    return true;
  }

  // A plain entry: {free, initial, prior}, all optional.
  bool ReadEntry(const YAML::Node& node, int line, const GroupInfo& g, const std::string& path,
                 EntryText* entry) {
    KeyMap keys;
    return ReadMap(node, line, path, {"free", "initial", "prior"}, &keys) &&
           ReadEntryKeys(keys, g, path, entry);
  }

  // {x: entry, y: entry, z: entry}, each optional; a named axis yields a parameter.
  bool ReadAxes(const YAML::Node& node, int line, const GroupInfo& g, int index,
                const std::string& path, std::vector<ParameterSpec>* out) {
    KeyMap keys;
    if (!ReadMap(node, line, path, {"x", "y", "z"}, &keys)) return false;
    for (int c = 0; c < 3; ++c) {
      const std::string axis(1, kAxes[c]);
      if (const KeyValue* kv = Find(keys, axis)) {
        EntryText entry;
        if (!ReadEntry(kv->value, kv->line, g, Join(path, axis), &entry)) return false;
        out->push_back(MakeParameter(g, index, c, entry));
      }
    }
    return true;
  }

  bool ReadPerCableGroup(const KeyValue& group, const GroupInfo& g, const std::string& path,
                         std::vector<ParameterSpec>* out) {
    KeyMap keys;
    if (!ReadMap(group, path, {"mode", "free", "initial", "prior", "cables"}, &keys)) {
      return false;
    }
    EntryText base;
    if (!ReadEntryKeys(keys, g, path, &base)) return false;
    int mode = 0;  // 0 common, 1 per_cable
    if (const KeyValue* kv = Find(keys, "mode")) {
      if (!ReadChoice(*kv, Join(path, "mode"), {"common", "per_cable"}, &mode)) return false;
    }
    const KeyValue* cables = Find(keys, "cables");
    if (mode == 0) {
      if (cables != nullptr) {
        return Fail(cables->line, Join(path, "cables"),
                    "only allowed with mode: per_cable (this group is common to all cables)");
      }
      out->push_back(MakeParameter(g, -1, -1, base));
      return true;
    }
    std::array<EntryText, kNumCables> per_cable;
    per_cable.fill(base);
    if (cables != nullptr) {
      const std::string list_path = Join(path, "cables");
      const YAML::Node& list = cables->value;
      if (!list.IsSequence() || list.size() != kNumCables) {
        return Fail(cables->line, list_path,
                    "expected a list of exactly 6 entries (cable 1 first), got " +
                        (list.IsSequence() ? std::to_string(list.size()) + " entries"
                                           : std::string("no list")));
      }
      for (size_t i = 0; i < kNumCables; ++i) {
        const int line = LineOf(list[i]) > 0 ? LineOf(list[i]) : cables->line;
        EntryText over;
        if (!ReadEntry(list[i], line, g, Element(list_path, i), &over)) return false;
        per_cable[i] = Override(base, over);
      }
    }
    for (int i = 0; i < kNumCables; ++i) out->push_back(MakeParameter(g, i, -1, per_cable[i]));
    return true;
  }

  // {all: entry} or a list of {x, y, z} maps, one per anchor point / tower.
  bool ReadOffsets(const KeyValue& group, const GroupInfo& g, const std::string& path,
                   std::vector<ParameterSpec>* out) {
    const bool anchors = g.kind == ParameterKind::kAnchorOffset;
    const int count = anchors ? num_anchor_points_ : kNumCables;
    const std::string what = anchors ? "anchor points" : "towers";
    if (group.value.IsSequence()) {
      const YAML::Node& list = group.value;
      if (static_cast<int>(list.size()) > count) {
        return Fail(group.line, path,
                    "has " + std::to_string(list.size()) + " entries but the model has " +
                        std::to_string(count) + " " + what);
      }
      for (size_t j = 0; j < list.size(); ++j) {
        const int line = LineOf(list[j]) > 0 ? LineOf(list[j]) : group.line;
        if (!ReadAxes(list[j], line, g, static_cast<int>(j), Element(path, j), out)) {
          return false;
        }
      }
      return true;
    }
    if (!group.value.IsNull() && !group.value.IsMap()) {
      return Fail(group.line, path,
                  "expected {all: entry} or a list of {x, y, z} entries, one per " +
                      what.substr(0, what.size() - 1));
    }
    KeyMap keys;
    if (!ReadMap(group, path, {"all"}, &keys)) return false;
    if (const KeyValue* kv = Find(keys, "all")) {
      EntryText entry;
      if (!ReadEntry(kv->value, kv->line, g, Join(path, "all"), &entry)) return false;
      if (count < 1) return Fail(kv->line, Join(path, "all"), "the model has no " + what);
      for (int j = 0; j < count; ++j) {
        for (int c = 0; c < 3; ++c) out->push_back(MakeParameter(g, j, c, entry));
      }
    }
    return true;
  }

  // {all: entry} (every attachment of the group's kind on every cable), or a list of
  // entries each naming its `cable` (1..6) and `attachment` (1.., its position in the
  // model's cables[cable - 1].attachments).
  bool ReadAttachments(const KeyValue& group, const GroupInfo& g, const std::string& path,
                       std::vector<ParameterSpec>* out) {
    const AttachmentKind kind = AttachmentKindOf(g.kind);
    const char* what = kind == AttachmentKind::kPointMass ? "point mass" : "added density";
    if (group.value.IsSequence()) {
      const YAML::Node& list = group.value;
      std::vector<ParameterSpec> listed;
      for (size_t k = 0; k < list.size(); ++k) {
        const std::string item = Element(path, k);
        const int line = LineOf(list[k]) > 0 ? LineOf(list[k]) : group.line;
        KeyMap keys;
        if (!ReadMap(list[k], line, item, {"cable", "attachment", "free", "initial", "prior"},
                     &keys)) {
          return false;
        }
        int cable = 0, attachment = 0;
        for (const auto& [name, field] :
             {std::pair{"cable", &cable}, std::pair{"attachment", &attachment}}) {
          const KeyValue* kv = Find(keys, name);
          if (kv == nullptr) {
            return Fail(line, Join(item, name),
                        "missing (each entry names its cable and attachment)");
          }
          if (!ReadInteger(*kv, Join(item, name), field)) return false;
        }
        if (cable < 1 || cable > kNumCables) {
          return Fail(keys.at("cable").line, Join(item, "cable"), "must be a cable 1..6");
        }
        const std::vector<AttachmentKind>& on = attachments_[cable - 1];
        if (attachment < 1 || attachment > static_cast<int>(on.size()) ||
            on[attachment - 1] != kind) {
          return Fail(keys.at("attachment").line, Join(item, "attachment"),
                      "cable " + std::to_string(cable) + " has no " + what + " at position " +
                          std::to_string(attachment) + " of its attachments in the model (" +
                          std::to_string(on.size()) + " attachments; give the model with --model)");
        }
        EntryText entry;
        if (!ReadEntryKeys(keys, g, item, &entry)) return false;
        const ParameterSpec p = MakeParameter(g, cable - 1, attachment - 1, entry);
        for (const ParameterSpec& q : listed) {
          if (q.index == p.index && q.component == p.component) {
            return Fail(line, item, p.name + " is listed twice");
          }
        }
        listed.push_back(p);
      }
      // Canonical order: cable by cable, attachment by attachment.
      std::sort(listed.begin(), listed.end(), [](const ParameterSpec& a, const ParameterSpec& b) {
        return std::make_pair(a.index, a.component) < std::make_pair(b.index, b.component);
      });
      out->insert(out->end(), listed.begin(), listed.end());
      return true;
    }
    if (!group.value.IsNull() && !group.value.IsMap()) {
      return Fail(group.line, path,
                  "expected {all: entry} or a list of entries with cable and attachment");
    }
    KeyMap keys;
    if (!ReadMap(group, path, {"all"}, &keys)) return false;
    if (const KeyValue* kv = Find(keys, "all")) {
      EntryText entry;
      if (!ReadEntry(kv->value, kv->line, g, Join(path, "all"), &entry)) return false;
      const size_t before = out->size();
      for (int i = 0; i < kNumCables; ++i) {
        for (size_t j = 0; j < attachments_[i].size(); ++j) {
          if (attachments_[i][j] == kind) {
            out->push_back(MakeParameter(g, i, static_cast<int>(j), entry));
          }
        }
      }
      if (out->size() == before) {
        return Fail(kv->line, Join(path, "all"),
                    std::string("the model's cables carry no ") + what +
                        " (cables[i].attachments in the model file, given with --model)");
      }
    }
    return true;
  }

  bool ReadParameters(const KeyValue& parameters, CalibrationSpec* spec) {
    std::vector<std::string> accepted;
    for (const GroupInfo& g : kGroups) accepted.push_back(g.key);
    KeyMap keys;
    if (!ReadMap(parameters.value, parameters.line, "parameters", accepted, &keys,
                 "unknown parameter (accepted: ")) {
      return false;
    }
    std::vector<ParameterSpec> out;
    for (const GroupInfo& g : kGroups) {  // canonical order
      const KeyValue* kv = Find(keys, g.key);
      if (kv == nullptr) continue;
      const std::string path = Join("parameters", g.key);
      bool ok = true;
      if (g.kind == ParameterKind::kMassCentre) {
        ok = ReadAxes(kv->value, kv->line, g, -1, path, &out);
      } else if (g.kind == ParameterKind::kCabinMass) {
        EntryText entry;
        ok = ReadEntry(kv->value, kv->line, g, path, &entry);
        if (ok) out.push_back(MakeParameter(g, -1, -1, entry));
      } else if (IsPerCableCapable(g.kind)) {
        ok = ReadPerCableGroup(*kv, g, path, &out);
      } else if (IsAttachment(g.kind)) {
        ok = ReadAttachments(*kv, g, path, &out);
      } else {
        ok = ReadOffsets(*kv, g, path, &out);
      }
      if (!ok) return false;
    }
    spec->parameters = std::move(out);
    return true;
  }

  std::string source_;
  int num_anchor_points_;
  AttachmentShape attachments_;
  std::string error_;
};

// ---------------------------------------------------------------------------------------
// Writer.

// {free: ..., initial: ..., prior: {mean: ..., sigma: ...}} in the group's file unit.
std::string EntryYaml(const ParameterSpec& p, const GroupInfo& g) {
  std::string s = std::string("free: ") + (p.free ? "true" : "false");
  if (p.has_initial) s += ", initial: " + NumInUnit(p.initial_si, g.to_si);
  if (p.has_prior) {
    s += ", prior: {mean: " + NumInUnit(p.prior_mean_si, g.to_si) +
         ", sigma: " + NumInUnit(p.prior_sigma_si, g.to_si) + "}";
  }
  return "{" + s + "}";
}

// The named axes of one point (index ignored for the mass centre), "x: {...}" each.
std::vector<std::string> AxisLines(const CalibrationSpec& spec, const GroupInfo& g, int index) {
  std::vector<std::string> lines;
  for (int c = 0; c < 3; ++c) {
    for (const ParameterSpec& p : spec.parameters) {
      if (p.kind == g.kind && p.component == c &&
          (g.kind == ParameterKind::kMassCentre || p.index == index)) {
        lines.push_back(std::string(1, kAxes[c]) + ": " + EntryYaml(p, g));
        break;
      }
    }
  }
  return lines;
}

}  // namespace

namespace {

// The slow error's parts: stated ones plausible, an amplitude and a time constant.
std::string SlowErrorProblem(const SlowErrorSpec& slow) {
  if (!slow.enabled) return "";
  std::string why;
  if (!slow.stated.IsValid(&why)) return why;
  if (!(slow.estimate_amplitude && slow.amplitude_in_percent)) {
    why = CheckNoiseSigma(ModelQuantity::kTensionSigmaPercent, slow.stated.sigma_percent);
    if (!why.empty()) return "sigma_percent: " + why;
  }
  if (!(slow.estimate_amplitude && !slow.amplitude_in_percent)) {
    why = CheckNoiseSigma(ModelQuantity::kTensionSigmaN, slow.stated.sigma_n);
    if (!why.empty()) return "sigma_n: " + why;
  }
  if (!slow.estimate_time_constant) {
    why = CheckTimeConstant(slow.stated.time_constant_s);
    if (!why.empty()) return "time_constant_s: " + why;
  }
  if (!slow.estimate_amplitude && slow.stated.sigma_percent == 0.0 && slow.stated.sigma_n == 0.0) {
    return "no amplitude (sigma_percent and sigma_n are 0 and none is estimated)";
  }
  return "";
}

// The first problem with the spec's options (everything but the parameters), as
// "field: why"; empty when there is none.
std::string OptionsProblem(const CalibrationSpec& s) {
  if (!IsKnownMethod(s.forward_model)) return "forward_model: unknown statics method";
  const bool known_loss = s.robust_loss == RobustLoss::kNone ||
                          s.robust_loss == RobustLoss::kHuber ||
                          s.robust_loss == RobustLoss::kCauchy;
  // In the order of the spec file's documentation; each check gives "" or why.
  const std::pair<const char*, std::string> checks[] = {
      {"tension_sigma_n", CheckNoiseSigma(ModelQuantity::kTensionSigmaN, s.tension_sigma_n)},
      {"tension_sigma_percent",
       CheckNoiseSigma(ModelQuantity::kTensionSigmaPercent, s.tension_sigma_percent)},
      {"noise", s.tension_sigma_n == 0.0 && s.tension_sigma_percent == 0.0 ? kBothNoiseZero : ""},
      {"slow_error", SlowErrorProblem(s.slow_error)},
      {"robust_loss", known_loss ? "" : "unknown loss"},
      {"robust_loss_scale", CheckPositive(s.robust_loss_scale)},
      {"holdout_fraction", CheckHoldoutFraction(s.holdout_fraction)},
      {"holdout_blocks", CheckAtLeastTwo(s.holdout_blocks)},
      {"cross_validation_blocks", CheckAtLeastTwo(s.cross_validation_blocks)},
      {"gross_error_threshold_sigmas", CheckPositive(s.gross_error_threshold_sigmas)},
      {"max_gross_error_fraction", CheckFraction(s.max_gross_error_fraction)},
      {"max_iterations", CheckAtLeastOne(s.max_iterations)},
      {"num_threads", CheckThreads(s.num_threads)},
      {"function_tolerance", CheckPositive(s.function_tolerance)},
      {"gradient_tolerance", CheckPositive(s.gradient_tolerance)},
      {"parameter_tolerance", CheckPositive(s.parameter_tolerance)},
  };
  for (const auto& [name, why] : checks) {
    if (!why.empty()) return std::string(name) + ": " + why;
  }
  return "";
}

// The first problem with one listed parameter on its own (kind, index, component, initial
// value, prior), as "label: why"; empty when there is none.
std::string ParameterProblem(const ParameterSpec& p, const std::string& label) {
  if (InfoOf(p.kind) == nullptr) return label + ": unknown parameter kind";
  if (p.name.empty()) return label + ": has no name";
  if (IsVector(p.kind) && (p.component < 0 || p.component > 2)) {
    return label + ": component must be 0, 1 or 2 (x, y, z)";
  }
  if (IsPerCableCapable(p.kind) && (p.index < -1 || p.index >= kNumCables)) {
    return label + ": index must be -1 (all cables) or a cable 0..5";
  }
  if (p.kind == ParameterKind::kAnchorOffset && p.index < 0) {
    return label + ": index must be an anchor point >= 0";
  }
  if (p.kind == ParameterKind::kTowerOffset && (p.index < 0 || p.index >= kNumCables)) {
    return label + ": index must be a tower 0..5";
  }
  if (IsAttachment(p.kind) && (p.index < 0 || p.index >= kNumCables || p.component < 0 ||
                               p.component >= kMaxAttachmentsPerCable)) {
    return label + ": index must be a cable 0..5 and component an attachment 0..7";
  }
  if (!(std::isfinite(p.to_si) && p.to_si > 0.0)) return label + ": to_si must be > 0";
  if (p.has_initial) {
    if (const std::string w = CheckInitial(p.kind, p.initial_si); !w.empty()) {
      return label + ".initial: " + w;
    }
  }
  if (p.has_prior) {
    if (const std::string w = CheckPriorMean(p.kind, p.prior_mean_si); !w.empty()) {
      return label + ".prior.mean: " + w;
    }
    if (const std::string w = CheckPriorSigma(p.kind, p.prior_sigma_si); !w.empty()) {
      return label + ".prior.sigma: " + w;
    }
  }
  return "";
}

}  // namespace

bool CalibrationSpec::IsValid(std::string* error) const {
  auto fail = [error](const std::string& what) {
    if (error != nullptr) *error = what;
    return false;
  };
  if (const std::string w = OptionsProblem(*this); !w.empty()) return fail(w);
  for (const auto* list : {&separate_groups, &change_scan_groups}) {
    for (const std::string& group : *list) {
      const std::string w = GroupWithoutFreeParameter(*this, group);
      if (!w.empty())
        return fail((list == &separate_groups ? "sessions.separate: " : "change_scan: ") + w);
    }
  }
  if (!change_scan_groups.empty()) {
    if (const std::string w = CheckAtLeastTwo(change_scan_min_segment); !w.empty()) {
      return fail("change_scan_min_segment: " + w);
    }
    if (const std::string w = CheckSignificance(change_scan_significance); !w.empty()) {
      return fail("change_scan_significance: " + w);
    }
    if (const std::string w = CheckAtLeastOne(change_scan_max_changes); !w.empty()) {
      return fail("change_scan_max_changes: " + w);
    }
  }
  // Across parameters: none listed twice, as (kind, index, component) with the fields that
  // do not apply set to -1, and no group both common and per cable.
  std::set<std::tuple<int, int, int, int>> seen;
  std::set<int> kinds_common, kinds_per_cable;
  for (size_t k = 0; k < parameters.size(); ++k) {
    const ParameterSpec& p = parameters[k];
    const std::string label = p.name.empty() ? "parameters[" + std::to_string(k) + "]" : p.name;
    if (const std::string w = ParameterProblem(p, label); !w.empty()) return fail(w);
    const bool indexed =
        p.kind != ParameterKind::kMassCentre && p.kind != ParameterKind::kCabinMass;
    const auto key =
        std::make_tuple(static_cast<int>(p.kind), indexed ? p.index : -1,
                        IsVector(p.kind) || IsAttachment(p.kind) ? p.component : -1, p.session);
    if (!seen.insert(key).second) return fail(label + ": listed twice");
    if (IsPerCableCapable(p.kind)) {
      (p.index < 0 ? kinds_common : kinds_per_cable).insert(static_cast<int>(p.kind));
      if (kinds_common.count(static_cast<int>(p.kind)) != 0 &&
          kinds_per_cable.count(static_cast<int>(p.kind)) != 0) {
        return fail(label + ": " + InfoOf(p.kind)->key +
                    " is listed both for all cables (common) and per cable; choose one mode");
      }
    }
  }
  return true;
}

namespace {

bool ParseSpec(const std::string& text, const std::string& source_name, int num_anchor_points,
               const AttachmentShape& attachments, CalibrationSpec* spec, std::string* error) {
  Reader reader(source_name, num_anchor_points, attachments);
  CalibrationSpec parsed;
  try {
    const internal::YamlDocuments documents = internal::LoadYamlDocuments(text);
    if (documents.count > 1) {
      reader.Fail(documents.second_line, kRootPath, "only one YAML document is allowed");
    } else if (documents.first.IsNull() ||  // empty file: all defaults
               reader.ReadRoot(documents.first, &parsed)) {
      // The reader checked every value where it read it; this only guards the two
      // against drifting apart.
      std::string why;
      if (!parsed.IsValid(&why)) reader.Fail(0, kRootPath, why);
    }
  } catch (const YAML::Exception& e) {
    reader.Fail(e.mark.line < 0 ? 0 : e.mark.line + 1, "YAML syntax error", e.msg);
  } catch (const std::exception& e) {
    reader.Fail(0, kRootPath, std::string("cannot read: ") + e.what());
  }
  if (!reader.error().empty()) {
    if (error != nullptr) *error = reader.error();
    return false;
  }
  *spec = std::move(parsed);
  return true;
}

bool LoadSpec(const std::string& path, int num_anchor_points, const AttachmentShape& attachments,
              CalibrationSpec* spec, std::string* error) {
  std::string text;
  std::string message;
  if (!internal::ReadRegularFile(path, kMaxSpecFileBytes, "calibration spec", &text, &message)) {
    if (error != nullptr) *error = message;
    return false;
  }
  return ParseSpec(text, path, num_anchor_points, attachments, spec, error);
}

}  // namespace

bool ParseCalibrationSpecYaml(const std::string& text, const std::string& source_name,
                              const CableRobot& model, CalibrationSpec* spec, std::string* error) {
  return ParseSpec(text, source_name, static_cast<int>(model.anchor_points_cabin_m.size()),
                   ShapeOf(model), spec, error);
}

bool ParseCalibrationSpecYaml(const std::string& text, const std::string& source_name,
                              int num_anchor_points, CalibrationSpec* spec, std::string* error) {
  return ParseSpec(text, source_name, num_anchor_points, AttachmentShape(), spec, error);
}

bool LoadCalibrationSpec(const std::string& path, const CableRobot& model, CalibrationSpec* spec,
                         std::string* error) {
  return LoadSpec(path, static_cast<int>(model.anchor_points_cabin_m.size()), ShapeOf(model), spec,
                  error);
}

bool LoadCalibrationSpec(const std::string& path, int num_anchor_points, CalibrationSpec* spec,
                         std::string* error) {
  return LoadSpec(path, num_anchor_points, AttachmentShape(), spec, error);
}

namespace {

// The spec's sessions and change_scan blocks ("" when it has neither).
std::string SessionsYaml(const CalibrationSpec& spec) {
  const auto list = [](const std::vector<std::string>& groups) {
    std::string text;
    for (const std::string& g : groups) text += (text.empty() ? "" : ", ") + g;
    return "[" + text + "]";
  };
  std::ostringstream out;
  if (!spec.separate_groups.empty()) {
    out << "sessions: {separate: " << list(spec.separate_groups) << "}\n";
  }
  if (!spec.change_scan_groups.empty()) {
    out << "change_scan: {parameters: " << list(spec.change_scan_groups)
        << ", min_segment_samples: " << spec.change_scan_min_segment
        << ", significance: " << Num(spec.change_scan_significance)
        << ", max_changes: " << spec.change_scan_max_changes << "}\n";
  }
  return out.str();
}

std::string SlowErrorYaml(const SlowErrorSpec& slow) {
  if (!slow.enabled) return "none";
  const auto part = [](bool estimated, const std::string& value) {
    return estimated ? std::string("estimate") : value;
  };
  const bool percent = slow.estimate_amplitude && slow.amplitude_in_percent;
  const bool kn = slow.estimate_amplitude && !slow.amplitude_in_percent;
  return "{sigma_percent: " + part(percent, Num(slow.stated.sigma_percent)) +
         ", sigma_kN: " + part(kn, NumInUnit(slow.stated.sigma_n, kNewtonsPerKilonewton)) +
         ", time_constant_s: " +
         part(slow.estimate_time_constant, Num(slow.stated.time_constant_s)) + "}";
}

}  // namespace

SlowErrorProcess SlowErrorSpec::Initial() const {
  if (!enabled || estimates_any()) return SlowErrorProcess();
  return stated;
}

std::string CalibrationSpecToYaml(const CalibrationSpec& spec) {
  std::ostringstream out;
  out << "format: " << kFormatName << "\n";
  out << "forward_model: " << StaticsMethodName(spec.forward_model) << "\n";
  out << "noise: {tension_sigma_kN: " << NumInUnit(spec.tension_sigma_n, kNewtonsPerKilonewton)
      << ", tension_sigma_percent: " << Num(spec.tension_sigma_percent)
      << ", slow_error: " << SlowErrorYaml(spec.slow_error) << "}\n";
  const char* loss = RobustLossName(spec.robust_loss);
  out << "robust_loss: {type: " << (loss != nullptr ? loss : "unknown")
      << ", scale: " << Num(spec.robust_loss_scale) << "}\n";
  out << "gross_errors: {detect: " << (spec.detect_gross_errors ? "true" : "false")
      << ", threshold_sigmas: " << Num(spec.gross_error_threshold_sigmas)
      << ", max_fraction: " << Num(spec.max_gross_error_fraction) << "}\n";
  out << "holdout: {fraction: " << Num(spec.holdout_fraction) << ", seed: " << spec.holdout_seed
      << ", blocks: " << spec.holdout_blocks << "}\n";
  out << "cross_validation: {blocks: " << spec.cross_validation_blocks << "}\n";
  out << "attitude: " << (spec.use_planned_attitude ? "planned" : "measured") << "\n";
  out << "solver: {max_iterations: " << spec.max_iterations
      << ", function_tolerance: " << Num(spec.function_tolerance)
      << ", gradient_tolerance: " << Num(spec.gradient_tolerance)
      << ", parameter_tolerance: " << Num(spec.parameter_tolerance)
      << ", threads: " << spec.num_threads << "}\n";
  if (spec.parameters.empty()) {
    out << "parameters: {}\n";
    return out.str();
  }
  out << "parameters:\n";
  for (const GroupInfo& g : kGroups) {
    std::vector<const ParameterSpec*> group;
    for (const ParameterSpec& p : spec.parameters) {
      if (p.kind == g.kind) group.push_back(&p);
    }
    if (group.empty()) continue;
    out << "  " << g.key << ":";
    if (g.kind == ParameterKind::kMassCentre) {
      out << "\n";
      for (const std::string& line : AxisLines(spec, g, -1)) out << "    " << line << "\n";
    } else if (g.kind == ParameterKind::kCabinMass) {
      out << " " << EntryYaml(*group.front(), g) << "\n";
    } else if (IsPerCableCapable(g.kind)) {
      if (group.front()->index < 0) {
        const std::string entry = EntryYaml(*group.front(), g);
        out << " {mode: common, " << entry.substr(1) << "\n";
      } else {
        // Cables not listed are written fixed without a value: the model's, as before.
        out << "\n    mode: per_cable\n    cables:\n";
        for (int i = 0; i < kNumCables; ++i) {
          ParameterSpec fixed;
          const ParameterSpec* p = &fixed;
          for (const ParameterSpec* q : group) {
            if (q->index == i) p = q;
          }
          out << "      - " << EntryYaml(*p, g) << "  # cable " << i + 1 << "\n";
        }
      }
    } else if (IsAttachment(g.kind)) {  // one entry per listed attachment
      out << "\n";
      for (const ParameterSpec* p : group) {
        const std::string entry = EntryYaml(*p, g);
        out << "    - {cable: " << p->index + 1 << ", attachment: " << p->component + 1 << ", "
            << entry.substr(1) << "\n";
      }
    } else {  // offsets: one list element per point up to the last one listed
      int last = -1;
      for (const ParameterSpec* p : group) last = std::max(last, p->index);
      out << "\n";
      const char* what = g.kind == ParameterKind::kAnchorOffset ? "anchor point" : "tower";
      for (int j = 0; j <= last; ++j) {
        const std::vector<std::string> lines = AxisLines(spec, g, j);
        const std::string comment = std::string("  # ") + what + " " + std::to_string(j + 1);
        if (lines.empty()) out << "    - {}" << comment << "\n";
        for (size_t k = 0; k < lines.size(); ++k) {
          out << (k == 0 ? "    - " : "      ") << lines[k] << (k == 0 ? comment : "") << "\n";
        }
      }
    }
  }
  out << SessionsYaml(spec);
  return out.str();
}

std::vector<ParameterSpec> AllModelParameters(int num_anchor_points) {
  std::vector<ParameterSpec> all;
  const EntryText fixed;
  for (const GroupInfo& g : kGroups) {
    if (g.kind == ParameterKind::kMassCentre) {
      for (int c = 0; c < 3; ++c) all.push_back(MakeParameter(g, -1, c, fixed));
    } else if (g.kind == ParameterKind::kCabinMass) {
      all.push_back(MakeParameter(g, -1, -1, fixed));
    } else if (IsPerCableCapable(g.kind)) {
      for (int i = -1; i < kNumCables; ++i) all.push_back(MakeParameter(g, i, -1, fixed));
    } else {
      if (IsAttachment(g.kind)) continue;  // none without a model (the overload below)
      const int count = g.kind == ParameterKind::kAnchorOffset ? num_anchor_points : kNumCables;
      for (int j = 0; j < count; ++j) {
        for (int c = 0; c < 3; ++c) all.push_back(MakeParameter(g, j, c, fixed));
      }
    }
  }
  return all;
}

std::vector<ParameterSpec> AllModelParameters(const CableRobot& model) {
  std::vector<ParameterSpec> all =
      AllModelParameters(static_cast<int>(model.anchor_points_cabin_m.size()));
  const EntryText fixed;
  for (const GroupInfo& g : kGroups) {
    if (!IsAttachment(g.kind)) continue;
    for (int i = 0; i < kNumCables; ++i) {
      const std::vector<CableAttachment>& on = model.cables[i].attachments;
      for (size_t j = 0; j < on.size(); ++j) {
        if (on[j].kind == AttachmentKindOf(g.kind)) {
          all.push_back(MakeParameter(g, i, static_cast<int>(j), fixed));
        }
      }
    }
  }
  return all;
}

bool ParameterFitsModel(const ParameterSpec& p, const CableRobot& model, std::string* error) {
  auto fail = [&](const std::string& why) {
    if (error != nullptr) *error = p.name + ": " + why;
    return false;
  };
  if (p.kind == ParameterKind::kAnchorOffset &&
      p.index >= static_cast<int>(model.anchor_points_cabin_m.size())) {
    return fail("the model has " + std::to_string(model.anchor_points_cabin_m.size()) +
                " anchor points");
  }
  if (IsAttachment(p.kind)) {
    const bool on_cable = p.index >= 0 && p.index < kNumCables && p.component >= 0 &&
                          p.component < static_cast<int>(model.cables[p.index].attachments.size());
    if (!on_cable ||
        model.cables[p.index].attachments[p.component].kind != AttachmentKindOf(p.kind)) {
      return fail(std::string("the model has no ") +
                  (p.kind == ParameterKind::kAttachmentMass ? "point mass" : "added density") +
                  " there (cables[i].attachments in the model file)");
    }
  }
  return true;
}

bool SameParameter(const ParameterSpec& a, const ParameterSpec& b) {
  if (a.kind != b.kind) return false;
  switch (a.kind) {
    case ParameterKind::kMassCentre:
      return a.component == b.component;
    case ParameterKind::kCabinMass:
      return true;
    case ParameterKind::kAnchorOffset:
    case ParameterKind::kTowerOffset:
    case ParameterKind::kAttachmentMass:
    case ParameterKind::kAttachmentDensity:
      return a.index == b.index && a.component == b.component;
    default:
      return a.index == b.index;
  }
}

const char* ParameterGroupName(ParameterKind kind) {
  const GroupInfo* g = InfoOf(kind);
  return g != nullptr ? g->key : "unknown";
}

const char* RobustLossName(RobustLoss loss) {
  switch (loss) {
    case RobustLoss::kNone:
      return "none";
    case RobustLoss::kHuber:
      return "huber";
    case RobustLoss::kCauchy:
      return "cauchy";
  }
  return "none";
}

}  // namespace fastcal
