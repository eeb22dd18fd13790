// The calibration spec's rules, shared by its reader (calibration_spec_reader.cc), its
// checks and writer (calibration_spec.cc): the parameter groups in canonical order with
// their keys and units, the checks of each value (one set, so that a spec built in code
// and a spec read from a file are held to the same rules), and the exact number text of
// the writer. Private to lib/src/calibration.
#ifndef FASTCAL_SRC_CALIBRATION_CALIBRATION_SPEC_RULES_H_
#define FASTCAL_SRC_CALIBRATION_CALIBRATION_SPEC_RULES_H_

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/internal/units.h"
#include "fastcal/model_plausibility.h"
#include "fastcal/parameter_table.h"
#include "fastcal/statics.h"

namespace fastcal::spec_rules {

inline constexpr char kFormatName[] = "fastcal-calibration-spec-1";
inline constexpr char kRootPath[] = "(top level)";
inline constexpr char kAxes[] = "xyz";

// The parameter groups' facts (key, unit, shape) are the table of kinds:
// parameter_table.h, in canonical order (the order of ParameterKind).

inline constexpr char kMovingPartsKey[] = "moving_parts";
inline constexpr char kMeasuredFrameKey[] = "measured_frame";

// "measured_frame.offset_m.x".
std::string MeasuredOffsetName(int component);

// "moving_parts.NAME.first_moment_kg_m.x", "moving_parts.NAME.mass_kg".
std::string PartParameterName(const std::string& part, ParameterKind kind, int component);
// The part's name in such a parameter name ("" if it is not one).
std::string PartOfParameterName(const std::string& name);

// What the model's cables carry, as the spec reader needs it: each cable's attachment kinds.
using AttachmentShape = std::array<std::vector<AttachmentKind>, kNumCables>;

// What the spec reader needs of the model: what its groups may name.
struct ModelShape {
  int num_anchor_points = 3;
  AttachmentShape attachments;
  std::vector<std::string> parts;  // the moving parts, by name
  bool measured_frame = false;     // cabin.measured_frame declared
};

inline constexpr char kBothNoiseZero[] =
    "tension_sigma_kN and tension_sigma_percent are both 0 (the residuals could not be "
    "weighted)";

// An entry as written in the file; fields not given stay empty, so that a per-cable
// entry can override its group field by field.
struct EntryText {
  std::optional<bool> free;
  std::optional<double> initial;                   // file unit
  std::optional<std::pair<double, double>> prior;  // mean, sigma; file unit
};

AttachmentKind AttachmentKindOf(ParameterKind kind);

AttachmentShape ShapeOf(const CableRobot& model);

// "mass_centre_m.x", "cabin_mass_kg", "ea_n[3]", "anchor_offset_m[2].z",
// "attachment_mass_kg[3][1]" (1-based).
std::string ParameterName(const ParameterKindInfo& g, int index, int component);

// ---------------------------------------------------------------------------------------
// Checks shared by the reader and CalibrationSpec::IsValid. Each returns what is wrong,
// or an empty string.

// "" for a value within the plausible range of its kind (plausibility.h), else why not.
std::string CheckPlausible(ParameterKind kind, double value_si);

std::string CheckInitial(ParameterKind kind, double initial_si);

std::string CheckPriorMean(ParameterKind kind, double mean);

// A prior's sigma: > 0, and not wider than the parameter's plausible range (a sigma of
// 2000 on sensor_bias_kN is 2000 N written as kN).
//
// Nor narrower than kTightestPriorFraction of that range (issue 29: a sigma of 1e-200
// made the fit's weights infinite, NaN in the fit and Ceres' dumps on stderr): a prior
// that tight is the parameter held fixed, which the spec says with free: false.
std::string CheckPriorSigma(ParameterKind kind, double sigma_si);

// The noise's sigmas: >= 0 and plausible (a tension sigma of 3000 kN is 3000 N).
// A part that is not 0 (none) must be at least what a sensor could resolve (issue 29: a
// tension sigma of 1e-160 kN made the weights infinite and the fit NaN).
std::string CheckNoiseSigma(ModelQuantity quantity, double value_si);

// A slow error's time constant: > 0 and shorter than a year (a longer memory is a
// constant offset: the sensors' biases).
std::string CheckTimeConstant(double value_s);

std::string CheckPositive(double value);

// The lengths' sigma: > 0 when given (leave it out for no lengths) and plausible.
std::string CheckLengthSigma(double value_m);

// Lengths in the fit need exact's s0 (aas's are not solved in a fit), and a free or
// consider length_offset_m needs the lengths in the fit.
std::string LengthsProblem(const CalibrationSpec& s);

std::string CheckHoldoutFraction(double fraction);
std::string CheckAtLeastOne(int value);
std::string CheckThreads(int value);
std::string CheckAtLeastTwo(int value);

// The change scan's family-wise false-alarm probability: strictly between 0 and 0.5
// (its critical values are tabulated down to 1e-4: change_scan.cc).
std::string CheckSignificance(double p);

// A group (or one parameter, by its name) named by sessions.separate or
// change_scan.parameters must have a free parameter: only free parameters can differ
// between sessions or step.
std::string GroupWithoutFreeParameter(const CalibrationSpec& spec, const std::string& group);

std::string CheckFraction(double fraction);

bool IsKnownMethod(StaticsMethod method);

// ---------------------------------------------------------------------------------------
// Number text.

// A value stored in SI, as text in a unit `to_si` times larger: the shortest text t with
// parse(t) * to_si == si when there is one, so that writing and reading back is exact.
// For values the reader produced (si = file value * to_si) si / to_si already is such a
// t; the search of the neighbours is a guard for values set in code.
std::string NumInUnit(double si, double to_si);

ParameterSpec MakeParameter(const ParameterKindInfo& g, int index, int component,
                            const EntryText& e);

}  // namespace fastcal::spec_rules

namespace fastcal {
// The spec's reader and checks (the only includers: this header is private to
// lib/src/calibration) read the rules as their own names, as when they were one file.
using internal::kNPerKn;
using spec_rules::AttachmentKindOf;
using spec_rules::AttachmentShape;
using spec_rules::CheckAtLeastOne;
using spec_rules::CheckAtLeastTwo;
using spec_rules::CheckFraction;
using spec_rules::CheckHoldoutFraction;
using spec_rules::CheckInitial;
using spec_rules::CheckLengthSigma;
using spec_rules::CheckNoiseSigma;
using spec_rules::CheckPositive;
using spec_rules::CheckPriorMean;
using spec_rules::CheckPriorSigma;
using spec_rules::CheckSignificance;
using spec_rules::CheckThreads;
using spec_rules::CheckTimeConstant;
using spec_rules::EntryText;
using spec_rules::GroupWithoutFreeParameter;
using spec_rules::IsKnownMethod;
using spec_rules::kAxes;
using spec_rules::kBothNoiseZero;
using spec_rules::kFormatName;
using spec_rules::kMeasuredFrameKey;
using spec_rules::kMovingPartsKey;
using spec_rules::kRootPath;
using spec_rules::LengthsProblem;
using spec_rules::MakeParameter;
using spec_rules::MeasuredOffsetName;
using spec_rules::ModelShape;
using spec_rules::NumInUnit;
using spec_rules::PartOfParameterName;
using spec_rules::PartParameterName;
using spec_rules::ShapeOf;
}  // namespace fastcal

#endif  // FASTCAL_SRC_CALIBRATION_CALIBRATION_SPEC_RULES_H_
