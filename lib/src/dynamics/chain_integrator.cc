// Generalised-alpha for the chains and the cabin (chain_integrator.h).
//
// The equations of motion M(q) qdd + g(q, v) = f(q, v, t) (chain_system.cc) are met at
// each step's end; Chung and Hulbert's (1993, J. Appl. Mech. 60) algorithmic acceleration
// a carries the scheme, in the form of Arnold and Bruls (2007, Multibody Syst. Dyn. 18):
//     (1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) qdd_{n+1} + alpha_f qdd_n,
//     q_{n+1} = q_n + h v_n + h^2 ((1/2 - beta) a_n + beta a_{n+1}),
//     v_{n+1} = v_n + h ((1 - gamma) a_n + gamma a_{n+1}),
// alpha_m = (2 rho - 1)/(rho + 1), alpha_f = rho/(rho + 1), gamma = 1/2 + alpha_f - alpha_m,
// beta = (gamma + 1/2)^2 / 4, rho the spectral radius at infinite frequency (second order
// for any rho in [0, 1]; rho = 1 is the trapezoidal rule). The cabin's rotation moves by
// the step's rotation vector theta (the same update, angular velocity and acceleration in
// global axes): R_{n+1} = exp([theta]x) R_n.
//
// Newton on qdd_{n+1}: the residual r = M qdd + g - f at the step's end, its Jacobian
// M + gamma' C + beta' K with beta' = h^2 beta (1 - alpha_f)/(1 - alpha_m) and
// gamma' = h gamma (1 - alpha_f)/(1 - alpha_m) (how the step's end moves with qdd),
// factored once a step (BorderedSolver) and reused by its further iterations (a
// simplified Newton: the tangent hardly changes within a step), refactored when an
// iteration does not halve the correction. Converged when beta' times the correction,
// the displacements' change, is below newton_tolerance_m.
#include "dynamics/chain_integrator.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "fastcal/internal/number_text.h"

