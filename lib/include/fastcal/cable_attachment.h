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
#include <utility>
#include <vector>

namespace fastcal {

// Attachments one cable may carry. The statics keep them in fixed-size arrays (no
// allocation per solve); a model with more is refused by CableRobot::IsValid.
inline constexpr int kMaxAttachmentsPerCable = 8;

enum class AttachmentKind {
  kPointMass,     // mass_kg at at_m
  kAddedDensity,  // added_density_kg_per_m over [from_m, to_m]
};

struct CableAttachment {
  static CableAttachment PointMass(double at_m, double mass_kg) {
    CableAttachment a;
    a.at_m = at_m;
    a.mass_kg = mass_kg;
    return a;
  }
  static CableAttachment AddedDensity(double from_m, double to_m, double density_kg_per_m) {
    CableAttachment a;
    a.kind = AttachmentKind::kAddedDensity;
    a.from_m = from_m;
    a.to_m = to_m;
    a.added_density_kg_per_m = density_kg_per_m;
    return a;
  }

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

  // The model file's keys of an attachment of `kind` (docs/model-format.md) with the
  // fields they fill: at_m, mass_kg; or from_m, to_m, added_density_kg_per_m.
  std::vector<std::pair<const char*, double*>> Fields() {
    if (kind == AttachmentKind::kPointMass) return {{"at_m", &at_m}, {"mass_kg", &mass_kg}};
    return {
        {"from_m", &from_m}, {"to_m", &to_m}, {"added_density_kg_per_m", &added_density_kg_per_m}};
  }
  // What an attachment of `kind` must give, for messages.
  static const char* KeysText(AttachmentKind kind) {
    return kind == AttachmentKind::kPointMass
               ? "a point mass has exactly the keys at_m and mass_kg"
               : "added weight has exactly the keys from_m, to_m and added_density_kg_per_m";
  }

  // Checks the rules above; on failure names the offending key relative to the
  // attachment ("at_m", "to_m", ...) and says why in *error.
  bool IsValid(std::string* error) const;
};

}  // namespace fastcal

#endif  // FASTCAL_CABLE_ATTACHMENT_H_
