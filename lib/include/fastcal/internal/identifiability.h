// Whether a calibration's data (and priors) determine its free parameters: the singular
// values of the whitened Jacobian's R factor, each parameter's formal sigma and strongest
// correlation, and the poorly determined and undetermined directions (calibration.h,
// Identifiability). Used by Calibrate before solving (to refuse an undetermined free
// set) and at the solution.
#ifndef FASTCAL_INTERNAL_IDENTIFIABILITY_H_
#define FASTCAL_INTERNAL_IDENTIFIABILITY_H_

#include <ceres/crs_matrix.h>
#include <ceres/problem.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fastcal/calibration.h"
#include "fastcal/calibration_spec.h"

namespace fastcal::internal {

// The largest sigma with which parameter `p` (at value `initial`) counts as determined
// (CalibrationOptions).
double MaxSigma(const ParameterSpec& p, double initial, const CalibrationOptions& o);

// Upper-triangular R with R^T R = J^T J of a CRS Jacobian.
Eigen::MatrixXd RFactor(const ceres::CRSMatrix& j);

// The identifiability from an R factor (n x n) of the free parameters `names`.
Identifiability Analyse(const Eigen::MatrixXd& r, const std::vector<std::string>& names,
                        const CalibrationOptions& options);

// R factor of the whitened Jacobian (data and prior rows) of `problem` at its current
// parameters, evaluated on one Ceres thread (the data term threads itself). False when
// the evaluation fails.
bool JacobianR(ceres::Problem* problem, Eigen::MatrixXd* r);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_IDENTIFIABILITY_H_
