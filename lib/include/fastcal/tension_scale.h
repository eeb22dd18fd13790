// A whole-file check of the tension readings' scale (issue 37): the six cables hold the
// cabin, so the tensions of a sample sum to at least its weight, m g (the vertical
// components alone make m g; FAST: 30 t, 294 kN, ~180 kN a cable, a sum of ~3.6 m g). A
// file whose median sum is under 0.8 of that (room for sensors 20% low before their
// calibration), or thirty times more, was read in the wrong unit (kN declared as N: 1000x
// small; tonne-force as kN: 9.8x small, a sum of ~0.37 m g), not measured so: refused with
// the likely slip named. So is one cable whose median tension is 30 times the median of
// the six cables' medians, or a thirtieth of it (one column in another unit; FAST's cables
// hold 50-800 kN anywhere on the cap).
#ifndef FASTCAL_TENSION_SCALE_H_
#define FASTCAL_TENSION_SCALE_H_

#include <string>

#include "fastcal/cable_robot.h"
#include "fastcal/dataset.h"

namespace fastcal {

// True when `data` has no tensions, or their median sum per sample is within
// [kMinWeightFraction, kMaxWeightMultiple] of the model's cabin weight and each cable's
// median within a factor 30 of the six medians' median; else false with *error naming the
// file (and the cable), the medians and the likely slip.
inline constexpr double kMinWeightFraction = 0.8;
inline constexpr double kMaxWeightMultiple = 30.0;
bool CheckTensionScale(const Dataset& data, const CableRobot& model, std::string* error);

// The same where the cabin is not known (`fastcal import`, where the map's units are known
// and the model is not; issue 57: an export in kN under a map declaring N was written,
// 1000x small, exit 0): against the lightest cabin the plausibility limits allow (10 t,
// 98 kN), which still tells a 1000x slip (FAST's six tensions sum to about 1000 kN: 1 kN
// read 1000x small) and one column 30x off the others, but not a 9.8x slip of the whole
// file (calibrate, evaluate and track tell it against their model's cabin).
bool CheckTensionScaleOfAnyCabin(const Dataset& data, std::string* error);

}  // namespace fastcal

#endif  // FASTCAL_TENSION_SCALE_H_
