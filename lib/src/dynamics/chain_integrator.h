// The time integration of a chain system (chain_system.h) by generalised-alpha with a
// Newton iteration per step; the scheme and why open chain_integrator.cc and dynamics.h.
#ifndef FASTCAL_SRC_DYNAMICS_CHAIN_INTEGRATOR_H_
#define FASTCAL_SRC_DYNAMICS_CHAIN_INTEGRATOR_H_

#include <string>
#include <vector>

#include "dynamics/chain_system.h"
#include "fastcal/dynamics.h"
#include "fastcal/wind.h"

namespace fastcal::internal {

struct IntegratorSettings {
  double max_step_s = 0.02;
  double spectral_radius = 0.9;
  double newton_tolerance_m = 1e-9;
  int max_newton_iterations = 16;
  int max_step_halvings = 8;
};

class ChainIntegrator {
 public:
  // Starts from `state` (its velocities as given): the accelerations from the equations
  // of motion there. `model` and `wind` (may be null: still air) must outlive this.
  void Reset(const ChainModel* model, const ChainState& state, const IntegratorSettings& settings,
             const WindField* wind);
  // To `time_s`, the winches' lengths going linearly to `s0_m` (dynamics.h, Advance).
  bool Advance(double time_s, const std::vector<double>& s0_m, std::string* error);

  const ChainState& state() const { return state_; }
  // The true accelerations (body: of O' and angular) at the current state.
  const ChainField& acceleration() const { return acceleration_; }
  // The forces at the current state (evaluated when first asked after a step).
  const ChainForces& Forces() const;
  const DynamicsStats& stats() const { return stats_; }
  Eigen::Vector3d Wind(double time_s) const;

 private:
  // One step of `h` to lengths `s0_end` at rates `rate`: false when Newton does not
  // converge (the state is then unchanged).
  bool Step(double h, const std::vector<double>& s0_end, const std::vector<double>& rate);
  // Steps of `h`, halved on failure down to `depth` halvings.
  bool StepHalving(double h, const std::vector<double>& s0_end, const std::vector<double>& rate,
                   int depth);
  // The state at the step's end from the algorithmic acceleration `a1`.
  void Kinematics(double h, const ChainField& a1, ChainState* out) const;

  const ChainModel* model_ = nullptr;
  const WindField* wind_ = nullptr;
  IntegratorSettings settings_;
  // The generalised-alpha coefficients (Arnold and Bruls's form).
  double alpha_m_ = 0.0, alpha_f_ = 0.0, beta_ = 0.25, gamma_ = 0.5;
  ChainState state_;
  ChainField acceleration_, algorithmic_;
  // Scratch of a step.
  ChainState trial_;
  ChainField qdd_, a1_, residual_, delta_;
  ChainForces step_forces_;
  BorderedSolver solver_;
  mutable ChainForces forces_;
  mutable bool forces_current_ = false;
  DynamicsStats stats_;
};

}  // namespace fastcal::internal

#endif  // FASTCAL_SRC_DYNAMICS_CHAIN_INTEGRATOR_H_
