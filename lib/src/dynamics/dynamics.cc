// The cabin and its cables in time (dynamics.h): the robot's chain system built from the
// model, its start at the chains' own equilibrium for the exact statics' lengths, the
// strain-rate damping that gives the lowest mode its stated ratio, and the public face
// of the integrator (chain_integrator.cc). The equations are in chain_system.cc.
#include "fastcal/dynamics.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <utility>

#include "dynamics/chain_integrator.h"
#include "dynamics/chain_statics.h"
#include "dynamics/chain_system.h"
#include "fastcal/cable.h"
#include "fastcal/catenary.h"

namespace fastcal {
namespace {

// The most pieces the quasi-static reference splits a change of the winches into.
constexpr int kMaxQuasiStaticPieces = 64;

// The lowest modes computed at the start (for the damping and DynamicsStart).
constexpr int kStartModes = 10;

// The interior nodes 1..N-1 (at s = j s0/N) of a cable's lumped chain on its elastic
// catenary (cable.h) from `lower_m` to `upper_m`, lower-end forces (fl, fz) on the cable.
bool CatenaryNodes(const Cable& cable, const Eigen::Vector3d& lower_m,
                   const Eigen::Vector3d& upper_m, double fl_n, double fz_n, double s0_m,
                   double gravity_m_per_s2, int segments, Eigen::Matrix3Xd* nodes,
                   std::string* error) {
  LumpedChain chain;
  if (!cable.Lumped(lower_m, upper_m, fl_n, fz_n, s0_m, gravity_m_per_s2, segments, &chain,
                    error)) {
    return false;
  }
  nodes->resize(3, segments - 1);
  for (int j = 1; j < segments; ++j) nodes->col(j - 1) = chain.nodes_m[j];
  return true;
}

internal::IntegratorSettings Settings(const DynamicsOptions& o) {
  internal::IntegratorSettings s;
  s.max_step_s = o.max_step_s;
  s.spectral_radius = o.spectral_radius;
  s.newton_tolerance_m = o.newton_tolerance_m;
  s.max_newton_iterations = o.max_newton_iterations;
  s.max_step_halvings = o.max_step_halvings;
  return s;
}

void SetCommon(const DynamicsOptions& o, internal::ChainModel* model) {
  model->segments = o.segments;
  model->air_density_kg_per_m3 = o.air_density_kg_per_m3;
  model->cable_drag_coefficient = o.cable_drag_coefficient;
}

internal::ChainModel RobotModel(const CableRobot& robot, const DynamicsOptions& o) {
  internal::ChainModel model;
  SetCommon(o, &model);
  model.has_body = true;
  model.body.mass_kg = robot.cabin_mass_kg;
  model.body.mass_centre_m = robot.mass_centre_cabin_m;
  model.body.inertia_kg_m2 = robot.cabin_inertia_kg_m2;
  model.body.drag_area_m2 = o.cabin_drag_area_m2;
  model.gravity_m_per_s2 = robot.gravity_m_per_s2;
  for (int i = 0; i < kNumCables; ++i) {
    internal::ChainCable c;
    c.upper_m = robot.cables[i].tower_top_m;
    c.lower_m = robot.AnchorOfCable(i);
    c.ea_n = robot.cables[i].ea_n;
    c.density_kg_per_m = robot.cables[i].linear_density_kg_per_m;
    c.drag_diameter_m = o.cable_drag_diameter_m;
    model.cables.push_back(c);
  }
  return model;
}

// The strain-rate damping (chain_statics.cc): each cable's tau, from the lowest mode's
// stated ratio (`axial_only`: from the cables' first axial modes' instead, a fixed
// cable's check), or from the cables' own ratios; and the lowest modes' frequencies,
// ratios and shapes.
bool SetDamping(const DynamicsOptions& o, const internal::ChainState& equilibrium, bool axial_only,
                internal::ChainModel* model, std::vector<double>* frequency_hz,
                std::vector<double>* damping_ratio, Eigen::MatrixXd* shapes_out,
                std::string* error) {
  // Below this share of its strain energy in the cables' stretch, a mode cannot be damped
  // by the strain rate to a stated ratio (FAST's lowest mode: 6.7%).
  constexpr double kMinAxialShare = 1e-4;
  Eigen::VectorXd omega2;
  Eigen::MatrixXd& shapes = *shapes_out;
  if (!internal::LowestModes(*model, equilibrium, kStartModes, &omega2, &shapes, error)) {
    return false;
  }
  const size_t cables = model->cables.size();
  std::vector<std::vector<double>> axial(omega2.size());
  for (int k = 0; k < omega2.size(); ++k) {
    axial[k] = internal::AxialQuadratic(*model, equilibrium, shapes.col(k));
  }
  if (!o.cable_damping_ratio.empty() || axial_only) {
    for (size_t i = 0; i < cables; ++i) {
      const internal::ChainCable& c = model->cables[i];
      const double omega = M_PI / equilibrium.s0_m[i] * std::sqrt(c.ea_n / c.density_kg_per_m);
      const double zeta =
          o.cable_damping_ratio.empty() ? o.damping_ratio : o.cable_damping_ratio[i];
      model->cables[i].damping_time_s = 2.0 * zeta / omega;
    }
  } else if (o.damping_ratio > 0.0) {
    double q = 0.0;
    for (double v : axial[0]) q += v;
    if (!(q > kMinAxialShare * omega2[0])) {
      *error = "the lowest mode barely stretches the cables (" +
               std::to_string(100.0 * q / omega2[0]) +
               "% of its strain energy): the strain-rate damping cannot give it a ratio; give "
               "the cables' own (cable_damping_ratio)";
      return false;
    }
    const double tau = 2.0 * o.damping_ratio * std::sqrt(omega2[0]) / q;
    for (internal::ChainCable& c : model->cables) c.damping_time_s = tau;
  }
  frequency_hz->clear();
  damping_ratio->clear();
  for (int k = 0; k < omega2.size(); ++k) {
    const double omega = std::sqrt(std::max(omega2[k], 0.0));
    double c = 0.0;
    for (size_t i = 0; i < cables; ++i) c += model->cables[i].damping_time_s * axial[k][i];
    frequency_hz->push_back(omega / (2.0 * M_PI));
    damping_ratio->push_back(omega > 0.0 ? c / (2.0 * omega) : 0.0);
  }
  return true;
}

double Degrees(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle() * 180.0 / M_PI;
}

std::array<double, kNumCables> Tensions(const internal::ChainModel& model,
                                        const internal::ChainState& state,
                                        const internal::ChainForces& forces,
                                        const internal::Vector6d& body_acceleration) {
  const std::vector<Eigen::Vector3d> f =
      internal::LowerEndForces(model, state, forces, body_acceleration);
  std::array<double, kNumCables> out{};
  for (size_t i = 0; i < f.size() && i < out.size(); ++i) out[i] = f[i].norm();
  return out;
}

}  // namespace

bool DynamicsOptions::IsValid(std::string* error) const {
  if (segments < 2 || segments > 1000) {
    *error = "segments: must be in [2, 1000] (got " + std::to_string(segments) + ")";
    return false;
  }
  if (!(damping_ratio >= 0.0 && damping_ratio < 1.0)) {
    *error = "damping_ratio: must be in [0, 1)";
    return false;
  }
  if (!cable_damping_ratio.empty()) {
    if (cable_damping_ratio.size() != kNumCables) {
      *error = "cable_damping_ratio: must give 6 values (one per cable) or none";
      return false;
    }
    for (double z : cable_damping_ratio) {
      if (!(z >= 0.0 && z < 1.0)) {
        *error = "cable_damping_ratio: each must be in [0, 1)";
        return false;
      }
    }
  }
  if (!(max_step_s > 0.0 && max_step_s <= 10.0)) {
    *error = "max_step_s: must be in (0, 10] s";
    return false;
  }
  if (!(spectral_radius >= 0.0 && spectral_radius <= 1.0)) {
    *error = "spectral_radius: must be in [0, 1]";
    return false;
  }
  if (!(newton_tolerance_m > 0.0 && newton_tolerance_m <= 1e-3)) {
    *error = "newton_tolerance_m: must be in (0, 1e-3] m";
    return false;
  }
  if (max_newton_iterations < 1 || max_newton_iterations > 1000 || max_step_halvings < 0 ||
      max_step_halvings > 30) {
    *error = "max_newton_iterations: must be in [1, 1000], max_step_halvings in [0, 30]";
    return false;
  }
  const std::pair<const char*, double> non_negative[] = {
      {"air_density_kg_per_m3", air_density_kg_per_m3},
      {"cabin_drag_area_m2", cabin_drag_area_m2},
      {"cable_drag_diameter_m", cable_drag_diameter_m},
      {"cable_drag_coefficient", cable_drag_coefficient}};
  for (const auto& [name, value] : non_negative) {
    if (!(value >= 0.0) || !std::isfinite(value)) {
      *error = std::string(name) + ": must be finite and >= 0";
      return false;
    }
  }
  if (!wind.IsValid(error)) return false;
  if (statics.method != StaticsMethod::kExact) {
    *error = "statics.method: must be exact (the winches hold the exact statics' lengths)";
    return false;
  }
  return statics.IsValid(error);
}

struct CableDynamics::Impl {
  DynamicsOptions options;
  internal::ChainModel model;
  internal::ChainState equilibrium, quasi_static;
  internal::ChainIntegrator integrator;
  WindField wind;
  DynamicsStart start;
  Eigen::MatrixXd shapes;  // the start's lowest modes (columns over the dofs)
};

CableDynamics::CableDynamics(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
CableDynamics::~CableDynamics() = default;

std::unique_ptr<CableDynamics> CableDynamics::Create(const CableRobot& robot, const Pose& pose,
                                                     const DynamicsOptions& options,
                                                     double duration_s, std::string* error) {
  if (!options.IsValid(error)) return nullptr;
  if (!internal::CheckChainInputs(robot, pose, "the dynamics", error)) return nullptr;
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  DynamicsStart& start = impl->start;
  if (SolveStatics(robot, pose, options.statics, &start.statics) != StaticsStatus::kOk) {
    *error = "the statics cannot hold the start pose: " + DescribeStatus(start.statics);
    return nullptr;
  }
  impl->model = RobotModel(robot, options);
  internal::ChainModel& model = impl->model;
  internal::ChainState state;
  state.body_position_m = pose.position_m;
  state.body_rotation = pose.rotation;
  for (int i = 0; i < kNumCables; ++i) {
    const CableSolution& s = start.statics.cables[i];
    const CableProperties& c = robot.cables[i];
    Eigen::Matrix3Xd nodes;
    if (!CatenaryNodes(Cable::Of(c), pose.position_m + pose.rotation * robot.AnchorOfCable(i),
                       c.tower_top_m, s.horizontal_force_n, s.force_n.z(), s.unstretched_length_m,
                       robot.gravity_m_per_s2, options.segments, &nodes, error)) {
      *error = "cable " + std::to_string(i + 1) + ": " + *error;
      return nullptr;
    }
    state.node_m.push_back(nodes);
    state.node_velocity_m_per_s.push_back(Eigen::Matrix3Xd::Zero(3, options.segments - 1));
    state.s0_m.push_back(s.unstretched_length_m);
    state.s0_rate_m_per_s.push_back(0.0);
  }
  int iterations = 0;
  if (!internal::SolveChainStatics(model, internal::ChainStaticsOptions(), &state, &iterations,
                                   error) ||
      !SetDamping(options, state, false, &model, &start.frequency_hz, &start.damping_ratio,
                  &impl->shapes, error)) {
    *error = "the start: " + *error;
    return nullptr;
  }
  for (int i = 0; i < kNumCables; ++i) start.damping_time_s[i] = model.cables[i].damping_time_s;
  start.equilibrium.position_m = state.body_position_m;
  start.equilibrium.rotation = state.body_rotation;
  start.position_offset_m = (state.body_position_m - pose.position_m).norm();
  start.attitude_offset_deg = Degrees(state.body_rotation, pose.rotation);
  internal::ChainForces forces;
  internal::EvaluateForces(model, state, Eigen::Vector3d::Zero(), false, &forces);
  const std::array<double, kNumCables> tension =
      Tensions(model, state, forces, internal::Vector6d::Zero());
  for (int i = 0; i < kNumCables; ++i) {
    const double exact = start.statics.cables[i].lower_tension_n;
    start.tension_offset = std::max(start.tension_offset, std::abs(tension[i] - exact) / exact);
  }
  if (!impl->wind.Build(options.wind, duration_s, error)) return nullptr;
  impl->equilibrium = state;
  impl->quasi_static = state;
  impl->integrator.Reset(&impl->model, state, Settings(options), &impl->wind);
  return std::unique_ptr<CableDynamics>(new CableDynamics(std::move(impl)));
}

bool CableDynamics::Displace(const Eigen::Vector3d& offset_m, const Eigen::Vector3d& rotation_rad,
                             std::string* error) {
  if (impl_->integrator.stats().steps > 0 || !offset_m.allFinite() || !rotation_rad.allFinite()) {
    *error = "a displacement is a start: at time 0 and finite";
    return false;
  }
  const internal::ChainModel& model = impl_->model;
  internal::ChainState state = impl_->equilibrium;
  state.body_position_m += offset_m;
  const double angle = rotation_rad.norm();
  if (angle > 0.0) {
    state.body_rotation =
        Eigen::AngleAxisd(angle, rotation_rad / angle).toRotationMatrix() * state.body_rotation;
  }
  // The chains' first guess: each node moved by the anchor's shift, less toward the tower.
  for (int i = 0; i < kNumCables; ++i) {
    const Eigen::Vector3d shift =
        internal::LowerEnd(model, state, i) - internal::LowerEnd(model, impl_->equilibrium, i);
    for (int j = 1; j < model.segments; ++j) {
      state.node_m[i].col(j - 1) += (1.0 - static_cast<double>(j) / model.segments) * shift;
    }
  }
  internal::ChainStaticsOptions held;
  held.body_held = true;
  int iterations = 0;
  if (!internal::SolveChainStatics(model, held, &state, &iterations, error)) {
    *error = "the displaced start: " + *error;
    return false;
  }
  impl_->integrator.Reset(&impl_->model, state, Settings(impl_->options), &impl_->wind);
  return true;
}

bool CableDynamics::DisplaceAlongMode(int mode, double amplitude_m, std::string* error) {
  if (impl_->integrator.stats().steps > 0 || mode < 1 || mode > impl_->shapes.cols() ||
      !std::isfinite(amplitude_m)) {
    *error = "a mode's decay starts at time 0, from one of the " +
             std::to_string(impl_->shapes.cols()) + " lowest modes, with a finite amplitude";
    return false;
  }
  const internal::ChainModel& model = impl_->model;
  const Eigen::VectorXd phi = impl_->shapes.col(mode - 1);
  // The scale: O' by amplitude_m, unless the cabin moves less than a tenth of the cables.
  const double cabin = phi.head<3>().norm();
  const double nodes = phi.tail(phi.size() - 6).cwiseAbs().maxCoeff();
  const double scale = cabin > 0.1 * nodes ? amplitude_m / cabin : 10.0 * amplitude_m / nodes;
  internal::ChainField dx;
  dx.Resize(model);
  dx.body = scale * phi.head<6>();
  const int per_cable = 3 * model.interior();
  for (int i = 0; i < kNumCables; ++i) {
    dx.nodes[i] =
        Eigen::Map<const Eigen::Matrix3Xd>(phi.data() + 6 + i * per_cable, 3, model.interior()) *
        scale;
  }
  internal::ChainState state = impl_->equilibrium;
  internal::Displace(dx, &state);
  impl_->integrator.Reset(&impl_->model, state, Settings(impl_->options), &impl_->wind);
  return true;
}

bool CableDynamics::StartAt(const std::array<double, kNumCables>& s0_m, std::string* error) {
  if (impl_->integrator.stats().steps > 0) {
    *error = "a start is at time 0";
    return false;
  }
  internal::ChainState state = impl_->integrator.state();
  state.s0_m.assign(s0_m.begin(), s0_m.end());
  int iterations = 0;
  if (!internal::SolveChainStatics(impl_->model, internal::ChainStaticsOptions(), &state,
                                   &iterations, error)) {
    *error = "the chains cannot hang at the first lengths: " + *error;
    return false;
  }
  impl_->equilibrium = state;
  impl_->quasi_static = state;
  impl_->integrator.Reset(&impl_->model, state, Settings(impl_->options), &impl_->wind);
  return true;
}

bool CableDynamics::Advance(double time_s, const std::array<double, kNumCables>& s0_m,
                            std::string* error) {
  for (double s : s0_m) {
    if (!(s > 0.0) || !std::isfinite(s)) {
      *error = "the winches' lengths must be finite and > 0";
      return false;
    }
  }
  return impl_->integrator.Advance(time_s, std::vector<double>(s0_m.begin(), s0_m.end()), error);
}

double CableDynamics::time_s() const { return impl_->integrator.state().time_s; }

Pose CableDynamics::CabinPose() const {
  Pose p;
  p.position_m = impl_->integrator.state().body_position_m;
  p.rotation = impl_->integrator.state().body_rotation;
  return p;
}

Eigen::Vector3d CableDynamics::CabinVelocity() const {
  return impl_->integrator.state().body_velocity_m_per_s;
}

Eigen::Vector3d CableDynamics::CabinAngularVelocity() const {
  return impl_->integrator.state().body_angular_velocity_rad_per_s;
}

std::array<double, kNumCables> CableDynamics::LowerTensionsN() const {
  const internal::ChainIntegrator& it = impl_->integrator;
  return Tensions(impl_->model, it.state(), it.Forces(), it.acceleration().body);
}

std::array<double, kNumCables> CableDynamics::UnstretchedLengthsM() const {
  std::array<double, kNumCables> out{};
  const std::vector<double>& s0 = impl_->integrator.state().s0_m;
  std::copy(s0.begin(), s0.end(), out.begin());
  return out;
}

Eigen::Matrix3Xd CableDynamics::CableNodes(int cable) const {
  const internal::ChainModel& model = impl_->model;
  const internal::ChainState& state = impl_->integrator.state();
  Eigen::Matrix3Xd nodes(3, model.segments + 1);
  nodes.col(0) = internal::LowerEnd(model, state, cable);
  nodes.middleCols(1, model.segments - 1) = state.node_m[cable];
  nodes.col(model.segments) = model.cables[cable].upper_m;
  return nodes;
}

DynamicsEnergy CableDynamics::Energy() const {
  const internal::ChainEnergy e =
      internal::Energy(impl_->model, impl_->integrator.state(), impl_->equilibrium);
  DynamicsEnergy out;
  out.kinetic_j = e.kinetic_j;
  out.elastic_j = e.elastic_j;
  out.gravity_j = e.gravity_j;
  return out;
}

const DynamicsStart& CableDynamics::start() const { return impl_->start; }
const DynamicsStats& CableDynamics::stats() const { return impl_->integrator.stats(); }
const DynamicsOptions& CableDynamics::options() const { return impl_->options; }
double CableDynamics::WindSpeed(double time_s) const { return impl_->wind.Speed(time_s); }

bool CableDynamics::QuasiStatic(const std::array<double, kNumCables>& s0_m, QuasiStaticState* out,
                                std::string* error) {
  // From the last equilibrium found (the start's or the previous sample's), in as many
  // equal pieces of the winches' change as Newton needs: a move of 40 m in 16 s sampled at
  // 1 Hz changes the lengths by metres between samples, beyond one Newton solve's reach.
  internal::ChainState& state = impl_->quasi_static;
  const internal::ChainState last = state;
  const bool continuable = last.s0_m.size() == s0_m.size();
  int iterations = 0;
  for (int pieces = 1;; pieces *= 2) {
    state = last;
    bool ok = true;
    for (int k = 1; k <= pieces && ok; ++k) {
      for (size_t i = 0; i < s0_m.size(); ++i) {
        state.s0_m.resize(s0_m.size());
        state.s0_m[i] = continuable && k < pieces
                            ? last.s0_m[i] + (s0_m[i] - last.s0_m[i]) * k / pieces
                            : s0_m[i];
      }
      ok = internal::SolveChainStatics(impl_->model, internal::ChainStaticsOptions(), &state,
                                       &iterations, error);
    }
    if (ok) break;
    if (!continuable || pieces >= kMaxQuasiStaticPieces) {
      state = last;
      *error = "the quasi-static reference: " + *error;
      return false;
    }
  }
  internal::ChainForces forces;
  internal::EvaluateForces(impl_->model, state, Eigen::Vector3d::Zero(), false, &forces);
  out->pose.position_m = state.body_position_m;
  out->pose.rotation = state.body_rotation;
  out->lower_tension_n = Tensions(impl_->model, state, forces, internal::Vector6d::Zero());
  return true;
}

bool SimulateFixedCable(const FixedCable& cable, const DynamicsOptions& options,
                        const FixedCableRelease& release, double duration_s,
                        double sample_interval_s, FixedCableRecord* record, std::string* error) {
  if (!options.IsValid(error)) return false;
  const double chord_m = std::hypot(cable.span_m, cable.rise_m);
  if (!(cable.span_m > 0.0) || !std::isfinite(chord_m) || !(cable.ea_n > 0.0) ||
      !(cable.linear_density_kg_per_m > 0.0) || !(cable.gravity_m_per_s2 < 0.0) ||
      !(cable.unstretched_length_m > 0.0)) {
    *error = "cable: span, unstretched length, EA and density must be > 0 and finite, g < 0";
    return false;
  }
  if (release.harmonic < 1 || release.harmonic >= options.segments ||
      !std::isfinite(release.amplitude_m) || !(sample_interval_s > 0.0) ||
      !(duration_s >= sample_interval_s)) {
    *error = "release: harmonic in [1, segments), finite amplitude, 0 < interval <= duration";
    return false;
  }
  const Cable bare(cable.ea_n, cable.linear_density_kg_per_m);
  CatenaryForces forces;
  int iterations = 0;
  if (bare.Forces(cable.span_m, cable.rise_m, cable.unstretched_length_m, cable.gravity_m_per_s2,
                  CatenarySolverOptions(), nullptr, &forces, &iterations) != CatenaryStatus::kOk) {
    *error = "cable: the catenary has no solution for this span, rise and length";
    return false;
  }
  internal::ChainModel model;
  SetCommon(options, &model);
  model.has_body = false;
  model.gravity_m_per_s2 = cable.gravity_m_per_s2;
  internal::ChainCable c;
  c.upper_m = Eigen::Vector3d(cable.span_m, 0.0, cable.rise_m);
  c.ea_n = cable.ea_n;
  c.density_kg_per_m = cable.linear_density_kg_per_m;
  c.drag_diameter_m = options.cable_drag_diameter_m;
  model.cables.push_back(c);
  const int n = options.segments;
  internal::ChainState state;
  Eigen::Matrix3Xd nodes;
  if (!CatenaryNodes(bare, Eigen::Vector3d::Zero(), c.upper_m, forces.fl_n, forces.fz_n,
                     cable.unstretched_length_m, cable.gravity_m_per_s2, n, &nodes, error)) {
    return false;
  }
  state.node_m.push_back(nodes);
  state.node_velocity_m_per_s.push_back(Eigen::Matrix3Xd::Zero(3, n - 1));
  state.s0_m = {cable.unstretched_length_m};
  state.s0_rate_m_per_s = {0.0};
  std::vector<double> frequency_hz, damping_ratio;
  Eigen::MatrixXd shapes;
  if (!internal::SolveChainStatics(model, internal::ChainStaticsOptions(), &state, &iterations,
                                   error) ||
      !SetDamping(options, state, true, &model, &frequency_hz, &damping_ratio, &shapes, error)) {
    return false;
  }
  const internal::ChainState equilibrium = state;
  const Eigen::Vector3d direction = release.kind == FixedCableRelease::Kind::kTransverse
                                        ? Eigen::Vector3d::UnitY()
                                        : Eigen::Vector3d(c.upper_m / chord_m);
  for (int j = 1; j < n; ++j) {
    state.node_m[0].col(j - 1) +=
        release.amplitude_m * std::sin(M_PI * release.harmonic * j / n) * direction;
  }
  record->sample_interval_s = sample_interval_s;
  record->probe_node =
      std::clamp(static_cast<int>(std::lround(0.5 * n / release.harmonic)), 1, n - 1);
  internal::ChainIntegrator integrator;
  integrator.Reset(&model, state, Settings(options), nullptr);
  auto energy = [&]() {
    const internal::ChainEnergy e = internal::Energy(model, integrator.state(), equilibrium);
    DynamicsEnergy out;
    out.kinetic_j = e.kinetic_j;
    out.elastic_j = e.elastic_j;
    out.gravity_j = e.gravity_j;
    return out;
  };
  auto sample = [&]() {
    const internal::ChainState& s = integrator.state();
    record->displacement_m.push_back(
        direction.dot(s.node_m[0].col(record->probe_node - 1) -
                      equilibrium.node_m[0].col(record->probe_node - 1)));
    record->lower_tension_n.push_back(
        internal::LowerEndForces(model, s, integrator.Forces(), internal::Vector6d::Zero())[0]
            .norm());
  };
  record->displacement_m.clear();
  record->lower_tension_n.clear();
  record->energy_start = energy();
  sample();
  const int samples = static_cast<int>(std::floor(duration_s / sample_interval_s + 1e-9));
  for (int k = 1; k <= samples; ++k) {
    if (!integrator.Advance(k * sample_interval_s, state.s0_m, error)) return false;
    sample();
  }
  record->energy_end = energy();
  return true;
}

}  // namespace fastcal
