// Plausibility of a whole model (plausibility.h's ranges applied to every value of a
// CableRobot), and what to say when a model cannot solve many rows of a dataset: a unit
// or magnitude slip in the model or spec (30 kg for 30 t) makes the statics fail on row
// after row, and the first failing row is then the wrong thing to blame.
#ifndef FASTCAL_MODEL_PLAUSIBILITY_H_
#define FASTCAL_MODEL_PLAUSIBILITY_H_

#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"
#include "fastcal/plausibility.h"
#include "fastcal/statics.h"

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

// The plausibility.h quantity of a calibration parameter kind's values; false for a kind
// without one.
bool QuantityOfParameter(ParameterKind kind, ModelQuantity* quantity);
// True when `value_si` is plausible for a parameter of `kind` (or the kind has no range);
// otherwise false and *why as CheckQuantity says it.
bool CheckParameterValue(ParameterKind kind, double value_si, const PlausibilityLimits& limits,
                         std::string* why);

// The values of `robot` furthest from the nominal FAST model, furthest first, at most
// `count`, as "cabin.mass_kg = 45000 kg (nominal 30000 kg)". Distance: for a positive
// scale quantity |log(value / nominal)| over log(max / nominal) of its plausible range;
// for a position or offset its departure over its plausible half range (1 m for tower
// tops). Values within 1% of their range are not listed.
std::vector<std::string> FurthestFromNominal(const CableRobot& robot,
                                             const PlausibilityLimits& limits, size_t count);

// How many rows a model cannot solve, and whether the model, not the data, is the likely
// cause: it fails on at least two rows and the nominal FAST model solves at least half of
// them (rows the nominal model cannot hold either are the data's: outside the workspace).
struct UnsolvableRows {
  int rows = 0;
  int failed = 0;
  int solved_by_nominal = 0;  // of the failed ones
  std::string first;          // the first failure's message
  bool model_likely = false;
  std::vector<std::string> furthest_from_nominal;  // FurthestFromNominal(model, ., 3)
};
UnsolvableRows DiagnoseUnsolvableRows(const CableRobot& model, const std::string& model_name,
                                      const Dataset& data,
                                      const std::vector<AttitudeSource>& attitudes,
                                      const std::vector<StaticsMethod>& methods);
// "the initial model cannot solve 26 of 1441 rows (the nominal FAST model solves 26 of
// them): the model or spec is the likely cause, not the data; furthest from nominal:
// cabin.mass_kg = 45000 kg (nominal 30000 kg), ...". Only meaningful when model_likely.
std::string DescribeUnsolvableRows(const UnsolvableRows& diagnosis, const std::string& model_name);

}  // namespace fastcal

#endif  // FASTCAL_MODEL_PLAUSIBILITY_H_
