// Plausibility limits: values no file or flag from the real FAST can hold. A value beyond
// them is a corrupt export, a unit mix-up or a typo (1e30 kN, a position below the
// reflector, 1e300 degrees), and is refused where it is read, naming the file, line and
// column or the flag (docs/data-format.md, "Limits"), before it can break a fit or a
// report's tables. They are deliberately wide: a reading that is wrong but possible (a
// sensor glitch of a few times the normal tension, a dropout to 0 kN) is not refused
// here; the calibration's robust screen flags it as a gross error (gross_errors.h).
//
// The geometry is the nominal FAST layout of docs/model.md, held here as plain numbers
// so that the limits do not depend on a model file: towers on a ring of 300 m radius
// with tops at 270 m, the reflector a sphere of 300 m radius about (0, 0, 300) m with an
// aperture of 500 m, the global origin at its lowest point, z up.
#ifndef FASTCAL_PLAUSIBILITY_H_
#define FASTCAL_PLAUSIBILITY_H_

#include <Eigen/Core>
#include <string>

namespace fastcal {

struct PlausibilityLimits {
  // Largest tension reading, N. A FAST cable breaks well below 10 MN and works near 200 kN;
  // 5000 kN is 25 times that. Readings must also be >= 0 (0 is a possible dropout).
  double max_tension_n = 5.0e6;
  // Largest horizontal distance of the cabin-frame origin from the z axis, m: the ring of
  // towers (300 m) plus 50 m.
  double max_horizontal_radius_m = 350.0;
  // Highest z of the cabin-frame origin, m: the tower tops (270 m) plus 30 m.
  double max_height_m = 300.0;
  // The nominal reflector: a sphere of this radius about (0, 0, radius), cut at the
  // aperture radius; outside the aperture its rim height holds.
  double reflector_radius_m = 300.0;
  double reflector_aperture_radius_m = 250.0;
  // How far below the nominal reflector surface a position may be, m (measurement error
  // and a real surface off the nominal sphere); never below the ground, z = 0.
  double below_reflector_margin_m = 10.0;
  // Largest |angle| of an attitude given as angles (roll, pitch, yaw; planned too), deg:
  // one turn, so both the (-180, 180] and the [0, 360) conventions pass.
  double max_abs_angle_deg = 360.0;
  // Largest |rotation vector| (solve --rotvec), rad: one turn.
  double max_rotation_vector_rad = 6.283185307179586;
  // Longest unstretched cable length, m: a cable from a tower top to the far side of
  // the workspace is under 700 m.
  double max_unstretched_length_m = 1000.0;
  // Largest |time_s|, s: Unix times to the year 2286 (FAST saw first light in 2016), or
  // seconds from a survey's start; one time of 1e300 once moved a calibration by 1.9 cm
  // through its time-correlated noise (issue 37).
  double max_abs_time_s = 1.0e10;

  // Model and calibration-spec values (model_plausibility.h checks model files with them,
  // calibration_spec.h initial values, priors and noise): wide enough for any real FAST
  // cabin, cable and sensor, narrow enough that a factor of 1000 (tonnes typed as kg, kN
  // as N, mm as m) always falls outside. Nominal values: docs/model.md, Table 1.
  // Cabin mass, kg: nominal 30 t; a third to three times it.
  double min_cabin_mass_kg = 1.0e4;
  double max_cabin_mass_kg = 1.0e5;
  // Largest |component| of the mass centre in the cabin frame, m: the cabin's anchor
  // points are 7.5 m from its origin.
  double max_abs_mass_centre_m = 5.0;
  // Largest |component| of a cabin anchor point, m: the cabin is about 15 m across.
  double max_abs_anchor_point_m = 20.0;
  // Cable linear density, kg/m: nominal 11.718; a fifth to five times it.
  double min_linear_density_kg_per_m = 2.0;
  double max_linear_density_kg_per_m = 60.0;
  // Cable axial stiffness EA, N: nominal 2.4656e7 N; a fifth to five times it.
  double min_ea_n = 5.0e6;
  double max_ea_n = 1.25e8;
  // Largest |component| of a calibration's anchor or tower offset, m: the points are
  // surveyed to about a centimetre; a metre off is a survey blunder, not a calibration.
  double max_abs_offset_m = 1.0;
  // Tension sensor: reading = gain * tension + bias.
  double min_sensor_gain = 0.5;
  double max_sensor_gain = 2.0;
  // Largest |bias|, N: half the working tension of about 200 kN.
  double max_abs_sensor_bias_n = 1.0e5;
  // Largest |zero offset| of a winch's length encoder, m: a winch re-zeroed a few metres
  // off is possible; 20 m (7% of a cable) is a configuration slip.
  double max_abs_length_offset_m = 20.0;
  // Stated length noise, m: a metre would make the lengths worthless for the pose.
  double max_length_sigma_m = 1.0;
  // Stated tension noise: beyond a quarter of the working tension (50 kN) or 50% the
  // readings would carry no information.
  double max_tension_sigma_n = 5.0e4;
  double max_tension_sigma_percent = 50.0;
  // Smallest non-zero part (0 is none): 1 N, or 0.001% (2 N of a working tension),
  // finer than any tension sensor resolves; below them the weights overflow.
  double min_tension_sigma_n = 1.0;
  double min_tension_sigma_percent = 1e-3;
  // A cable's attachments (cable_attachment.h): FAST's sensor assemblies weigh 250-650 kg
  // and its hung lines 0.6-1.6 kg/m; 5 t on one cable, 50 kg/m (four times the cable) or
  // a position 2 km up a ~300 m cable is a slip.
  double max_attachment_mass_kg = 5000.0;
  double max_attachment_density_kg_per_m = 50.0;
  double max_attachment_position_m = 2000.0;

