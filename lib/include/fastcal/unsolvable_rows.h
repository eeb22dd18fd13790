// What to say when a model cannot solve many rows of a dataset: a unit or magnitude slip
// in the model or spec (30 kg for 30 t) makes the statics fail on row after row, and the
// first failing row is then the wrong thing to blame. An algorithm over data (the
// evaluation's SkipUnsolvableSamples on the model and on the nominal FAST model), so it
// sits in the calibration layer, above the model's own checks (model_plausibility.h).
#ifndef FASTCAL_UNSOLVABLE_ROWS_H_
#define FASTCAL_UNSOLVABLE_ROWS_H_

#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"
#include "fastcal/statics.h"

namespace fastcal {

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

#endif  // FASTCAL_UNSOLVABLE_ROWS_H_
