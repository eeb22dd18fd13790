// Sensors re-zeroed between sessions (docs/calibration.md, "Sessions"): an offset that
// changed between two surveys by more than the slow sensor error explains.
//
// A joint fit of several sessions shares the sensors' biases. The slow error
// (slow_error.h) already lets each session's mean offset differ by what the process
// explains (its filter starts afresh at every session); a sensor re-zeroed during
// maintenance steps by more, and a shared bias would then push that step into the
// session-separate parameters (the mass centre). Each shared free bias b_k is tested per
// session s by the score (Lagrange-multiplier) test of "b_k differs in session s", at the
// joint fit's solution, from the linearisation's per-session sums (whitened rows; the
// filter restarts at each session, so restricting a column to one session commutes with
// the whitening):
//   g = (J_x^T r)_s,k,   c = (J_x^T J_x)_s e_k,   A = c_k - c^T M^-1 c,
//   statistic = g^2 / (A w^2),   step = -g / A,   sigma = w / sqrt(A)
// with M the fit's normal matrix (priors included) and w the budget's misfit widening
// (>= 1). Without a step the statistic is chi-square with 1 degree of freedom; the
// threshold is its 1 - alpha / m quantile over the m tests (Bonferroni: alpha = 1% that
// any sensor is accused by chance). With two sessions the test of session 2 is the test of
// session 1; from three on every session is tested. When one sensor is accused the
// calibration fits every shared bias per session (sessions.separate gets their names:
// a maintenance that re-zeroes one sensor may re-zero the others by less than the test
// sees, and those steps too would move the separate parameters) and says so: a re-zeroed
// sensor is named, and no step is read as a mass-centre move.
#ifndef FASTCAL_SENSOR_STEPS_H_
#define FASTCAL_SENSOR_STEPS_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fastcal/calibration_spec.h"

namespace fastcal {

// Chance that some sensor is accused of a step by chance, over all the tests of a fit.
inline constexpr double kSensorStepFamilyError = 0.01;

struct SensorStep {
  std::string parameter;  // the shared free bias tested, e.g. "sensor_bias_kN[3]"
  int cable = -1;         // 0-based; -1 for a bias common to all cables
  std::string session;    // the session whose offset differs (its label)
  std::string unit;       // the parameter's unit (kN)
  double step = 0.0;      // that session's offset minus the shared fit's, in `unit`
  double sigma = 0.0;     // its 1-sigma, widened by w
  double statistic = 0.0;
  bool significant = false;
};

struct SensorStepTest {
  bool tested = false;  // a joint fit of two or more sessions with a shared free bias
  double threshold = 0.0;
  double widening = 1.0;
  std::vector<SensorStep> tests;       // every test: per bias, per session
  std::vector<std::string> separated;  // biases then fitted per session: all, when one is accused
};

struct SensorStepInputs {
  const std::vector<ParameterSpec>* free = nullptr;  // in fit order, with sessions
  const Eigen::MatrixXd* information = nullptr;      // M, priors included
  const std::vector<Eigen::MatrixXd>* session_information = nullptr;
  const std::vector<Eigen::VectorXd>* session_gradient = nullptr;
  const std::vector<std::string>* labels = nullptr;
  double widening = 1.0;
};

SensorStepTest TestSensorSteps(const SensorStepInputs& in);

// One sentence for the verdict: the accused sensors, or "" when none is.
std::string SensorStepVerdict(const SensorStepTest& test);

}  // namespace fastcal

#endif  // FASTCAL_SENSOR_STEPS_H_
