// The survey design's information (design.h): each candidate pose's whitened Jacobian
// with respect to the free and the consider parameters, from the calibration's own
// residual (TensionResidual, internal/calibration_model.h), and the criterion on the
// predicted P_total with its gradient in the samples per candidate (formulas in design.h).
#ifndef FASTCAL_INTERNAL_DESIGN_INFORMATION_H_
#define FASTCAL_INTERNAL_DESIGN_INFORMATION_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/design.h"
#include "fastcal/pose.h"

namespace fastcal::internal {

struct DesignProblem {
  int n = 0;                                  // free parameters
  int q = 0;                                  // consider parameters
  std::vector<int> free_spec, consider_spec;  // indices into spec.parameters
  Eigen::VectorXd prior_information;          // Lambda's diagonal (n)
  Eigen::VectorXd consider_variance;          // sigma_c^2 (q)
  std::vector<int> consider_group;            // group index of each consider parameter
  std::vector<std::string> consider_groups;
  std::vector<int> wanted;  // indices into the free parameters
  DesignCriterion criterion = DesignCriterion::kA;
  Eigen::VectorXd wanted_weight;  // A: weight of each wanted variance (n; 0 elsewhere)
  // Readings per pose: the six tensions, twelve with the lengths (spec noise.length_sigma_m).
  int rows = 6;
  // Whitened Jacobian rows, `rows` per candidate (candidate k's rows rows k .. rows k +
  // rows - 1): free (X) and consider (Z) columns.
  Eigen::MatrixXd x_rows, z_rows;
  // Per row: the reading its Jacobian is of (N for a tension, m for a length) and the
  // white sigma it was whitened by, for the slow error's whitening (WhitenInTimeOrder).
  Eigen::VectorXd reading, white_sigma;
  int candidates() const { return static_cast<int>(x_rows.rows() / rows); }
};

// The free and consider parameters of `spec` (consider = fixed with a prior). False
// with *error when nothing is free or n + q exceeds the calibration's Jet size.
bool SetUpDesignProblem(const CalibrationSpec& spec, DesignProblem* problem, std::string* error);

// Whitened Jacobian rows of each pose (appended to problem->x_rows and z_rows), at the
// spec's initial values with its noise model. False with *error naming the pose when the
// statics fail there.
// `joints`: each pose's joint values (moving parts), parallel to poses; empty: all zero.
// The poses are the cabin's (the residual is given the data's: measured_frame.h).
bool AddPoseRows(const CableRobot& robot, const CalibrationSpec& spec,
                 const std::vector<Pose>& poses, const std::vector<JointValues>& joints,
                 DesignProblem* problem, std::string* error);

// The rows of a survey's samples (one candidate per sample, in time order at times_s)
// whitened by the slow sensor error `process` as the calibration whitens its readings
// (internal/slow_error_filter.h: each cable's Kalman filter over its readings in time
// order; the lengths' rows are left white). Nothing changes when the process is inactive.
void WhitenInTimeOrder(const SlowErrorProcess& process, const std::vector<double>& times_s,
                       DesignProblem* problem);

// Information sums of a design with weights w (one per candidate): M (data part, no
// priors) and C.
struct DesignSums {
  Eigen::MatrixXd m;  // sum w_i J_x,i^T J_x,i
  Eigen::MatrixXd c;  // sum w_i J_x,i^T J_c,i
};
DesignSums SumsOf(const DesignProblem& problem, const Eigen::VectorXd& weights);
// Candidate k's own contribution (weight 1).
DesignSums SumsOfCandidate(const DesignProblem& problem, int k);

// P_total of the sums, split into its parts (design.h). False when M + Lambda is not
// positive definite.
struct DesignCovariance {
  Eigen::MatrixXd k;      // (M + Lambda)^-1
  Eigen::MatrixXd total;  // P_total
};
bool CovarianceOf(const DesignProblem& problem, const DesignSums& sums, DesignCovariance* out);

// The criterion (+infinity when not determined).
double CriterionOf(const DesignProblem& problem, const DesignSums& sums);
// Its gradient in each candidate's weight (one per candidate); false when not determined.
bool CriterionGradient(const DesignProblem& problem, const DesignSums& sums,
                       Eigen::VectorXd* gradient);

// Candidates (design_candidates.cc): the feasible poses of the grid and its attitude
// variants (design.h), and how many were infeasible.
bool DesignCandidates(const CableRobot& robot, const DesignOptions& options,
                      std::vector<DesignCandidate>* candidates, int* rejected, std::string* error);
// With a rotator in the model and options.joint_grid_deg not empty, each candidate
// replaced by one per point of the joint grid within the joints' ranges (design.h,
// "Moving parts"); otherwise unchanged. False with *error when no point is in range.
bool ExpandJointGrid(const CableRobot& robot, const DesignOptions& options,
                     std::vector<DesignCandidate>* candidates, std::string* error);
// Each pose's joints for the surveys compared with: the rotator by the focal law when the
// model has one, else zero (empty for a rigid cabin).
std::vector<JointValues> ObservingJoints(const CableRobot& robot, const std::vector<Pose>& poses);
// The paper's circle with `samples` poses at the focal law.
bool CirclePoses(const DesignOptions& options, int samples, std::vector<Pose>* poses,
                 std::string* error);
// `samples` poses uniform over the cap's area at the focal law, each feasible as a
// candidate is (drawn with options.seed; infeasible draws are skipped).
bool RandomSurveyPoses(const CableRobot& robot, const DesignOptions& options, int samples,
                       std::vector<Pose>* poses, std::string* error);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_DESIGN_INFORMATION_H_
