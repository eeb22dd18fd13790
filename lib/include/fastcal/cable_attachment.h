// What a cable carries besides its own weight: sensors, connectors and clamps (point
// masses), and power and signal lines hung along part of it (added weight per length).
//
// The paper (Sect. 5) names them as a cause of its remaining misfit: "many wires and
// sensors are added to the cables, so that the cables are not of the uniform mass assumed
// by theory". Positions are unstretched arc lengths s from the cable's lower (cabin) end:
// an attachment is clamped to the cable, so it keeps its s when the cable's unstretched
// length changes with the pose. The cable's tension sensor sits at s = 0, below every
// attachment. The statics treat such a cable as a chain of uniform elastic catenaries
// (catenary_chain.h; docs/model.md, "Cables as built").
#ifndef FASTCAL_CABLE_ATTACHMENT_H_
#define FASTCAL_CABLE_ATTACHMENT_H_

#include <string>

namespace fastcal {

// Attachments one cable may carry. The statics keep them in fixed-size arrays (no
// allocation per solve); a model with more is refused by CableRobot::IsValid.
inline constexpr int kMaxAttachmentsPerCable = 8;

enum class AttachmentKind {
  kPointMass,     // mass_kg at at_m
  kAddedDensity,  // added_density_kg_per_m over [from_m, to_m]
};

struct CableAttachment {
  AttachmentKind kind = AttachmentKind::kPointMass;
  // kPointMass: unstretched arc length from the lower end (m), >= 0. At 0 the mass hangs
  // just above the sensor: the cabin carries it, the sensor does not read it.
  double at_m = 0.0;
  double mass_kg = 0.0;  // >= 0
  // kAddedDensity: weight per unstretched metre added over [from_m, to_m] (m), with
  // 0 <= from_m < to_m. Lines that add weight but carry no load: EA is unchanged. Where
  // to_m lies beyond the cable's unstretched length at a pose, the lines cover the rest
  // of the cable (the remainder rests on the tower's pulley).
  double from_m = 0.0;
  double to_m = 0.0;
  double added_density_kg_per_m = 0.0;  // >= 0

  // The arc length at which the attachment starts: at_m or from_m. An attachment that
  // starts at or beyond a cable's unstretched length is not on the cable: the statics
  // refuse such a pose (StaticsStatus::kAttachmentBeyondCable).
  double StartM() const { return kind == AttachmentKind::kPointMass ? at_m : from_m; }
  // The value a calibration estimates: mass_kg or added_density_kg_per_m.
  double Value() const {
    return kind == AttachmentKind::kPointMass ? mass_kg : added_density_kg_per_m;
  }
  void SetValue(double v) {
    (kind == AttachmentKind::kPointMass ? mass_kg : added_density_kg_per_m) = v;
  }
  // Its added weight (kg): the mass, or the density times the range's length.
  double TotalMassKg() const {
    return kind == AttachmentKind::kPointMass ? mass_kg : added_density_kg_per_m * (to_m - from_m);
  }

  // Checks the rules above; on failure names the offending key relative to the
  // attachment ("at_m", "to_m", ...) and says why in *error.
  bool IsValid(std::string* error) const;
};

}  // namespace fastcal

#endif  // FASTCAL_CABLE_ATTACHMENT_H_
