// The forward problem's equations, their Jacobian blocks and the eliminated Newton system
// (equations: fastcal/internal/forward_statics.h; docs/model.md, "Forward statics").
#include "fastcal/internal/forward_statics.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "fastcal/catenary.h"

namespace fastcal::internal {
namespace {

// A 3x3 matrix given in the basis (h, h_perp, z) of a cable's vertical plane,
// [hh, 0, hz; 0, perp, 0; zh, 0, zz], as a matrix of global axes (h horizontal, unit).
Eigen::Matrix3d InCablePlane(const Eigen::Vector3d& h, double hh, double hz, double zh, double zz,
                             double perp) {
  const double xx = h.x() * h.x(), xy = h.x() * h.y(), yy = h.y() * h.y();
  const double along = hh - perp;  // h h^T's weight once the perpendicular part is added
  Eigen::Matrix3d m;
  m << perp + along * xx, along * xy, hz * h.x(),  //
      along * xy, perp + along * yy, hz * h.y(),   //
      zh * h.x(), zh * h.y(), zz;
  return m;
}

// The moment block of S without the cables: d(e x W)/dtheta = [W]x [e]x.
Eigen::Matrix3d WeightMomentBlock(const StaticsParameters<double>& p, const Pose& pose) {
  const Eigen::Vector3d weight(0.0, 0.0, p.cabin_mass_kg * p.gravity_m_per_s2);
  return Skew(weight) * Skew(pose.rotation * p.mass_centre_cabin_m);
}

}  // namespace

bool CableEnd3dAt(const StaticsParameters<double>& p, int i, const Eigen::Vector3d& force_n,
                  double s0_m, CableEnd3d* end) {
  const double fl = std::sqrt(force_n.x() * force_n.x() + force_n.y() * force_n.y());
  if (!(fl > 0.0) || !(s0_m > 0.0) || !std::isfinite(force_n.z())) return false;
  const Eigen::Vector3d h(force_n.x() / fl, force_n.y() / fl, 0.0);
  const double w = p.linear_density_kg_per_m[i] * p.gravity_m_per_s2;
  const CatenaryEnd<double> e = CableEndpoint(p, i, fl, force_n.z(), s0_m, w);
  // In the cable's plane: d(E_h, E_z)/d(Fl, Fz) = [-dL/dFl, -dL/dFz; dZ/dFl, dZ/dFz], and
  // a force turned about the vertical turns the span with it: -L/Fl.
  const double a = -e.dspan[0], b = -e.dspan[1], c = e.drise[0], d = e.drise[1];
  const double lambda = e.span_m / fl;
  const double det = a * d - b * c;
  if (!(std::abs(det) > 0.0) || !(lambda > 0.0) || !std::isfinite(det)) return false;
  end->end_m = Eigen::Vector3d(-h.x() * e.span_m, -h.y() * e.span_m, e.rise_m);
  end->d = InCablePlane(h, a, b, c, d, -lambda);
  end->d_inverse = InCablePlane(h, d / det, -b / det, -c / det, a / det, -1.0 / lambda);
  end->de_ds0 = Eigen::Vector3d(-h.x() * e.dspan[2], -h.y() * e.dspan[2], e.drise[2]);
  end->lower_tension_n = e.lower_tension_n;
  end->upper_tension_n = e.upper_tension_n;
  return true;
}

ForwardScales MakeForwardScales(const StaticsParameters<double>& p) {
  ForwardScales s;
  s.weight_n = std::abs(p.cabin_mass_kg * p.gravity_m_per_s2);
  for (const Eigen::Vector3d& a : p.anchor_cabin_m) s.size_m = std::max(s.size_m, a.norm());
  return s;
}

bool LineariseForward(const StaticsParameters<double>& p, const ForwardScales& scales,
                      const Lengths& s0_m, const ForwardState& x, ForwardLinearisation* lin) {
  const Eigen::Matrix3d& rotation = x.pose.rotation;
  const Eigen::Vector3d weight(0.0, 0.0, p.cabin_mass_kg * p.gravity_m_per_s2);
  Eigen::Vector3d force_sum = weight;
  Eigen::Vector3d moment_sum = (rotation * p.mass_centre_cabin_m).cross(weight);
  Eigen::Matrix3d moment_block = WeightMomentBlock(p, x.pose);
  Matrix6d k = Matrix6d::Zero();
  double merit = 0.0;
  for (int i = 0; i < kNumCables; ++i) {
    CableEnd3d& end = lin->ends[i];
    if (!CableEnd3dAt(p, i, x.force_n[i], s0_m[i], &end)) return false;
    const Eigen::Vector3d r = rotation * p.anchor_cabin_m[i];
    const Eigen::Vector3d chord = p.tower_top_m[i] - x.pose.position_m - r;
    const Eigen::Vector3d& f = x.force_n[i];
    lin->r[i] = r;
    lin->closure_m[i] = end.end_m - chord;
    lin->chord_m[i] = chord.norm();
    merit += lin->closure_m[i].squaredNorm() / chord.squaredNorm();
    force_sum -= f;
    moment_sum -= r.cross(f);
    const Eigen::Matrix3d rx = Skew(r);
    moment_block -= Skew(f) * rx;
    // P^T D^-1 P with P = (I, -[r]x), P^T = (I; [r]x).
    const Eigen::Matrix3d& m = end.d_inverse;
    const Eigen::Matrix3d rx_m = rx * m;
    k.topLeftCorner<3, 3>() += m;
    k.topRightCorner<3, 3>() -= m * rx;
    k.bottomLeftCorner<3, 3>() += rx_m;
    k.bottomRightCorner<3, 3>() -= rx_m * rx;
    const Eigen::Vector3d m_g = m * end.de_ds0;
    lin->length_coupling.col(i) << m_g, rx * m_g;
  }
  k.bottomRightCorner<3, 3>() += moment_block;
  lin->stiffness = k;
  lin->wrench << force_sum, moment_sum;
  const double moment_scale = scales.weight_n * scales.size_m;
  merit += force_sum.squaredNorm() / (scales.weight_n * scales.weight_n) +
           moment_sum.squaredNorm() / (moment_scale * moment_scale);
  lin->merit = merit;
  return true;
}

bool ForwardNewtonStep(const ForwardLinearisation& lin, Vector6d* dx,
                       std::array<Eigen::Vector3d, kNumCables>* dforce_n) {
  Vector6d rhs = -lin.wrench;
  for (int i = 0; i < kNumCables; ++i) {
    const Eigen::Vector3d m_c = lin.ends[i].d_inverse * lin.closure_m[i];
    rhs.head<3>() -= m_c;
    rhs.tail<3>() -= lin.r[i].cross(m_c);
  }
  *dx = lin.stiffness.partialPivLu().solve(rhs);
  if (!dx->allFinite()) return false;
  for (int i = 0; i < kNumCables; ++i) {
    // P_i dx = dr_p - [r_i]x dtheta = dr_p + dtheta x r_i.
    const Eigen::Vector3d p_dx = dx->head<3>() + dx->tail<3>().cross(lin.r[i]);
    (*dforce_n)[i] = -lin.ends[i].d_inverse * (lin.closure_m[i] + p_dx);
  }
  return true;
}

std::array<Eigen::Vector3d, kNumCables> ZeroForces() {
  std::array<Eigen::Vector3d, kNumCables> f;
  for (Eigen::Vector3d& v : f) v.setZero();
  return f;
}

ForwardState MoveState(const ForwardState& x, const Vector6d& dx,
                       const std::array<Eigen::Vector3d, kNumCables>& dforce_n, double fraction) {
  ForwardState y = x;
  y.pose.position_m += fraction * dx.head<3>();
  const Eigen::Vector3d turn = fraction * dx.tail<3>();
  const double angle = turn.norm();
  if (angle > 0.0) {
    y.pose.rotation = Eigen::AngleAxisd(angle, turn / angle).toRotationMatrix() * x.pose.rotation;
  }
  for (int i = 0; i < kNumCables; ++i) y.force_n[i] += fraction * dforce_n[i];
  return y;
}

double StepSizeM(const Vector6d& dx, double size_m) {
  return std::sqrt(dx.head<3>().squaredNorm() + size_m * size_m * dx.tail<3>().squaredNorm());
}

Eigen::Matrix<double, 24, 1> ForwardResiduals(const ForwardLinearisation& lin) {
  Eigen::Matrix<double, 24, 1> r;
  for (int i = 0; i < kNumCables; ++i) r.segment<3>(3 * i) = lin.closure_m[i];
  r.tail<6>() = lin.wrench;
  return r;
}

Eigen::Matrix<double, 24, 24> ForwardJacobian(const StaticsParameters<double>& p,
                                              const ForwardState& x,
                                              const ForwardLinearisation& lin) {
  Eigen::Matrix<double, 24, 24> j = Eigen::Matrix<double, 24, 24>::Zero();
  Eigen::Matrix3d moment_block = WeightMomentBlock(p, x.pose);
  for (int i = 0; i < kNumCables; ++i) {
    const Eigen::Matrix3d rx = Skew(lin.r[i]);
    j.block<3, 3>(3 * i, 3 * i) = lin.ends[i].d;
    j.block<3, 3>(3 * i, 18) = Eigen::Matrix3d::Identity();
    j.block<3, 3>(3 * i, 21) = -rx;
    j.block<3, 3>(18, 3 * i) = -Eigen::Matrix3d::Identity();
    j.block<3, 3>(21, 3 * i) = -rx;
    moment_block -= Skew(x.force_n[i]) * rx;
  }
  j.block<3, 3>(21, 21) = moment_block;
  return j;
}

bool LengthSensitivity(const ForwardLinearisation& lin, Matrix6d* pose_per_length,
                       Eigen::Matrix<double, 3 * kNumCables, kNumCables>* force_per_length) {
  const Matrix6d x = -lin.stiffness.partialPivLu().solve(lin.length_coupling);
  if (!x.allFinite()) return false;
  *pose_per_length = x;
  if (force_per_length == nullptr) return true;
  for (int i = 0; i < kNumCables; ++i) {
    Eigen::Matrix<double, 3, kNumCables> p_x;
    for (int j = 0; j < kNumCables; ++j) {
      p_x.col(j) = x.col(j).head<3>() + x.col(j).tail<3>().cross(lin.r[i]);
    }
    p_x.col(i) += lin.ends[i].de_ds0;
    force_per_length->block<3, kNumCables>(3 * i, 0) = -lin.ends[i].d_inverse * p_x;
  }
  return true;
}

bool ClosedForcesAt(const StaticsParameters<double>& p, const Lengths& s0_m, const Pose& pose,
                    std::array<Eigen::Vector3d, kNumCables>* force_n) {
  CatenarySolverOptions options;
  for (int i = 0; i < kNumCables; ++i) {
    const Eigen::Vector3d chord =
        p.tower_top_m[i] - pose.position_m - pose.rotation * p.anchor_cabin_m[i];
    const double span = chord.head<2>().norm();
    CatenaryForces f;
    int iterations = 0;
    if (!(span > 0.0) ||
        SolveCatenaryForcesDouble(span, chord.z(), s0_m[i], p.ea_n[i],
                                  p.linear_density_kg_per_m[i] * p.gravity_m_per_s2, options,
                                  nullptr, &f, &iterations) != CatenaryStatus::kOk) {
      return false;
    }
    (*force_n)[i] = Eigen::Vector3d(-chord.x() / span * f.fl_n, -chord.y() / span * f.fl_n, f.fz_n);
  }
  return true;
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

Eigen::Matrix3d InverseLeftJacobian(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  const Eigen::Matrix3d k = Skew(phi);
  // Below this angle the series 1/12 + angle^2/720 replaces the coefficient (cancellation).
  constexpr double kSmallAngle = 1e-4;
  const double c =
      angle < kSmallAngle
          ? 1.0 / 12.0 + angle * angle / 720.0
          : 1.0 / (angle * angle) - (1.0 + std::cos(angle)) / (2.0 * angle * std::sin(angle));
  return Eigen::Matrix3d::Identity() - 0.5 * k + c * k * k;
}

Eigen::Vector3d RotationDifference(const Eigen::Matrix3d& to, const Eigen::Matrix3d& from) {
  const Eigen::AngleAxisd turn(to * from.transpose());
  return turn.angle() * turn.axis();
}

Pose HomePose(const StaticsParameters<double>& p) {
  constexpr double kHomeDepthPerTowerRadius = 130.0 / 300.0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& t : p.tower_top_m) centroid += t / kNumCables;
  double radius_m = 0.0;
  for (const Eigen::Vector3d& t : p.tower_top_m) {
    radius_m += (t - centroid).head<2>().norm() / kNumCables;
  }
  Pose home;
  home.position_m = centroid - Eigen::Vector3d(0.0, 0.0, kHomeDepthPerTowerRadius * radius_m);
  return home;
}

}  // namespace fastcal::internal