  // The model's world (issue 29: these were accepted, then blamed on the solver).
  // |gravity| in m/s^2: Earth's surface gravity is 9.78 to 9.83 (FAST: about 9.79).
  double min_abs_gravity_m_per_s2 = 9.7;
  double max_abs_gravity_m_per_s2 = 9.9;
  // The model's reflector sphere, m (FAST: radius 300, aperture 500, centre (0, 0, 300)):
  // a radius within these, an aperture of at least min_reflector_aperture_m, and a centre
  // within max_reflector_offset_m of (0, 0, radius) per axis (the global origin is the
  // reflector's lowest point).
  double min_reflector_radius_m = 100.0;
  double max_reflector_radius_m = 1000.0;
  double min_reflector_aperture_m = 100.0;
  double max_reflector_offset_m = 50.0;
  // Tower tops: at least this far from the z axis, m (FAST: 300), at least this high
  // (FAST: 270; the cabin works at 140 to 160 m and hangs from above), and around the
  // axis with no gap wider than max_tower_gap_deg between neighbours seen from it (FAST:
  // 60 deg); a wider gap leaves a side the cables cannot pull toward.
  double min_tower_radius_m = 100.0;
  double min_tower_top_z_m = 150.0;
  double max_tower_gap_deg = 150.0;

  // The cabin's principal moments of inertia, kg m^2 (cabin.inertia_kg_m2; only the
  // vibrations read it; issue 57: 1e300 aborted `modes`, 1e100 gave a mode of 0 Hz). The
  // assumed default is diag(3.5e5, 3.5e5, 5e5), a 30 t cabin of ~13 m diameter; a 10 t
  // cabin of 2.5 m radius has about m r^2 / 4 = 1.6e4, a 100 t one of 20 m about
  // m r^2 / 2 = 2e7. A factor of 1000 either way (t m^2 typed as kg m^2) falls outside.
  double min_cabin_inertia_kg_m2 = 1.0e4;
  double max_cabin_inertia_kg_m2 = 1.0e8;

  // False, naming the field, when a limit is not finite or not > 0.
  bool IsValid(std::string* error) const;
};

// Each check returns true for a plausible value; otherwise false and *why says what is
// wrong with the value, in the units of the files (kN for a tension), e.g.
//   "1e+30 kN is above the plausible maximum of 5000 kN"
//   "z = -50 m is below the reflector (z >= 0 m at 0 m from the axis)"
// Values must be finite (the readers refuse others before).
bool CheckTensionN(double tension_n, const PlausibilityLimits& limits, std::string* why);
bool CheckPosition(const Eigen::Vector3d& position_m, const PlausibilityLimits& limits,
                   std::string* why);
bool CheckAngleDeg(double angle_deg, const PlausibilityLimits& limits, std::string* why);
bool CheckRotationVector(const Eigen::Vector3d& rotation_vector_rad,
                         const PlausibilityLimits& limits, std::string* why);
bool CheckUnstretchedLengthM(double length_m, const PlausibilityLimits& limits, std::string* why);

// The model and spec quantities with a plausible range (PlausibilityLimits above).
enum class ModelQuantity {
  kCabinMassKg,
  kMassCentreM,   // one component, cabin frame
  kAnchorPointM,  // one component, cabin frame
  kLinearDensityKgPerM,
  kEaN,
  kOffsetM,  // one component of an anchor or tower offset
  kSensorGain,
  kSensorBiasN,
  kLengthOffsetM,  // a winch encoder's zero offset
  kLengthSigmaM,   // stated noise of a measured length
  kTensionSigmaN,
  kTensionSigmaPercent,
  kAttachmentMassKg,
  kAttachmentDensityKgPerM,
  kAttachmentPositionM,  // at_m, from_m, to_m
  kGravityMPerS2,        // negative: z is up
  kReflectorRadiusM,
  kReflectorApertureM,
  // A moving part's first moment (one component) and mass (moving_parts.h): at most the
  // whole cabin's mass at the farthest plausible mass centre, and at most the cabin's mass.
  kPartFirstMomentKgM,
  kPartMassKg,
  // One component of the measured frame's point in its part's frame (measured_frame.h): a
  // point of the cabin, within max_abs_anchor_point_m like its anchors.
  kMeasuredOffsetM,
  // A moving part's origin_m (one component, its parent's frame): inside the cabin, as an
  // anchor point is (max_abs_anchor_point_m).
  kPartOriginM,
  // One principal moment of the cabin's inertia.
  kCabinInertiaKgM2,
};

// A quantity's plausible range and its nominal FAST value, SI (percent for
// kTensionSigmaPercent), and how the files write it: file value = SI / si_per_file_unit.
struct QuantityRange {
  double min = 0.0;
  double max = 0.0;
  double nominal = 0.0;
  const char* file_unit = "";
  double si_per_file_unit = 1.0;
};
QuantityRange PlausibleRange(ModelQuantity quantity, const PlausibilityLimits& limits);

// True for a value within its plausible range; otherwise false and *why says so in the
// file's unit, with the nominal value and, when the value times or over 1000 would be
// plausible, the likely unit slip:
//   "30 kg is below the plausible minimum of 10000 kg (nominal FAST: 30000 kg; tonnes
//    written as kg?)"
bool CheckQuantity(ModelQuantity quantity, double value_si, const PlausibilityLimits& limits,
                   std::string* why);

// Lowest plausible z at `horizontal_radius_m` from the axis (PlausibilityLimits above).
double LowestPlausibleZ(double horizontal_radius_m, const PlausibilityLimits& limits);

}  // namespace fastcal

#endif  // FASTCAL_PLAUSIBILITY_H_
