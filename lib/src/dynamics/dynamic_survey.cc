// A survey flown in time (dynamic_survey.h).
#include "fastcal/dynamic_survey.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "fastcal/dynamics_run.h"
#include "fastcal/internal/number_text.h"

namespace fastcal {
namespace {

bool SamePose(const Pose& a, const Pose& b) {
  return (a.position_m - b.position_m).norm() < 1e-9 &&
         (a.rotation - b.rotation).cwiseAbs().maxCoeff() < 1e-12;
}

// The flight's plan: each sample's time, and for a sample after a move, the move's
// start and duration.
struct Leg {
  double move_start_s = 0.0;
  double move_s = 0.0;  // 0: no move before this sample
  double sample_s = 0.0;
};

// The moves of a flight over `planned` (consecutive samples at different poses).
size_t Moves(const std::vector<Pose>& planned) {
  size_t moves = 0;
  for (size_t n = 1; n < planned.size(); ++n) moves += !SamePose(planned[n], planned[n - 1]);
  return moves;
}

std::vector<Leg> Plan(const std::vector<Pose>& planned, const SurveyFlightOptions& o) {
  std::vector<Leg> legs(planned.size());
  double t = 0.0;
  size_t moves = 0;
  for (size_t n = 1; n < planned.size(); ++n) {
    Leg& leg = legs[n];
    if (SamePose(planned[n], planned[n - 1])) {
      t += o.sample_interval_s;
    } else {
      leg.move_start_s = t;
      const double distance = (planned[n].position_m - planned[n - 1].position_m).norm();
      leg.move_s = std::max(o.min_move_s, distance / o.speed_m_per_s);
      t += leg.move_s + (o.per_move_waits ? o.move_waits_s[moves] : o.wait_s);
      ++moves;
    }
    leg.sample_s = t;
  }
  return legs;
}

// The flight as it is flown: the dynamics, made at the first sample with the truth model.
struct Flight {
  std::vector<Pose> planned;
  std::vector<Leg> legs;
  SurveyFlightOptions options;
  double duration_s = 0.0;
  std::unique_ptr<CableDynamics> dynamics;
  StaticsOptions statics;
  StaticsSolution solution;  // the last move pose's exact statics (warm)

  bool Advance(long long n, const CableRobot& truth, std::string* error) {
    const Leg& leg = legs[n];
    if (leg.move_s > 0.0) {
      const int steps =
          std::max(1, static_cast<int>(std::ceil(leg.move_s / options.dynamics.max_step_s - 1e-9)));
      for (int k = 1; k <= steps; ++k) {
        const double u = static_cast<double>(k) / steps;
        const Pose pose = MinimumJerkPose(planned[n - 1], planned[n], u, nullptr);
        if (SolveStatics(truth, pose, statics, &solution) != StaticsStatus::kOk) {
          *error = "the move to node " + std::to_string(n) + " passes a pose the statics " +
                   "cannot hold: " + DescribeStatus(solution);
          return false;
        }
        std::array<double, kNumCables> s0{};
        for (int i = 0; i < kNumCables; ++i) s0[i] = solution.cables[i].unstretched_length_m;
        if (!dynamics->Advance(leg.move_start_s + u * leg.move_s, s0, error)) return false;
      }
    }
    if (leg.sample_s > dynamics->time_s()) {
      return dynamics->Advance(leg.sample_s, dynamics->UnstretchedLengthsM(), error);
    }
    return true;
  }

  bool Sample(long long n, const Pose& planned_pose, const CableRobot& truth, ActualSample* out,
              std::string* error) {
    if (n < 0 || n >= static_cast<long long>(planned.size()) ||
        !SamePose(planned_pose, planned[n])) {
      *error = "the survey flight was planned for other poses (node " + std::to_string(n) + ")";
      return false;
    }
    if (n == 0) {
      dynamics = CableDynamics::Create(truth, planned[0], options.dynamics, duration_s, error);
      if (!dynamics) return false;
    } else if (!Advance(n, truth, error)) {
      *error = "node " + std::to_string(n) + ": " + *error;
      return false;
    }
    out->time_s = dynamics->time_s();
    out->pose = dynamics->CabinPose();
    out->lower_tension_n = dynamics->LowerTensionsN();
    out->unstretched_length_m = dynamics->UnstretchedLengthsM();
    return true;
  }
};

}  // namespace

bool SurveyFlightOptions::IsValid(std::string* error) const {
  if (!(speed_m_per_s > 0.0) || !std::isfinite(speed_m_per_s) || !(min_move_s > 0.0) ||
      !std::isfinite(min_move_s)) {
    *error = "speed_m_per_s and min_move_s: must be finite and > 0";
    return false;
  }
  if (!(wait_s >= 0.0) || !std::isfinite(wait_s) || !(sample_interval_s > 0.0) ||
      !std::isfinite(sample_interval_s)) {
    *error = "wait_s (>= 0) and sample_interval_s (> 0): must be finite";
    return false;
  }
  for (size_t k = 0; k < move_waits_s.size(); ++k) {
    if (!(move_waits_s[k] >= 0.0) || !std::isfinite(move_waits_s[k])) {
      *error = "move_waits_s[" + std::to_string(k) + "]: must be finite and >= 0";
      return false;
    }
  }
  return dynamics.IsValid(error);
}

bool MakeSurveyFlight(const std::vector<Pose>& planned, const SurveyFlightOptions& options,
                      ActualSource* source, double* duration_s, std::string* error) {
  if (!options.IsValid(error)) return false;
  if (planned.empty()) {
    *error = "no planned poses";
    return false;
  }
  if (options.per_move_waits && options.move_waits_s.size() != Moves(planned)) {
    *error = std::to_string(options.move_waits_s.size()) +
             " waits (one per move), but the poses make " + std::to_string(Moves(planned)) +
             " moves";
    return false;
  }
  auto flight = std::make_shared<Flight>();
  flight->planned = planned;
  flight->legs = Plan(planned, options);
  flight->options = options;
  flight->duration_s = flight->legs.back().sample_s;
  flight->statics = options.dynamics.statics;
  flight->statics.warm_start = true;
  *duration_s = flight->duration_s;
  *source = [flight](long long n, const Pose& planned_pose, const CableRobot& truth,
                     ActualSample* actual, std::string* why) {
    return flight->Sample(n, planned_pose, truth, actual, why);
  };
  return true;
}

}  // namespace fastcal
