// The cabin on its six lumped-mass chains as one mechanical system (chain_system.h).
//
// Cables (the lumped-mass model of MoorDyn: Hall and Goupee 2015, Ocean Eng. 104; the
// discretisation of modes.h). Cable i of paid-out unstretched length s0 is N segments of
// l0 = s0/N, nodes 0..N; interior node masses rho l0, the lower node's half on the body,
// the tower's half held. A segment with chord d = x_{k+1} - x_k, l = |d|, n = d/l pulls
// its ends toward each other with
//     T = EA (l - l0)/l0 + tau EA d/dt[(l - l0)/l0]    when l > l0 and T > 0, else 0
// (a cable cannot push: a slack segment carries no force, nor any damping), the strain
// rate d/dt[(l - l0)/l0] = (n . (v_{k+1} - v_k))/l0 - l l0'/l0^2 counting the winch's
// pay-out l0' = s0'/N, so that paying out at rest damps nothing. tau EA is MoorDyn's
// internal damping BA. Drag on a segment: the air's velocity relative to the segment's
// middle, its part across the chord u_n, 0.5 rho_air C_d d l |u_n| u_n, half to each end
// (MoorDyn's transverse Morison drag without added mass; the axial part is ignored).
// Tangent of a taut segment: K = (EA/l0) n n^T + (T/l)(I - n n^T) (the Hessian of its
// strain energy, as modes.cc), and C = (tau EA/l0) n n^T from the damping.
//
// Body: the cabin, mass m, mass centre c_b and inertia I_c (about the mass centre) in its
// frame, with the lower half nodes m_h,i at its anchors a_i: one rigid composite of mass
// m_t = m + sum m_h,i, first moment S = R (m c_b + sum m_h,i a_i), c = S/m_t and inertia
// about O' I_O = R I_c R^T + m [R c_b]x^T [R c_b]x + sum m_h,i [R a_i]x^T [R a_i]x. Its
// equations at O' (Newton-Euler about a point that is not the mass centre), with a the
// acceleration of O', w and alpha the angular velocity and acceleration (global):
//     F = m_t (a + alpha x c + w x (w x c)),   M_O = I_O alpha + m_t c x a + w x (I_O w),
// i.e. M_c [a; alpha] + [m_t w x (w x c); w x (I_O w)] = [F; M_O] with M_c the mass matrix
// of modes.h. F and M_O: the lowest segments' pulls at the anchors, the composite's
// weight at c, and the cabin's drag 0.5 rho_air (C_d A) |u| u at O' (u the wind relative
// to O'). A small rotation dtheta of the body moves a point p by dtheta x p, so the
// anchor's displacement is T_i [du; dtheta], T_i = [I, -[r_i]x], and forces held fixed
// while their points turn add the load stiffness sum [(f . p) I - p f^T] (modes.cc).
//
// The solve: the matrix a_m M + a_c C + a_k K is, per cable, block tridiagonal in its
// interior nodes, bordered by the body's six unknowns through node 1. Eliminating each
// chain from the tower down (P_{N-1} = D_{N-1}, P_j = D_j - B_j P_{j+1}^-1 B_j) leaves a
// 6x6 Schur complement on the body, S_cc - sum E^T P_1^-1 E; back-substitution runs up the
// chains. The blocks are symmetric (P_j positive definite while the chain has mass or
// stiffness); the body's block is not (the load stiffness), and is solved by LU.
#include "dynamics/chain_system.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "fastcal/cable.h"