namespace fastcal::internal {

void ChainIntegrator::Reset(const ChainModel* model, const ChainState& state,
                            const IntegratorSettings& settings, const WindField* wind) {
  model_ = model;
  wind_ = wind;
  settings_ = settings;
  const double rho = settings.spectral_radius;
  alpha_m_ = (2.0 * rho - 1.0) / (rho + 1.0);
  alpha_f_ = rho / (rho + 1.0);
  gamma_ = 0.5 + alpha_f_ - alpha_m_;
  beta_ = 0.25 * (gamma_ + 0.5) * (gamma_ + 0.5);
  state_ = state;
  stats_ = DynamicsStats();
  for (ChainField* f : {&acceleration_, &algorithmic_, &qdd_, &a1_, &residual_, &delta_}) {
    f->Resize(*model);
  }
  // The accelerations where it starts: M qdd = f - g, M block diagonal (nodes, body).
  EvaluateForces(*model, state_, Wind(state_.time_s), false, &forces_);
  forces_current_ = true;
  if (model->has_body) {
    const CompositeBody body = Composite(*model, state_);
    acceleration_.body = body.mass.lu().solve(
        forces_.body_force - BodyVelocityTerms(body, state_.body_angular_velocity_rad_per_s));
  }
  for (size_t i = 0; i < model->cables.size(); ++i) {
    const double node_mass = model->cables[i].density_kg_per_m * state_.s0_m[i] / model->segments;
    acceleration_.nodes[i] = forces_.node_force_n[i] / node_mass;
  }
  algorithmic_ = acceleration_;
}

Eigen::Vector3d ChainIntegrator::Wind(double time_s) const {
  return wind_ == nullptr ? Eigen::Vector3d::Zero() : wind_->Velocity(time_s);
}

const ChainForces& ChainIntegrator::Forces() const {
  if (!forces_current_) {
    EvaluateForces(*model_, state_, Wind(state_.time_s), false, &forces_);
    forces_current_ = true;
  }
  return forces_;
}

void ChainIntegrator::Kinematics(double h, const ChainField& a1, ChainState* out) const {
  const double p = h * h * (0.5 - beta_), q = h * h * beta_;
  const double r = h * (1.0 - gamma_), s = h * gamma_;
  const ChainField& a0 = algorithmic_;
  if (model_->has_body) {
    out->body_position_m = state_.body_position_m + h * state_.body_velocity_m_per_s +
                           p * a0.body.head<3>() + q * a1.body.head<3>();
    out->body_velocity_m_per_s =
        state_.body_velocity_m_per_s + r * a0.body.head<3>() + s * a1.body.head<3>();
    const Eigen::Vector3d theta =
        h * state_.body_angular_velocity_rad_per_s + p * a0.body.tail<3>() + q * a1.body.tail<3>();
    const double angle = theta.norm();
    out->body_rotation =
        angle > 0.0
            ? Eigen::Matrix3d(Eigen::AngleAxisd(angle, theta / angle) * state_.body_rotation)
            : state_.body_rotation;
    out->body_angular_velocity_rad_per_s =
        state_.body_angular_velocity_rad_per_s + r * a0.body.tail<3>() + s * a1.body.tail<3>();
  }
  for (size_t i = 0; i < model_->cables.size(); ++i) {
    out->node_m[i] =
        state_.node_m[i] + h * state_.node_velocity_m_per_s[i] + p * a0.nodes[i] + q * a1.nodes[i];
    out->node_velocity_m_per_s[i] =
        state_.node_velocity_m_per_s[i] + r * a0.nodes[i] + s * a1.nodes[i];
  }
}

bool ChainIntegrator::Step(double h, const std::vector<double>& s0_end,
                           const std::vector<double>& rate) {
  const ChainModel& model = *model_;
  const double scale = (1.0 - alpha_f_) / (1.0 - alpha_m_);
  const double beta_prime = h * h * beta_ * scale, gamma_prime = h * gamma_ * scale;
  trial_ = state_;
  trial_.time_s = state_.time_s + h;
  trial_.s0_m = s0_end;
  trial_.s0_rate_m_per_s = rate;
  const Eigen::Vector3d wind = Wind(trial_.time_s);
  qdd_ = acceleration_;  // the predictor: the last step's accelerations
  double last_correction = HUGE_VAL;
  bool factored = false;
  for (int it = 0; it < settings_.max_newton_iterations; ++it) {
    // a_{n+1} from qdd_{n+1}, then the step's end.
    a1_ = acceleration_;
    a1_.body = (alpha_f_ * acceleration_.body - alpha_m_ * algorithmic_.body +
                (1.0 - alpha_f_) * qdd_.body) /
               (1.0 - alpha_m_);
    for (size_t i = 0; i < model.cables.size(); ++i) {
      a1_.nodes[i] = (alpha_f_ * acceleration_.nodes[i] - alpha_m_ * algorithmic_.nodes[i] +
                      (1.0 - alpha_f_) * qdd_.nodes[i]) /
                     (1.0 - alpha_m_);
    }
    Kinematics(h, a1_, &trial_);
    const bool refactor = !factored;
    EvaluateForces(model, trial_, wind, refactor, &step_forces_);
    const CompositeBody body = Composite(model, trial_);
    residual_.body =
        model.has_body ? Vector6d(body.mass * qdd_.body +
                                  BodyVelocityTerms(body, trial_.body_angular_velocity_rad_per_s) -
                                  step_forces_.body_force)
                       : Vector6d::Zero();
    for (size_t i = 0; i < model.cables.size(); ++i) {
      const double node_mass = model.cables[i].density_kg_per_m * s0_end[i] / model.segments;
      residual_.nodes[i] = node_mass * qdd_.nodes[i] - step_forces_.node_force_n[i];
    }
    if (refactor) {
      ++stats_.factorisations;
      if (!solver_.Factor(model, trial_, body, step_forces_, 1.0, gamma_prime, beta_prime)) {
        return false;
      }
      factored = true;
    }
    solver_.Solve(residual_, &delta_);
    ++stats_.newton_iterations;
    qdd_.AddScaled(-1.0, delta_);
    const double correction = beta_prime * delta_.MaxAbs();
    if (!std::isfinite(correction)) return false;
    if (correction < settings_.newton_tolerance_m) {
      // The end of the step from the converged accelerations.
      a1_.body += (1.0 - alpha_f_) / (1.0 - alpha_m_) * -delta_.body;
      for (size_t i = 0; i < model.cables.size(); ++i) {
        a1_.nodes[i] -= (1.0 - alpha_f_) / (1.0 - alpha_m_) * delta_.nodes[i];
      }
      Kinematics(h, a1_, &trial_);
      state_ = trial_;
      acceleration_ = qdd_;
      algorithmic_ = a1_;
      forces_current_ = false;
      ++stats_.steps;
      stats_.slack_segment_steps += step_forces_.slack_segments;
      return true;
    }
    // A simplified Newton that stalls: refactor at the current iterate.
    if (correction > 0.5 * last_correction) factored = false;
    last_correction = correction;
  }
  return false;
}

bool ChainIntegrator::StepHalving(double h, const std::vector<double>& s0_end,
                                  const std::vector<double>& rate, int depth) {
  if (Step(h, s0_end, rate)) return true;
  if (depth >= settings_.max_step_halvings) return false;
  ++stats_.halvings;
  std::vector<double> middle(s0_end.size());
  for (size_t i = 0; i < middle.size(); ++i) middle[i] = s0_end[i] - 0.5 * h * rate[i];
  return StepHalving(0.5 * h, middle, rate, depth + 1) &&
         StepHalving(0.5 * h, s0_end, rate, depth + 1);
}

bool ChainIntegrator::Advance(double time_s, const std::vector<double>& s0_m, std::string* error) {
  const double span = time_s - state_.time_s;
  if (!(span > 0.0) || !std::isfinite(time_s)) {
    *error = "the time must move forward (from " + FormatDouble("%.9g", state_.time_s) + " s to " +
             FormatDouble("%.9g", time_s) + " s)";
    return false;
  }
  const int steps = std::max(1, static_cast<int>(std::ceil(span / settings_.max_step_s - 1e-9)));
  const double h = span / steps;
  const std::vector<double> s0_start = state_.s0_m;
  std::vector<double> rate(s0_m.size()), s0_end(s0_m.size());
  for (size_t i = 0; i < s0_m.size(); ++i) rate[i] = (s0_m[i] - s0_start[i]) / span;
  for (int k = 1; k <= steps; ++k) {
    const double fraction = static_cast<double>(k) / steps;
    for (size_t i = 0; i < s0_m.size(); ++i) {
      s0_end[i] = s0_start[i] + fraction * (s0_m[i] - s0_start[i]);
    }
    if (!StepHalving(h, s0_end, rate, 0)) {
      *error = "the integrator did not converge at t = " + FormatDouble("%.6g", state_.time_s) +
               " s after halving the step " + std::to_string(settings_.max_step_halvings) +
               " times (the winches too fast, or a cable gone slack?)";
      return false;
    }
    // Equal steps end exactly at time_s, whatever the rounding of their sum.
    if (k == steps) state_.time_s = time_s;
  }
  return true;
}

}  // namespace fastcal::internal
