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

// Lowest plausible z at `horizontal_radius_m` from the axis (PlausibilityLimits above).
double LowestPlausibleZ(double horizontal_radius_m, const PlausibilityLimits& limits);

}  // namespace fastcal

#endif  // FASTCAL_PLAUSIBILITY_H_
