// The calibration spec: its checks (CalibrationSpec::IsValid), its writer
// (CalibrationSpecToYaml, which the reader reads back to the same spec) and the lists of
// the model's parameters (format: docs/calibration.md). The reader is
// calibration_spec_reader.cc; the rules both share are calibration_spec_rules.h.
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

#include "calibration/calibration_spec_rules.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/number_text.h"
#include "fastcal/internal/quote.h"
#include "fastcal/model_plausibility.h"
#include "fastcal/plausibility.h"
#include "util/yaml_document.h"

namespace fastcal {

using internal::ShortestNumber;

namespace {

// ---------------------------------------------------------------------------------------
// Writer.

// {free: ..., initial: ..., prior: {mean: ..., sigma: ...}} in the group's file unit.
std::string EntryYaml(const ParameterSpec& p, const ParameterKindInfo& g) {
  std::string s = std::string("free: ") + (p.free ? "true" : "false");
  if (p.has_initial) s += ", initial: " + NumInUnit(p.initial_si, g.to_si);
  if (p.has_prior) {
    s += ", prior: {mean: " + NumInUnit(p.prior_mean_si, g.to_si) +
         ", sigma: " + NumInUnit(p.prior_sigma_si, g.to_si) + "}";
  }
  return "{" + s + "}";
}

// The named axes of one point (index ignored for the mass centre), "x: {...}" each.
std::vector<std::string> AxisLines(const CalibrationSpec& spec, const ParameterKindInfo& g,
                                   int index) {
  std::vector<std::string> lines;
  for (int c = 0; c < 3; ++c) {
    for (const ParameterSpec& p : spec.parameters) {
      if (p.kind == g.kind && p.component == c &&
          (g.shape == ParameterShape::kAxes || p.index == index)) {
        lines.push_back(std::string(1, kAxes[c]) + ": " + EntryYaml(p, g));
        break;
      }
    }
  }
  return lines;
}

// parameters.moving_parts: each part's first moment's axes and mass, parts in the order
// of their first parameter.
std::string MovingPartsYaml(const CalibrationSpec& spec) {
  std::vector<std::pair<int, std::string>> parts;  // index, name
  for (const ParameterSpec& p : spec.parameters) {
    if (!IsPart(p.kind)) continue;
    bool seen = false;
    for (const auto& [index, name] : parts) seen = seen || index == p.index;
    if (!seen) parts.emplace_back(p.index, PartOfParameterName(p.name));
  }
  std::ostringstream out;
  out << "  " << kMovingPartsKey << ":\n";
  for (const auto& [index, name] : parts) {
    out << "    " << name << ":\n";
    const ParameterKindInfo& moment = *FindParameterKind(ParameterKind::kPartFirstMoment);
    const std::vector<std::string> lines = AxisLines(spec, moment, index);
    if (!lines.empty()) out << "      first_moment_kg_m:\n";
    for (const std::string& line : lines) out << "        " << line << "\n";
    for (const ParameterSpec& p : spec.parameters) {
      if (p.kind == ParameterKind::kPartMass && p.index == index) {
        out << "      mass_kg: " << EntryYaml(p, *FindParameterKind(p.kind)) << "\n";
      }
    }
  }
  return out.str();
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
      {"length_sigma_m", s.length_sigma_m == 0.0 ? "" : CheckLengthSigma(s.length_sigma_m)},
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
  if (FindParameterKind(p.kind) == nullptr) return label + ": unknown parameter kind";
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
  if (IsPart(p.kind) && (p.index < 0 || p.index >= kMaxMovingParts)) {
    return label + ": index must be a moving part 0.." + std::to_string(kMaxMovingParts - 1);
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
  if (const std::string w = LengthsProblem(*this); !w.empty()) return fail(w);
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
    const ParameterShape shape = KindInfo(p.kind).shape;
    const bool indexed = shape != ParameterShape::kAxes && shape != ParameterShape::kOne;
    const auto key =
        std::make_tuple(static_cast<int>(p.kind), indexed ? p.index : -1,
                        IsVector(p.kind) || IsAttachment(p.kind) ? p.component : -1, p.session);
    if (!seen.insert(key).second) return fail(label + ": listed twice");
    if (IsPerCableCapable(p.kind)) {
      (p.index < 0 ? kinds_common : kinds_per_cable).insert(static_cast<int>(p.kind));
      if (kinds_common.count(static_cast<int>(p.kind)) != 0 &&
          kinds_per_cable.count(static_cast<int>(p.kind)) != 0) {
        return fail(label + ": " + FindParameterKind(p.kind)->key +
                    " is listed both for all cables (common) and per cable; choose one mode");
      }
    }
  }
  return true;
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
        << ", significance: " << ShortestNumber(spec.change_scan_significance)
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
  return "{sigma_percent: " + part(percent, ShortestNumber(slow.stated.sigma_percent)) +
         ", sigma_kN: " + part(kn, NumInUnit(slow.stated.sigma_n, kNPerKn)) +
         ", time_constant_s: " +
         part(slow.estimate_time_constant, ShortestNumber(slow.stated.time_constant_s)) + "}";
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
  out << "noise: {tension_sigma_kN: " << NumInUnit(spec.tension_sigma_n, kNPerKn)
      << ", tension_sigma_percent: " << ShortestNumber(spec.tension_sigma_percent)
      << ", slow_error: " << SlowErrorYaml(spec.slow_error);
  if (spec.UsesLengths()) out << ", length_sigma_m: " << ShortestNumber(spec.length_sigma_m);
  out << "}\n";
  const char* loss = RobustLossName(spec.robust_loss);
  out << "robust_loss: {type: " << (loss != nullptr ? loss : "unknown")
      << ", scale: " << ShortestNumber(spec.robust_loss_scale) << "}\n";
  out << "gross_errors: {detect: " << (spec.detect_gross_errors ? "true" : "false")
      << ", threshold_sigmas: " << ShortestNumber(spec.gross_error_threshold_sigmas)
      << ", max_fraction: " << ShortestNumber(spec.max_gross_error_fraction) << "}\n";
  out << "holdout: {fraction: " << ShortestNumber(spec.holdout_fraction)
      << ", seed: " << spec.holdout_seed << ", blocks: " << spec.holdout_blocks << "}\n";
  out << "cross_validation: {blocks: " << spec.cross_validation_blocks << "}\n";
  out << "attitude: " << (spec.use_planned_attitude ? "planned" : "measured") << "\n";
  out << "solver: {max_iterations: " << spec.max_iterations
      << ", function_tolerance: " << ShortestNumber(spec.function_tolerance)
      << ", gradient_tolerance: " << ShortestNumber(spec.gradient_tolerance)
      << ", parameter_tolerance: " << ShortestNumber(spec.parameter_tolerance)
      << ", threads: " << spec.num_threads << "}\n";
  if (spec.parameters.empty()) {
    out << "parameters: {}\n";
    return out.str();
  }
  out << "parameters:\n";
  for (const ParameterKindInfo& g : ParameterKinds()) {
    std::vector<const ParameterSpec*> group;
    for (const ParameterSpec& p : spec.parameters) {
      if (p.kind == g.kind) group.push_back(&p);
    }
    if (group.empty() || g.kind == ParameterKind::kPartMass) continue;
    if (g.kind == ParameterKind::kPartFirstMoment) {
      out << MovingPartsYaml(spec);
      continue;
    }
    if (g.kind == ParameterKind::kMeasuredOffset) {
      out << "  " << kMeasuredFrameKey << ":\n    offset_m:\n";
      for (const std::string& line : AxisLines(spec, g, -1)) out << "      " << line << "\n";
      continue;
    }
    out << "  " << g.key << ":";
    if (g.shape == ParameterShape::kAxes) {
      out << "\n";
      for (const std::string& line : AxisLines(spec, g, -1)) out << "    " << line << "\n";
    } else if (g.shape == ParameterShape::kOne) {
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
  for (const ParameterKindInfo& g : ParameterKinds()) {
    // None without a model (the overload below).
    if (IsAttachment(g.kind) || IsPart(g.kind) || g.kind == ParameterKind::kMeasuredOffset) {
      continue;
    }
    if (g.shape == ParameterShape::kAxes) {
      for (int c = 0; c < 3; ++c) all.push_back(MakeParameter(g, -1, c, fixed));
    } else if (g.shape == ParameterShape::kOne) {
      all.push_back(MakeParameter(g, -1, -1, fixed));
    } else if (IsPerCableCapable(g.kind)) {
      for (int i = -1; i < kNumCables; ++i) all.push_back(MakeParameter(g, i, -1, fixed));
    } else {
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
  // The moving parts' first moments, and the masses of parts whose origin moves.
  const std::vector<MovingPart>& parts = model.moving_parts.parts;
  for (size_t k = 0; k < parts.size(); ++k) {
    const int part = static_cast<int>(k);
    for (int c = 0; c < 3; ++c) {
      ParameterSpec p =
          MakeParameter(*FindParameterKind(ParameterKind::kPartFirstMoment), part, c, fixed);
      p.name = PartParameterName(parts[k].name, p.kind, c);
      all.push_back(p);
    }
    if (model.moving_parts.Translates(part)) {
      ParameterSpec p =
          MakeParameter(*FindParameterKind(ParameterKind::kPartMass), part, -1, fixed);
      p.name = PartParameterName(parts[k].name, p.kind, -1);
      all.push_back(p);
    }
  }
  if (model.measured_frame.has_value()) {  // the measured point's offset
    for (int c = 0; c < 3; ++c) {
      ParameterSpec p =
          MakeParameter(*FindParameterKind(ParameterKind::kMeasuredOffset), -1, c, fixed);
      p.name = MeasuredOffsetName(c);
      all.push_back(p);
    }
  }
  for (const ParameterKindInfo& g : ParameterKinds()) {
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
  if (IsPart(p.kind)) {
    const auto& parts = model.moving_parts.parts;
    if (p.index < 0 || p.index >= static_cast<int>(parts.size()) ||
        PartOfParameterName(p.name) != parts[p.index].name) {
      return fail("the model has no such moving part (cabin.moving_parts in the model file)");
    }
  }
  if (p.kind == ParameterKind::kMeasuredOffset && !model.measured_frame.has_value()) {
    return fail("the model declares no measured frame (cabin.measured_frame in the model file)");
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
  const ParameterKindInfo* row = FindParameterKind(a.kind);
  if (row == nullptr) return a.index == b.index;
  switch (row->shape) {
    case ParameterShape::kOne:
      return true;
    case ParameterShape::kAxes:
      return a.component == b.component;
    case ParameterShape::kPerCable:
    case ParameterShape::kPart:
      return a.index == b.index;
    case ParameterShape::kPointAxes:
    case ParameterShape::kAttachment:
    case ParameterShape::kPartAxes:
      return a.index == b.index && a.component == b.component;
  }
  return false;
}

const char* ParameterGroupName(ParameterKind kind) {
  const ParameterKindInfo* g = FindParameterKind(kind);
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
