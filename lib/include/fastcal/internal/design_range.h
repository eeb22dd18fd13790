// The plausible range a designed pose must hold over (design.h, "Poses that hold over the
// plausible range"; docs/design.md): the spec's statics parameters around their initial
// values, and the test of a pose over it.
//
// For a pose, T_i(theta) are the six lower-end tensions. With delta_j the range of
// parameter j and dT_ij = T_i(theta_0 + delta_j e_j) - T_i(theta_0) (one solve each), the
// corner where cable i is lowest is theta_0 - sum_j sign(dT_ij) delta_j e_j: exact for
// tensions linear in the parameters, and the corner's statics are then solved exactly, so
// the margins are checked where the model says, not where the linearisation does. With a
// maximum tension, the corners where each cable is highest too.
#ifndef FASTCAL_INTERNAL_DESIGN_RANGE_H_
#define FASTCAL_INTERNAL_DESIGN_RANGE_H_

#include <array>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/design.h"
#include "fastcal/internal/calibration_model.h"
#include "fastcal/pose.h"

namespace fastcal::internal {

class PlausibleRange {
 public:
  // The range of `spec`'s statics parameters by options.range_* (design.h). `spec` must
  // be valid for `robot`.
  PlausibleRange(const CableRobot& robot, const CalibrationSpec& spec,
                 const DesignOptions& options);

  const std::vector<DesignRangeParameter>& parameters() const { return parameters_; }

  // Whether `pose` holds at the nominal point and at each cable's lowest (and, with a
  // maximum tension, highest) corner: statics ok (model range, reflector clearance) and
  // tensions within the workspace limits. *binding (may be null): its tightest limit
  // there, when it holds; else the one broken (constraint: the statics' status code,
  // StaticsStatusName, where a solve fails).
  // With moving parts, at the joint values `joints` (the mass centre at c(q)). `pose` is
  // the cabin's at the initial values.
  bool Holds(const Pose& pose, const JointValues& joints, DesignBinding* binding) const;

 private:
  // A parameter's effect on the six lower-end tensions (N) and the clearance (m), per step.
  struct Effect {
    std::array<double, kNumCables> tension_n{};
    double clearance_m = 0.0;
  };
  bool Evaluate(const Pose& pose, const JointValues& joints, const std::vector<double>& offset,
                const StaticsSolution* start, StaticsSolution* out) const;
  bool Effects(const Pose& pose, const JointValues& joints, StaticsSolution* nominal,
               std::vector<Effect>* effects, std::vector<double>* failed,
               StaticsSolution* failed_solution) const;
  double Step(int j) const;  // parameter j's step for its effect (SI)
  std::vector<std::vector<double>> Points(const std::vector<Effect>& effects, bool has_max) const;

  DesignOptions options_;
  CalibrationModel model_;        // the spec with every ranged parameter free
  std::vector<double> theta0_;    // initial values of model_'s free parameters
  Eigen::Vector3d measured_offset0_ = Eigen::Vector3d::Zero();  // the measured point there
  std::vector<int> theta_index_;  // of each range parameter in theta
  std::vector<DesignRangeParameter> parameters_;
};

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_DESIGN_RANGE_H_