namespace fastcal::internal {
namespace {

Eigen::Matrix3d Cross(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// [r]x^T [r]x = (r . r) I - r r^T: a point mass's inertia about the origin, per kg.
Eigen::Matrix3d PointInertia(const Eigen::Vector3d& r) {
  return r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose();
}

// T_i = [I, -[r]x]: how a point at r (from O') moves with the body's (du, dtheta).
Matrix36d PointMap(const Eigen::Vector3d& r) {
  Matrix36d t;
  t << Eigen::Matrix3d::Identity(), -Cross(r);
  return t;
}

double HalfNodeMass(const ChainModel& model, const ChainState& state, int cable) {
  return 0.5 * model.cables[cable].density_kg_per_m * state.s0_m[cable] / model.segments;
}

// Node j's position and velocity (0: the lower end; N: the tower).
void NodeAt(const ChainModel& model, const ChainState& state, int cable, int j, Eigen::Vector3d* x,
            Eigen::Vector3d* v) {
  const ChainCable& c = model.cables[cable];
  if (j == model.segments) {
    *x = c.upper_m;
    v->setZero();
  } else if (j > 0) {
    *x = state.node_m[cable].col(j - 1);
    *v = state.node_velocity_m_per_s[cable].col(j - 1);
  } else if (model.has_body) {
    const Eigen::Vector3d r = state.body_rotation * c.lower_m;
    *x = state.body_position_m + r;
    *v = state.body_velocity_m_per_s + state.body_angular_velocity_rad_per_s.cross(r);
  } else {
    *x = c.lower_m;
    v->setZero();
  }
}

void ResizeForces(const ChainModel& model, bool tangents, ChainForces* f) {
  const size_t cables = model.cables.size();
  const int n = model.segments;
  f->node_force_n.resize(cables);
  f->unit.resize(cables);
  f->length_m.resize(cables);
  f->tension_n.resize(cables);
  f->lower_end_m.resize(cables);
  if (tangents) {
    f->stiffness.resize(cables);
    f->damping.resize(cables);
  }
  for (size_t i = 0; i < cables; ++i) {
    f->node_force_n[i].resize(3, n - 1);
    f->unit[i].resize(3, n);
    f->length_m[i].resize(n);
    f->tension_n[i].resize(n);
    if (tangents) {
      f->stiffness[i].resize(n);
      f->damping[i].resize(n);
    }
  }
}

// One cable's segments: their forces on its nodes (the lowest's on the body through
// `lower_force`), and their tangents.
void EvaluateCable(const ChainModel& model, const ChainState& state, int i,
                   const Eigen::Vector3d& wind, bool tangents, ChainForces* f,
                   Eigen::Vector3d* lower_force) {
  const ChainCable& c = model.cables[i];
  const int n = model.segments;
  const double l0 = state.s0_m[i] / n, l0_rate = state.s0_rate_m_per_s[i] / n;
  const double node_mass = c.density_kg_per_m * l0;
  const double drag_factor =
      0.5 * model.air_density_kg_per_m3 * model.cable_drag_coefficient * c.drag_diameter_m;
  const double damping_n_s = c.damping_time_s * c.ea_n;
  Eigen::Matrix3Xd& force = f->node_force_n[i];
  force.setZero();
  force.row(2).setConstant(node_mass * model.gravity_m_per_s2);
  lower_force->setZero();
  Eigen::Vector3d xa, va, xb, vb;
  NodeAt(model, state, i, 0, &xa, &va);
  f->lower_end_m[i] = xa;
  for (int k = 0; k < n; ++k) {
    NodeAt(model, state, i, k + 1, &xb, &vb);
    const Eigen::Vector3d d = xb - xa;
    const double l = d.norm();
    const Eigen::Vector3d u = d / l;
    const double strain_rate = u.dot(vb - va) / l0 - l * l0_rate / (l0 * l0);
    double tension = c.ea_n * (l - l0) / l0 + damping_n_s * strain_rate;
    const bool taut = l > l0 && tension > 0.0;
    if (!taut) {
      tension = 0.0;
      ++f->slack_segments;
    }
    f->unit[i].col(k) = u;
    f->length_m[i][k] = l;
    f->tension_n[i][k] = tension;
    Eigen::Vector3d pull = tension * u;  // on node k; node k + 1 feels -pull
    Eigen::Vector3d half_drag = Eigen::Vector3d::Zero();
    if (drag_factor > 0.0) {
      const Eigen::Vector3d relative = wind - 0.5 * (va + vb);
      const Eigen::Vector3d across = relative - relative.dot(u) * u;
      half_drag = 0.5 * drag_factor * l * across.norm() * across;
    }
    if (k == 0) {
      *lower_force = pull + half_drag;
    } else {
      force.col(k - 1) += pull + half_drag;
    }
    if (k + 1 < n) force.col(k) += half_drag - pull;
    if (tangents) {
      if (taut) {
        f->stiffness[i][k] = Cable::SegmentStiffnessAlong(u, l, tension, c.ea_n, l0);
        f->damping[i][k] = (damping_n_s / l0) * (u * u.transpose());
      } else {
        f->stiffness[i][k].setZero();
        f->damping[i][k].setZero();
      }
    }
    xa = xb;
    va = vb;
  }
}

}  // namespace

void ChainField::Resize(const ChainModel& model) {
  nodes.resize(model.cables.size());
  for (Eigen::Matrix3Xd& m : nodes) m.resize(3, model.interior());
  SetZero();
}

void ChainField::SetZero() {
  body.setZero();
  for (Eigen::Matrix3Xd& m : nodes) m.setZero();
}

double ChainField::MaxAbs() const {
  // NaN stays NaN (maxCoeff would skip it): a diverged Newton must not look converged.
  if (!body.allFinite()) return std::numeric_limits<double>::quiet_NaN();
  double largest = body.cwiseAbs().maxCoeff();
  for (const Eigen::Matrix3Xd& m : nodes) {
    if (m.size() == 0) continue;
    if (!m.allFinite()) return std::numeric_limits<double>::quiet_NaN();
    largest = std::max(largest, m.cwiseAbs().maxCoeff());
  }
  return largest;
}

void ChainField::AddScaled(double scale, const ChainField& other) {
  body += scale * other.body;
  for (size_t i = 0; i < nodes.size(); ++i) nodes[i] += scale * other.nodes[i];
}

CompositeBody Composite(const ChainModel& model, const ChainState& state) {
  CompositeBody b;
  if (!model.has_body) return b;
  const Eigen::Matrix3d& rot = state.body_rotation;
  const Eigen::Vector3d centre = rot * model.body.mass_centre_m;
  b.mass_kg = model.body.mass_kg;
  Eigen::Vector3d first_moment = b.mass_kg * centre;
  b.inertia_o = rot * model.body.inertia_kg_m2 * rot.transpose() + b.mass_kg * PointInertia(centre);
  for (size_t i = 0; i < model.cables.size(); ++i) {
    const double m = HalfNodeMass(model, state, static_cast<int>(i));
    const Eigen::Vector3d r = rot * model.cables[i].lower_m;
    b.mass_kg += m;
    first_moment += m * r;
    b.inertia_o += m * PointInertia(r);
  }
  b.centre_m = first_moment / b.mass_kg;
  const Eigen::Matrix3d c = Cross(b.centre_m);
  b.mass << b.mass_kg * Eigen::Matrix3d::Identity(), -b.mass_kg * c, b.mass_kg * c, b.inertia_o;
  return b;
}

void EvaluateForces(const ChainModel& model, const ChainState& state,
                    const Eigen::Vector3d& wind_m_per_s, bool tangents, ChainForces* f) {
  ResizeForces(model, tangents, f);
  f->slack_segments = 0;
  f->body_force.setZero();
  f->load_stiffness.setZero();
  auto add_load = [&](const Eigen::Vector3d& force, const Eigen::Vector3d& point) {
    f->body_force.head<3>() += force;
    f->body_force.tail<3>() += point.cross(force);
    if (tangents) {
      f->load_stiffness +=
          force.dot(point) * Eigen::Matrix3d::Identity() - point * force.transpose();
    }
  };
  for (size_t i = 0; i < model.cables.size(); ++i) {
    Eigen::Vector3d lower_force;
    EvaluateCable(model, state, static_cast<int>(i), wind_m_per_s, tangents, f, &lower_force);
    if (model.has_body) add_load(lower_force, state.body_rotation * model.cables[i].lower_m);
  }
  if (!model.has_body) return;
  const CompositeBody body = Composite(model, state);
  add_load(Eigen::Vector3d(0.0, 0.0, body.mass_kg * model.gravity_m_per_s2), body.centre_m);
  if (model.body.drag_area_m2 > 0.0) {
    const Eigen::Vector3d relative = wind_m_per_s - state.body_velocity_m_per_s;
    f->body_force.head<3>() +=
        0.5 * model.air_density_kg_per_m3 * model.body.drag_area_m2 * relative.norm() * relative;
  }
}

std::vector<Eigen::Vector3d> LowerEndForces(const ChainModel& model, const ChainState& state,
                                            const ChainForces& forces,
                                            const Vector6d& body_acceleration) {
  std::vector<Eigen::Vector3d> out(model.cables.size());
  const Eigen::Vector3d& w = state.body_angular_velocity_rad_per_s;
  for (size_t i = 0; i < model.cables.size(); ++i) {
    const double m = HalfNodeMass(model, state, static_cast<int>(i));
    Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();
    if (model.has_body) {
      const Eigen::Vector3d r = state.body_rotation * model.cables[i].lower_m;
      acceleration =
          body_acceleration.head<3>() + body_acceleration.tail<3>().cross(r) + w.cross(w.cross(r));
    }
    out[i] = forces.tension_n[i][0] * forces.unit[i].col(0) +
             m * (Eigen::Vector3d(0.0, 0.0, model.gravity_m_per_s2) - acceleration);
  }
  return out;
}

Vector6d BodyVelocityTerms(const CompositeBody& body, const Eigen::Vector3d& w) {
  Vector6d terms;
  terms.head<3>() = body.mass_kg * w.cross(w.cross(body.centre_m));
  terms.tail<3>() = w.cross(body.inertia_o * w);
  return terms;
}

bool BorderedSolver::Factor(const ChainModel& model, const ChainState& state,
                            const CompositeBody& body, const ChainForces& forces, double a_m,
                            double a_c, double a_k, bool body_held) {
  model_ = &model;
  body_free_ = model.has_body && !body_held;
  const size_t cables = model.cables.size();
  const int n = model.segments, interior = model.interior();
  pivot_inverse_.resize(cables);
  off_.resize(cables);
  coupling_.resize(cables);
  reduced_.resize(cables);
  Matrix6d schur = a_m * body.mass;
  schur.bottomRightCorner<3, 3>() += a_k * forces.load_stiffness;
  std::vector<Eigen::Matrix3d> segment(n);
  for (size_t i = 0; i < cables; ++i) {
    const double node_mass = model.cables[i].density_kg_per_m * state.s0_m[i] / n;
    for (int k = 0; k < n; ++k) {
      segment[k] = a_c * forces.damping[i][k] + a_k * forces.stiffness[i][k];
    }
    std::vector<Eigen::Matrix3d>& inv = pivot_inverse_[i];
    std::vector<Eigen::Matrix3d>& off = off_[i];
    inv.resize(interior);
    off.resize(std::max(interior - 1, 0));
    reduced_[i].resize(3, interior);
    // Node j (1..N-1) at index j - 1: its diagonal block joins segments j - 1 and j; the
    // block to node j + 1 is -segment[j].
    for (int j = interior; j >= 1; --j) {
      Eigen::Matrix3d pivot =
          a_m * node_mass * Eigen::Matrix3d::Identity() + segment[j - 1] + segment[j];
      if (j < interior) {
        off[j - 1] = -segment[j];
        pivot -= off[j - 1] * inv[j] * off[j - 1];
      }
      bool invertible = false;
      double determinant = 0.0;
      pivot.computeInverseAndDetWithCheck(inv[j - 1], determinant, invertible,
                                          1e-300);  // a chain of zero blocks only
      if (!invertible || !std::isfinite(determinant) || !(std::abs(determinant) > 0.0)) {
        return false;
      }
    }
    if (!body_free_) continue;
    const Matrix36d t = PointMap(state.body_rotation * model.cables[i].lower_m);
    coupling_[i] = -segment[0] * t;
    schur += t.transpose() * segment[0] * t;
    schur -= coupling_[i].transpose() * inv[0] * coupling_[i];
  }
  if (body_free_) {
    body_lu_.compute(schur);
    if (!(std::abs(body_lu_.determinant()) > 0.0) || !std::isfinite(body_lu_.determinant())) {
      return false;
    }
  }
  return true;
}

void BorderedSolver::Solve(const ChainField& rhs, ChainField* x) const {
  const ChainModel& model = *model_;
  const size_t cables = model.cables.size();
  const int interior = model.interior();
  Vector6d body_rhs = rhs.body;
  for (size_t i = 0; i < cables; ++i) {
    const std::vector<Eigen::Matrix3d>& inv = pivot_inverse_[i];
    const std::vector<Eigen::Matrix3d>& off = off_[i];
    Eigen::Matrix3Xd& r = reduced_[i];
    r.col(interior - 1) = rhs.nodes[i].col(interior - 1);
    for (int j = interior - 2; j >= 0; --j) {
      r.col(j) = rhs.nodes[i].col(j) - off[j] * (inv[j + 1] * r.col(j + 1));
    }
    if (body_free_) body_rhs -= coupling_[i].transpose() * (inv[0] * r.col(0));
  }
  x->body = body_free_ ? Vector6d(body_lu_.solve(body_rhs)) : Vector6d::Zero();
  for (size_t i = 0; i < cables; ++i) {
    const std::vector<Eigen::Matrix3d>& inv = pivot_inverse_[i];
    const std::vector<Eigen::Matrix3d>& off = off_[i];
    const Eigen::Matrix3Xd& r = reduced_[i];
    Eigen::Matrix3Xd& out = x->nodes[i];
    Eigen::Vector3d first = r.col(0);
    if (body_free_) first -= coupling_[i] * x->body;
    out.col(0) = inv[0] * first;
    for (int j = 1; j < interior; ++j) {
      out.col(j) = inv[j] * (r.col(j) - off[j - 1] * out.col(j - 1));
    }
  }
}

void Displace(const ChainField& dx, ChainState* state) {
  state->body_position_m += dx.body.head<3>();
  const Eigen::Vector3d theta = dx.body.tail<3>();
  const double angle = theta.norm();
  if (angle > 0.0) {
    state->body_rotation =
        Eigen::AngleAxisd(angle, theta / angle).toRotationMatrix() * state->body_rotation;
  }
  for (size_t i = 0; i < dx.nodes.size(); ++i) state->node_m[i] += dx.nodes[i];
}

void AssembleLinearised(const ChainModel& model, const ChainState& state, const ChainForces& forces,
                        Eigen::SparseMatrix<double>* stiffness, Eigen::SparseMatrix<double>* mass) {
  using Triplets = std::vector<Eigen::Triplet<double>>;
  Triplets k, m;
  const int n = model.segments, interior = model.interior(), first = model.has_body ? 6 : 0;
  auto add_block = [](Triplets* t, int row, int col, const Eigen::MatrixXd& block) {
    for (int r = 0; r < block.rows(); ++r) {
      for (int c = 0; c < block.cols(); ++c) {
        if (block(r, c) != 0.0) t->emplace_back(row + r, col + c, block(r, c));
      }
    }
  };
  if (model.has_body) {
    add_block(&m, 0, 0, Composite(model, state).mass);
    add_block(&k, 3, 3, forces.load_stiffness);
  }
  for (size_t i = 0; i < model.cables.size(); ++i) {
    const int base = first + 3 * interior * static_cast<int>(i);
    const double l0 = state.s0_m[i] / n;
    const double node_mass = model.cables[i].density_kg_per_m * l0;
    for (int j = 0; j < interior; ++j) {
      for (int r = 0; r < 3; ++r) m.emplace_back(base + 3 * j + r, base + 3 * j + r, node_mass);
    }
    Matrix36d lower_map = Matrix36d::Zero();
    if (model.has_body) lower_map = PointMap(state.body_rotation * model.cables[i].lower_m);
    for (int seg = 0; seg < n; ++seg) {
      const Eigen::Matrix3d& h = forces.stiffness[i][seg];
      // Ends: node seg and seg + 1; node 0 through the body's map (or held), node N held.
      const bool lower_on_body = seg == 0 && model.has_body;
      const bool lower_free = seg > 0, upper_free = seg + 1 < n;
      const int lower = base + 3 * (seg - 1), upper = base + 3 * seg;
      if (lower_free) add_block(&k, lower, lower, h);
      if (upper_free) add_block(&k, upper, upper, h);
      if (lower_free && upper_free) {
        add_block(&k, lower, upper, -h);
        add_block(&k, upper, lower, -h);
      }
      if (lower_on_body) {
        add_block(&k, 0, 0, lower_map.transpose() * h * lower_map);
        if (upper_free) {
          add_block(&k, upper, 0, -h * lower_map);
          add_block(&k, 0, upper, -lower_map.transpose() * h);
        }
      }
    }
  }
  const int dofs = model.Dofs();
  stiffness->resize(dofs, dofs);
  stiffness->setFromTriplets(k.begin(), k.end());
  mass->resize(dofs, dofs);
  mass->setFromTriplets(m.begin(), m.end());
  const Eigen::SparseMatrix<double> transposed = stiffness->transpose();
  *stiffness = 0.5 * (*stiffness + transposed);
}

Eigen::Vector3d LowerEnd(const ChainModel& model, const ChainState& state, int cable) {
  Eigen::Vector3d x, v;
  NodeAt(model, state, cable, 0, &x, &v);
  return x;
}

ChainEnergy Energy(const ChainModel& model, const ChainState& state, const ChainState& reference) {
  ChainEnergy e;
  const double g = model.gravity_m_per_s2;
  // Gravity's and the segments' potential energies of a state (absolute; their
  // differences are what is returned).
  auto potential = [&](const ChainState& s, double* elastic) {
    double u = 0.0;
    *elastic = 0.0;
    for (size_t i = 0; i < model.cables.size(); ++i) {
      const double l0 = s.s0_m[i] / model.segments;
      u -= model.cables[i].density_kg_per_m * l0 * g * s.node_m[i].row(2).sum();
      Eigen::Vector3d xa, va, xb, vb;
      NodeAt(model, s, static_cast<int>(i), 0, &xa, &va);
      for (int k = 0; k < model.segments; ++k) {
        NodeAt(model, s, static_cast<int>(i), k + 1, &xb, &vb);
        const double stretch = (xb - xa).norm() - l0;
        if (stretch > 0.0) *elastic += 0.5 * model.cables[i].ea_n / l0 * stretch * stretch;
        xa = xb;
      }
    }
    if (model.has_body) {
      const CompositeBody body = Composite(model, s);
      u -= body.mass_kg * g * (s.body_position_m.z() + body.centre_m.z());
    }
    return u;
  };
  double elastic = 0.0, elastic_reference = 0.0;
  e.gravity_j = potential(state, &elastic) - potential(reference, &elastic_reference);
  e.elastic_j = elastic - elastic_reference;
  for (size_t i = 0; i < model.cables.size(); ++i) {
    const double node_mass = model.cables[i].density_kg_per_m * state.s0_m[i] / model.segments;
    e.kinetic_j += 0.5 * node_mass * state.node_velocity_m_per_s[i].squaredNorm();
  }
  if (model.has_body) {
    Vector6d v;
    v << state.body_velocity_m_per_s, state.body_angular_velocity_rad_per_s;
    e.kinetic_j += 0.5 * v.dot(Composite(model, state).mass * v);
  }
  return e;
}

}  // namespace fastcal::internal
