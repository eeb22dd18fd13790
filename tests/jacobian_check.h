// The calibration's analytic Jacobian columns against ceres::Jet's and against central
// differences of the residuals in double, shared by the tests of parameter kinds
// (moving_parts_test, measured_frame_test).
#ifndef FASTCAL_TESTS_JACOBIAN_CHECK_H_
#define FASTCAL_TESTS_JACOBIAN_CHECK_H_

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "fastcal/calibration_spec.h"
#include "fastcal/internal/calibration_model.h"

namespace fastcal::testing {

// For each free parameter k for which step(p) > 0: the analytic column of f at theta
// against the Jet's (within jet_rel_tol of the column's largest entry) and against
// (r(theta + h e_k) - r(theta - h e_k)) / 2h, h = step(p) (within difference_rel_tol).
// `label` prefixes the messages.
inline void ExpectColumnsMatchJetsAndDifferences(
    const internal::TensionResidual& f, const internal::CalibrationModel& model,
    const std::vector<double>& theta, const std::function<double(const ParameterSpec&)>& step,
    double jet_rel_tol, double difference_rel_tol, const std::string& label) {
  const int n = model.num_free();
  std::vector<double> analytic(kNumCables * n), jet(kNumCables * n);
  double ra[kNumCables], rj[kNumCables];
  ASSERT_TRUE(f.Evaluate(theta.data(), ra, analytic.data())) << label;
  ASSERT_TRUE(internal::TensionCost::EvaluateJet(f, theta.data(), rj, jet.data())) << label;
  for (int k = 0; k < n; ++k) {
    const ParameterSpec& p = model.spec().parameters[model.spec_index(k)];
    const double h = step(p);
    if (!(h > 0.0)) continue;
    std::vector<double> up = theta, down = theta;
    up[k] += h;
    down[k] -= h;
    double ru[kNumCables], rd[kNumCables];
    ASSERT_TRUE(f.Evaluate(up.data(), ru, nullptr)) << label << " " << p.name;
    ASSERT_TRUE(f.Evaluate(down.data(), rd, nullptr)) << label << " " << p.name;
    double scale = 0.0;
    for (int i = 0; i < kNumCables; ++i) scale = std::max(scale, std::abs(jet[i * n + k]));
    ASSERT_GT(scale, 0.0) << label << " " << p.name;
    for (int i = 0; i < kNumCables; ++i) {
      EXPECT_NEAR(analytic[i * n + k], jet[i * n + k], jet_rel_tol * scale)
          << label << " " << p.name << " cable " << i + 1;
      EXPECT_NEAR(analytic[i * n + k], (ru[i] - rd[i]) / (2 * h), difference_rel_tol * scale)
          << label << " " << p.name << " cable " << i + 1;
    }
  }
}

}  // namespace fastcal::testing

#endif  // FASTCAL_TESTS_JACOBIAN_CHECK_H_
