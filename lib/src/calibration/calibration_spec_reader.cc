// The calibration spec's YAML reader (format: docs/calibration.md).
//
// The spec is edited by hand, so the reader is strict in the way the model reader is
// (cable_robot_yaml.cc): unknown keys and unknown parameter names are errors, and every
// error reads "<file>:<line>: <key path>: <what>". Parameters come out in the canonical
// order of calibration_spec.h, which is the order of ParameterKind, whatever the order of
// the keys in the file. Values in the file are in the unit the key names (kN for the
// sensor bias and the absolute tension noise); they are stored in SI. The checks of
// CalibrationSpec::IsValid and of the reader share one set of functions, so a spec built
// in code and a spec read from a file are held to the same rules.
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

#include "calibration/calibration_spec_rules.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/quote.h"
#include "fastcal/model_plausibility.h"
#include "fastcal/plausibility.h"
#include "util/yaml_document.h"

namespace fastcal {
namespace {

using internal::LineOf;

std::string Join(const std::string& parent, const std::string& key) {
  return parent.empty() || parent == kRootPath ? key : parent + "." + key;
}
// Key paths number list elements from 1, like the parameter names.
std::string Element(const std::string& parent, size_t i) {
  return parent + "[" + std::to_string(i + 1) + "]";
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

EntryText Override(const EntryText& base, const EntryText& over) {
  EntryText e = base;
  if (over.free) e.free = over.free;
  if (over.initial) e.initial = over.initial;
  if (over.prior) e.prior = over.prior;
  return e;
}

class Reader : public internal::YamlErrorRecorder {
 public:
  Reader(const std::string& source, const ModelShape& model)
      : YamlErrorRecorder(source),
        num_anchor_points_(model.num_anchor_points),
        attachments_(model.attachments),
        parts_(model.parts),
        measured_frame_(model.measured_frame) {}

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
    if (!ReadMap(noise, "noise",
                 {"tension_sigma_kN", "tension_sigma_percent", "slow_error", "length_sigma_m"},
                 &keys)) {
      return false;
    }
    if (const KeyValue* kv = Find(keys, "length_sigma_m")) {
      const std::string path = "noise.length_sigma_m";
      if (!ReadDouble(*kv, path, &spec->length_sigma_m) ||
          !Check(CheckLengthSigma(spec->length_sigma_m), kv->line, path)) {
        return false;
      }
    }
    if (const KeyValue* kv = Find(keys, "slow_error");
        kv != nullptr && !ReadSlowError(*kv, &spec->slow_error)) {
      return false;
    }
    if (const KeyValue* kv = Find(keys, "tension_sigma_kN")) {
      const std::string path = "noise.tension_sigma_kN";
      double kn = 0.0;
      if (!ReadDouble(*kv, path, &kn) ||
          !Check(CheckNoiseSigma(ModelQuantity::kTensionSigmaN, kn * kNPerKn), kv->line, path)) {
        return false;
      }
      spec->tension_sigma_n = kn * kNPerKn;
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
        !part("sigma_kN", kNPerKn, &kn_estimated, &slow->stated.sigma_n,
              [](double v) { return CheckNoiseSigma(ModelQuantity::kTensionSigmaN, v); }) ||
        !part("time_constant_s", 1.0, &slow->estimate_time_constant, &slow->stated.time_constant_s,
              CheckTimeConstant)) {
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
    for (const ParameterKindInfo& g : ParameterKinds()) keys.push_back(g.key);
    for (const YAML::Node& item : kv.value) {
      const int line = LineOf(item) > 0 ? LineOf(item) : kv.line;
      if (!item.IsScalar()) return Fail(line, path, "expected a parameter group name");
      const std::string name = item.Scalar();
      const bool parameter = std::any_of(spec.parameters.begin(), spec.parameters.end(),
                                         [&](const ParameterSpec& p) { return p.name == name; });
      if (std::find(keys.begin(), keys.end(), name) == keys.end() && !parameter) {
        return Fail(line, path,
                    "unknown parameter group " + internal::Quote(name) + " (accepted: " +
                        ListOf(keys) + ", or one parameter's name, e.g. sensor_bias_kN[3])");
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
  bool ReadEntryKeys(const KeyMap& keys, const ParameterKindInfo& g, const std::string& path,
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
  bool ReadEntry(const YAML::Node& node, int line, const ParameterKindInfo& g,
                 const std::string& path, EntryText* entry) {
    KeyMap keys;
    return ReadMap(node, line, path, {"free", "initial", "prior"}, &keys) &&
           ReadEntryKeys(keys, g, path, entry);
  }

  // {x: entry, y: entry, z: entry}, each optional; a named axis yields a parameter.
  bool ReadAxes(const YAML::Node& node, int line, const ParameterKindInfo& g, int index,
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

  bool ReadPerCableGroup(const KeyValue& group, const ParameterKindInfo& g, const std::string& path,
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
  bool ReadOffsets(const KeyValue& group, const ParameterKindInfo& g, const std::string& path,
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
  bool ReadAttachments(const KeyValue& group, const ParameterKindInfo& g, const std::string& path,
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

  // moving_parts: {NAME: {first_moment_kg_m: {x, y, z}, mass_kg: entry}}, NAME a part of
  // the model's cabin.moving_parts.
  bool ReadMovingParts(const KeyValue& group, const std::string& path,
                       std::vector<ParameterSpec>* out) {
    if (parts_.empty()) {
      return Fail(group.line, path,
                  "the model has no moving parts (cabin.moving_parts in the model file, given "
                  "with --model)");
    }
    KeyMap keys;
    if (!ReadMap(group.value, group.line, path, parts_, &keys,
                 "not a moving part of the model (its parts: ")) {
      return false;
    }
    for (size_t k = 0; k < parts_.size(); ++k) {
      const KeyValue* part = Find(keys, parts_[k]);
      if (part == nullptr) continue;
      const std::string part_path = Join(path, parts_[k]);
      KeyMap fields;
      if (!ReadMap(*part, part_path, {"first_moment_kg_m", "mass_kg"}, &fields)) return false;
      const size_t before = out->size();
      if (const KeyValue* kv = Find(fields, "first_moment_kg_m")) {
        const ParameterKindInfo& g = *FindParameterKind(ParameterKind::kPartFirstMoment);
        if (!ReadAxes(kv->value, kv->line, g, static_cast<int>(k),
                      Join(part_path, "first_moment_kg_m"), out)) {
          return false;
        }
      }
      if (const KeyValue* kv = Find(fields, "mass_kg")) {
        const ParameterKindInfo& g = *FindParameterKind(ParameterKind::kPartMass);
        EntryText entry;
        if (!ReadEntry(kv->value, kv->line, g, Join(part_path, "mass_kg"), &entry)) return false;
        out->push_back(MakeParameter(g, static_cast<int>(k), -1, entry));
      }
      for (size_t j = before; j < out->size(); ++j) {
        (*out)[j].name = PartParameterName(parts_[k], (*out)[j].kind, (*out)[j].component);
      }
    }
    return true;
  }

  // measured_frame: {offset_m: {x, y, z}} (measured_frame.h), for a model that declares
  // cabin.measured_frame.
  bool ReadMeasuredFrame(const KeyValue& group, const std::string& path,
                         std::vector<ParameterSpec>* out) {
    if (!measured_frame_) {
      return Fail(group.line, path,
                  "the model declares no measured frame (cabin.measured_frame in the model "
                  "file, given with --model: whose pose the data's x_m..z_m and attitude give)");
    }
    KeyMap keys;
    if (!ReadMap(group, path, {"offset_m"}, &keys)) return false;
    const KeyValue* kv = Find(keys, "offset_m");
    if (kv == nullptr) return true;
    const size_t before = out->size();
    if (!ReadAxes(kv->value, kv->line, *FindParameterKind(ParameterKind::kMeasuredOffset), -1,
                  Join(path, "offset_m"), out)) {
      return false;
    }
    for (size_t j = before; j < out->size(); ++j) {
      (*out)[j].name = MeasuredOffsetName((*out)[j].component);
    }
    return true;
  }

  bool ReadParameters(const KeyValue& parameters, CalibrationSpec* spec) {
    std::vector<std::string> accepted;
    for (const ParameterKindInfo& g : ParameterKinds()) {
      if (g.kind != ParameterKind::kPartMass) accepted.push_back(g.key);  // one key for both
    }
    KeyMap keys;
    if (!ReadMap(parameters.value, parameters.line, "parameters", accepted, &keys,
                 "unknown parameter (accepted: ")) {
      return false;
    }
    std::vector<ParameterSpec> out;
    for (const ParameterKindInfo& g : ParameterKinds()) {  // canonical order
      const KeyValue* kv = Find(keys, g.key);
      if (kv == nullptr) continue;
      const std::string path = Join("parameters", g.key);
      bool ok = true;
      if (g.kind == ParameterKind::kPartMass) continue;  // read with the first moments
      if (g.kind == ParameterKind::kPartFirstMoment) {
        ok = ReadMovingParts(*kv, path, &out);
      } else if (g.kind == ParameterKind::kMeasuredOffset) {
        ok = ReadMeasuredFrame(*kv, path, &out);
      } else if (g.shape == ParameterShape::kAxes) {
        ok = ReadAxes(kv->value, kv->line, g, -1, path, &out);
      } else if (g.shape == ParameterShape::kOne) {
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

  int num_anchor_points_;
  AttachmentShape attachments_;
  std::vector<std::string> parts_;  // the model's moving parts, by name
  bool measured_frame_;             // the model declares cabin.measured_frame
};
}  // namespace

namespace {

bool ParseSpec(const std::string& text, const std::string& source_name, const ModelShape& model,
               CalibrationSpec* spec, std::string* error) {
  Reader reader(source_name, model);
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

bool LoadSpec(const std::string& path, const ModelShape& model, CalibrationSpec* spec,
              std::string* error) {
  std::string text;
  std::string message;
  if (!internal::ReadRegularFile(path, kMaxSpecFileBytes, "calibration spec", &text, &message)) {
    if (error != nullptr) *error = message;
    return false;
  }
  return ParseSpec(text, path, model, spec, error);
}

ModelShape ShapeOfModel(const CableRobot& model) {
  ModelShape shape;
  shape.num_anchor_points = static_cast<int>(model.anchor_points_cabin_m.size());
  shape.attachments = ShapeOf(model);
  for (const MovingPart& p : model.moving_parts.parts) shape.parts.push_back(p.name);
  shape.measured_frame = model.measured_frame.has_value();
  return shape;
}

ModelShape ShapeOfAnchors(int num_anchor_points) {
  ModelShape shape;
  shape.num_anchor_points = num_anchor_points;
  return shape;
}

}  // namespace

bool ParseCalibrationSpecYaml(const std::string& text, const std::string& source_name,
                              const CableRobot& model, CalibrationSpec* spec, std::string* error) {
  return ParseSpec(text, source_name, ShapeOfModel(model), spec, error);
}

bool ParseCalibrationSpecYaml(const std::string& text, const std::string& source_name,
                              int num_anchor_points, CalibrationSpec* spec, std::string* error) {
  return ParseSpec(text, source_name, ShapeOfAnchors(num_anchor_points), spec, error);
}

bool LoadCalibrationSpec(const std::string& path, const CableRobot& model, CalibrationSpec* spec,
                         std::string* error) {
  return LoadSpec(path, ShapeOfModel(model), spec, error);
}

bool LoadCalibrationSpec(const std::string& path, int num_anchor_points, CalibrationSpec* spec,
                         std::string* error) {
  return LoadSpec(path, ShapeOfAnchors(num_anchor_points), spec, error);
}

}  // namespace fastcal
