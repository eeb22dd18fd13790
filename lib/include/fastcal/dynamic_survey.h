// A survey flown in time: the cabin moved between the planned poses by the dynamics
// (dynamics.h) instead of standing at each in its statics, so that simulated telemetry
// (simulation.h, SimulationOptions::actual_source; `fastcal simulate --dynamics`) carries
// what moves and wind do to the tensions and the poses (docs/calibration.md, "Dynamics").
//
// The flight: at rest at the first planned pose (the chains' equilibrium, dynamics.h);
// to each next pose that differs, a minimum-jerk move (dynamics_run.h) lasting the longer
// of min_move_s and its distance over speed_m_per_s, the winches paying out the exact
// statics' lengths on the way, then wait_s before the sample; a pose that repeats the
// one before is sampled sample_interval_s after it (a stop's samples, or an ambient
// record when every pose is the same). Each sample is the state at its time: the cabin's
// pose, the lower-end tensions (what the sensors read before their gain, bias and noise)
// and the winches' unstretched lengths.
#ifndef FASTCAL_DYNAMIC_SURVEY_H_
#define FASTCAL_DYNAMIC_SURVEY_H_

#include <string>
#include <vector>

#include "fastcal/dynamics.h"
#include "fastcal/pose.h"
#include "fastcal/simulation.h"

namespace fastcal {

struct SurveyFlightOptions {
  DynamicsOptions dynamics;
  // A move's mean speed (distance over duration, m/s, > 0; a minimum-jerk move's peak
  // speed is 1.875 times it) and its shortest duration (s, > 0).
  double speed_m_per_s = 0.5;
  double min_move_s = 10.0;
  // The wait after each move before its first sample (s, >= 0), and the time between
  // samples at one pose (s, > 0).
  double wait_s = 30.0;
  double sample_interval_s = 1.0;
  // Or, with per_move_waits, a wait of its own after each move, in the flight's order (s,
  // >= 0; exactly one per move: `fastcal design`'s stops[k].settle.wait_s for k >= 1, the
  // time each move's tensions take to settle).
  bool per_move_waits = false;
  std::vector<double> move_waits_s;

  bool IsValid(std::string* error) const;
};

// The source of the flight over `planned` (all of it, in order: the wind's record is
// sized from it), and the flight's duration. The source builds the dynamics at its first
// call with the truth model it is given. False with *error for invalid options or no poses.
bool MakeSurveyFlight(const std::vector<Pose>& planned, const SurveyFlightOptions& options,
                      ActualSource* source, double* duration_s, std::string* error);

}  // namespace fastcal

#endif  // FASTCAL_DYNAMIC_SURVEY_H_
