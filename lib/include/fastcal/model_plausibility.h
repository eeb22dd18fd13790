// Plausibility of a whole model: plausibility.h's ranges applied to every value of a
// CableRobot, the one validation of a model file, and the values furthest from the
// nominal FAST model. About the model alone; what judges a model against data (rows it
// cannot solve, unsolvable_rows.h) or a calibration parameter's value
// (parameter_plausibility.h) sits in the calibration layer.
#ifndef FASTCAL_MODEL_PLAUSIBILITY_H_
#define FASTCAL_MODEL_PLAUSIBILITY_H_

#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/plausibility.h"

namespace fastcal {

// True when every value of `robot` is within its plausible range; otherwise false and
// *why = "<key path>: <why>" with the model file's key path (0-based list indices, as
// CableRobot::IsValid), e.g.
//   "cables[2].ea_n: 24656 N is below the plausible minimum of 5000000 N (...)".
// Tower tops are checked as positions (CheckPosition).
bool CheckModelPlausible(const CableRobot& robot, const PlausibilityLimits& limits,
                         std::string* why);

// The checks a model file passes, in the reader's order: CableRobot::IsValid (physical
// sense, its key paths) then CheckModelPlausible with the default limits. The one
// validation of a model: the YAML reader and the Python setters both call it.
bool CheckModel(const CableRobot& robot, std::string* why);

// The values of `robot` furthest from the nominal FAST model, furthest first, at most
// `count`, as "cabin.mass_kg = 45000 kg (nominal 30000 kg)". Distance: for a positive
// scale quantity |log(value / nominal)| over log(max / nominal) of its plausible range;
// for a position or offset its departure over its plausible half range (1 m for tower
// tops). Values within 1% of their range are not listed.
std::vector<std::string> FurthestFromNominal(const CableRobot& robot,
                                             const PlausibilityLimits& limits, size_t count);

}  // namespace fastcal

#endif  // FASTCAL_MODEL_PLAUSIBILITY_H_
