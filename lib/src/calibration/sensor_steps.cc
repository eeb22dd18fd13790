// Sensors re-zeroed between sessions (sensor_steps.h).
#include "fastcal/sensor_steps.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "fastcal/gross_errors.h"
#include "fastcal/internal/number_text.h"

namespace fastcal {
namespace {

// The sessions tested: with two, the second only (the first's test is the same test).
std::vector<int> TestedSessions(int sessions) {
  std::vector<int> tested;
  for (int s = sessions == 2 ? 1 : 0; s < sessions; ++s) tested.push_back(s);
  return tested;
}

}  // namespace

SensorStepTest TestSensorSteps(const SensorStepInputs& in) {
  SensorStepTest out;
  const std::vector<ParameterSpec>& free = *in.free;
  const int n = static_cast<int>(free.size());
  const int sessions =
      in.session_information == nullptr ? 0 : static_cast<int>(in.session_information->size());
  std::vector<int> biases;
  for (int k = 0; k < n; ++k) {
    if (free[k].kind == ParameterKind::kSensorBias && free[k].session < 0) biases.push_back(k);
  }
  if (sessions < 2 || biases.empty()) return out;
  out.tested = true;
  out.widening = std::max(1.0, in.widening);
  const std::vector<int> tested = TestedSessions(sessions);
  const double tests = static_cast<double>(biases.size() * tested.size());
  const double z = TwoSidedNormalQuantile(kSensorStepFamilyError / tests);
  out.threshold = z * z;
  const Eigen::LDLT<Eigen::MatrixXd> m(*in.information);
  for (int k : biases) {
    for (int s : tested) {
      const Eigen::VectorXd c = (*in.session_information)[s].col(k);
      const double g = (*in.session_gradient)[s][k];
      const double a = c[k] - c.dot(m.solve(c));
      SensorStep step;
      step.parameter = free[k].name;
      step.cable = free[k].index;
      step.session = (*in.labels)[s];
      step.unit = free[k].unit;
      if (a > 0.0) {
        const double w2 = out.widening * out.widening;
        step.statistic = g * g / (a * w2);
        step.step = -g / a / free[k].to_si;
        step.sigma = out.widening / std::sqrt(a) / free[k].to_si;
        step.significant = step.statistic > out.threshold;
      }
      out.tests.push_back(step);
    }
  }
  // One accused sensor: a maintenance happened, and it may have re-zeroed the others by
  // less than the test can see; their steps would still move the separate parameters. So
  // every shared bias is then fitted per session.
  const bool accused = std::any_of(out.tests.begin(), out.tests.end(),
                                   [](const SensorStep& s) { return s.significant; });
  for (int k : biases) {
    if (accused) out.separated.push_back(free[k].name);
  }
  return out;
}

std::string SensorStepVerdict(const SensorStepTest& test) {
  std::string accused;
  for (const SensorStep& s : test.tests) {
    if (!s.significant) continue;
    accused += (accused.empty() ? "" : ", ") +
               (s.cable >= 0 ? "cable " + std::to_string(s.cable + 1) : std::string("all cables")) +
               " in session " + s.session + " (" + internal::FormatDouble("%+.3g", s.step) + " " +
               s.unit + " +- " + internal::FormatDouble("%.2g", s.sigma) + ", statistic " +
               internal::FormatDouble("%.1f", s.statistic) + ")";
  }
  if (accused.empty()) return "";
  return "sensor offsets stepped between sessions (re-zeroed?): " + accused +
         "; every sensor's bias is then fitted per session (a maintenance that re-zeroes one "
         "may re-zero the others by less than the test sees), so no step is read as a change "
         "of the separate parameters";
}

}  // namespace fastcal
