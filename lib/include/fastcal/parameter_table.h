// The kinds of calibration parameter, each declared once: the enum and one row per kind
// of what every part of fastcal asks of it (docs/architecture.md, "Adding a parameter").
//
// A row holds the kind's facts, not its physics: the spec's key and the file's unit (SI
// value = file value * to_si), how its parameters are indexed (ParameterShape), its
// plausible range (plausibility.h's ModelQuantity) and sign rule, whether it moves the
// forces (of the statics) or only the readings, the largest sigma with which it counts
// as determined (CalibrationOptions), and the survey design's margin for it. Its
// physics (where its value enters the statics, its Jacobian column) is in
// internal/calibration_model.h and calibration_model.cc, the only switches over kinds.
#ifndef FASTCAL_PARAMETER_TABLE_H_
#define FASTCAL_PARAMETER_TABLE_H_

#include <array>

#include "fastcal/plausibility.h"

namespace fastcal {

struct CalibrationOptions;  // calibration.h

enum class ParameterKind {
  kMassCentre,  // component = axis 0..2
  kCabinMass,
  kLinearDensity,  // cable = 0..5, or -1 for common
  kEa,             // cable = 0..5, or -1 for common
  kAnchorOffset,   // index = anchor point, component = axis
  kTowerOffset,    // index = cable/tower, component = axis
  kSensorGain,     // cable = 0..5, or -1 for common
  kSensorBias,     // cable = 0..5, or -1 for common
  // index = cable 0..5, component = the attachment's 0-based position in the model's
  // cables[index].attachments (of the matching kind).
  kAttachmentMass,
  kAttachmentDensity,
  kLengthOffset,  // cable = 0..5, or -1 for common
  // The cabin's moving parts (moving_parts.h): index = the part's position in the model's
  // cabin.moving_parts; named moving_parts.NAME.first_moment_kg_m.x and
  // moving_parts.NAME.mass_kg.
  kPartFirstMoment,  // component = axis 0..2 of the part's frame
  kPartMass,
  // The measured frame's point (measured_frame.h), component = axis 0..2 of its part's
  // frame; named measured_frame.offset_m.x.
  kMeasuredOffset,
};
// The last kind: readers of stored parameters (track's fold tasks) accept kinds up to it,
// so a kind added above is not refused as corrupt.
inline constexpr ParameterKind kLastParameterKind = ParameterKind::kMeasuredOffset;
inline constexpr int kNumParameterKinds = static_cast<int>(kLastParameterKind) + 1;

// How a kind's parameters are indexed (ParameterSpec::index and ::component) and named.
enum class ParameterShape {
  kOne,         // one value: cabin_mass_kg
  kAxes,        // component = axis: mass_centre_m.x, measured_frame.offset_m.x
  kPerCable,    // index = cable, or -1 for one common to all: ea_n, ea_n[3]
  kPointAxes,   // index = anchor point or tower, component = axis: anchor_offset_m[2].z
  kAttachment,  // index = cable, component = its attachment: attachment_mass_kg[3][1]
  kPartAxes,    // index = moving part, component = axis of its frame
  kPart,        // index = moving part
};

// How the largest sigma with which a parameter counts as determined scales.
enum class DeterminedScale {
  kAbsolute,  // the option itself, in the parameter's SI unit
  kOfValue,   // the option times |initial value|
  // The option, or just above a prior's sigma when that is wider: a kind seen only at
  // second order (moving parts) or through the geometry (the measured point) is bounded
  // by its prior.
  kAbsoluteOrPrior,
};

// The survey design's margin of a free parameter without a prior (DesignOptions::range_*).
enum class DesignMargin {
  kNone,        // of the readings: no range to hold the poses over
  kMassCentre,  // range_mass_centre_m
  kOffset,      // range_offset_m
  kRelative,    // range_relative * |value|
};

struct ParameterKindInfo {
  ParameterKind kind;
  const char* key;   // key under the spec's `parameters:` and stem of the names
  const char* unit;  // unit of the values in files and reports
  double to_si;      // SI value = file value * to_si
  ParameterShape shape;
  ModelQuantity quantity;  // its plausible range (plausibility.h)
  // What its value is, when it must be > 0 ("a mass"); null when any sign is plausible.
  const char* positive;
  bool non_negative;    // must be >= 0 (an attachment adds weight)
  bool moves_forces;    // of the statics; false for the readings' (gains, biases, zeros)
  bool moves_geometry;  // moves a cable's ends (its derivative needs the towers' columns)
  double CalibrationOptions::*max_sigma;
  DeterminedScale determined_scale;
  DesignMargin design_margin;
};

// Every kind's row, in canonical order (the order of ParameterKind, the spec's order).
const std::array<ParameterKindInfo, kNumParameterKinds>& ParameterKinds();

// The row of `kind`; null for a kind outside the enum (a spec built in code from a bad cast).
const ParameterKindInfo* FindParameterKind(ParameterKind kind);

// The row of `kind`, which must be a kind of the enum.
const ParameterKindInfo& KindInfo(ParameterKind kind);

// Shapes as questions.
bool IsPerCableCapable(ParameterKind kind);  // one for all cables or one per cable
bool IsVector(ParameterKind kind);           // has an axis component
bool IsAttachment(ParameterKind kind);
bool IsPart(ParameterKind kind);  // a moving part's (one key in the spec for both)

// The largest sigma with which a parameter of `kind` counts as determined: the row's
// rule over `options`, at its initial value and with its prior's sigma (0 without one).
double MaxSigmaOf(ParameterKind kind, double initial, double prior_sigma,
                  const CalibrationOptions& options);

}  // namespace fastcal

#endif  // FASTCAL_PARAMETER_TABLE_H_
