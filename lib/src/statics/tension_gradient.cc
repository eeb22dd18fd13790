// Exact's tension derivatives by the implicit-function theorem
// (internal/tension_gradient.h, where the equations are).
#include "fastcal/internal/tension_gradient.h"

#include <cmath>
#include <utility>

namespace fastcal::internal {
namespace {

// One cable's end point at its solved state and the derivatives of (span, rise) with
// respect to its own parameters: w (N/m), EA, and each attachment's value.
struct CableEnd {
  CatenaryEnd<double> end;  // partials with respect to (Fl, Fz, s0)
  double dspan_dw = 0.0, drise_dw = 0.0, dspan_dea = 0.0, drise_dea = 0.0;
  std::array<double, kMaxAttachmentsPerCable> dspan_dvalue{}, drise_dvalue{};
};

CableEnd UniformCableEnd(double fl, double fz, double s0, double ea, double w) {
  CableEnd c;
  c.end = CatenaryEndpoint(fl, fz, s0, ea, w);
  const double inv_ea2 = 1.0 / (ea * ea);
  c.dspan_dea = -fl * s0 * inv_ea2;
  c.drise_dea = (fz + 0.5 * w * s0) * s0 * inv_ea2;
  // Euler's relation (file comment): the end point is homogeneous of degree 0 in
  // (Fl, Fz, w, EA).
  c.dspan_dw = -(fl * c.end.dspan[0] + fz * c.end.dspan[1] + ea * c.dspan_dea) / w;
  c.drise_dw = -(fl * c.end.drise[0] + fz * c.end.drise[1] + ea * c.drise_dea) / w;
  return c;
}

// A cable with attachments: the chain's end point in a Jet over (w, EA, the values).
CableEnd ChainCableEnd(double fl, double fz, double s0, double ea, double w,
                       const CatenaryChain<double>& chain, double gravity_m_per_s2) {
  constexpr int kWidth = 2 + kMaxAttachmentsPerCable;
  using Jet = ceres::Jet<double, kWidth>;
  CatenaryChain<Jet> jet_chain;
  jet_chain.num_cuts = chain.num_cuts;
  jet_chain.cuts = chain.cuts;
  jet_chain.num_attachments = chain.num_attachments;
  for (int j = 0; j < chain.num_attachments; ++j) jet_chain.value[j] = Jet(chain.value[j], 2 + j);
  const CatenaryEnd<Jet> e = CatenaryChainEndpoint(Jet(fl), Jet(fz), Jet(s0), Jet(ea, 1), Jet(w, 0),
                                                   jet_chain, gravity_m_per_s2);
  CableEnd c;
  c.end.span_m = e.span_m.a;
  c.end.rise_m = e.rise_m.a;
  for (int k = 0; k < 3; ++k) {
    c.end.dspan[k] = e.dspan[k].a;
    c.end.drise[k] = e.drise[k].a;
  }
  c.end.lower_tension_n = e.lower_tension_n.a;
  c.end.upper_tension_n = e.upper_tension_n.a;
  c.dspan_dw = e.span_m.v[0];
  c.drise_dw = e.rise_m.v[0];
  c.dspan_dea = e.span_m.v[1];
  c.drise_dea = e.rise_m.v[1];
  for (int j = 0; j < chain.num_attachments; ++j) {
    c.dspan_dvalue[j] = e.span_m.v[2 + j];
    c.drise_dvalue[j] = e.rise_m.v[2 + j];
  }
  return c;
}

// What the equilibrium needs of each cable: its line's slope a and how a miss (c0, c1)
// of its end conditions shifts the line, db = nu0 c0 + nu1 c1.
struct CableLine {
  double fl, fz, a, nu0, nu1;
  CableEnd end;
};

using Matrix6d = Eigen::Matrix<double, 6, 6>;

// The inverse of a 6x6 matrix by Gauss-Jordan elimination with partial pivoting, written
// out: Eigen's PartialPivLU::inverse() took a third of the gradient's time in its general
// blocked solves. False when a pivot is 0 or the result is not finite.
bool Invert6(Matrix6d m, Matrix6d* inverse) {
  Matrix6d& x = *inverse;
  x.setIdentity();
  for (int c = 0; c < 6; ++c) {
    int p = c;
    for (int r = c + 1; r < 6; ++r) {
      if (std::abs(m(r, c)) > std::abs(m(p, c))) p = r;
    }
    if (!(std::abs(m(p, c)) > 0.0)) return false;
    if (p != c) {
      m.row(p).swap(m.row(c));
      x.row(p).swap(x.row(c));
    }
    const double inv_pivot = 1.0 / m(c, c);
    m.row(c) *= inv_pivot;
    x.row(c) *= inv_pivot;
    for (int r = 0; r < 6; ++r) {
      if (r == c) continue;
      const double f = m(r, c);
      m.row(r) -= f * m.row(c);
      x.row(r) -= f * x.row(c);
    }
  }
  return x.allFinite();
}

// d T / d (the cable's chord, global axes) and d T / d (its lever r = R a, global axes).
void GeometryColumns(const PoseGeometry<double>& g, const Matrix6d& k, int i, const CableLine& c,
                     const Vector6d& beta, Matrix63d* chord, Matrix63d* lever) {
  const double ux = g.ux[i], uy = g.uy[i], inv_l = 1.0 / g.span[i];
  const Vector3T<double>& r = g.r[i];
  // The equilibrium rows' response to the chord's horizontal direction turning by phi.
  Vector6d eta;
  eta << -uy, ux, 0.0, r[2] * ux, -r[2] * uy, -(r[1] * uy + r[0] * ux);
  const Vector6d kappa = k * (c.fl * eta);
  chord->col(0) = -c.nu0 * ux * beta + uy * inv_l * kappa;
  chord->col(1) = -c.nu0 * uy * beta - ux * inv_l * kappa;
  chord->col(2) = -c.nu1 * beta;
  lever->col(0) = -c.fz * k.col(4) + uy * c.fl * k.col(5);
  lever->col(1) = -c.fz * k.col(3) - ux * c.fl * k.col(5);
  lever->col(2) = -uy * c.fl * k.col(3) - ux * c.fl * k.col(4);
}

}  // namespace

StaticsStatus ExactTensionGradient(const StaticsParameters<double>& p, const Pose& pose,
                                   const StaticsSolution& solution, double vertical_span_fraction,
                                   bool geometry, TensionGradient* gradient,
                                   bool tensions_from_state) {
  TensionGradient& out = *gradient;
  PoseGeometry<double> g;
  int cable = -1;
  const StaticsStatus status =
      ComputeGeometry(p, pose, vertical_span_fraction, &g, &cable, /*null_basis=*/false);
  if (status != StaticsStatus::kOk) return status;
  std::array<CableLine, kNumCables> lines;
  Matrix6d a_matrix;
  Vector6d d1;  // d T / d Fl along the cable's line
  for (int i = 0; i < kNumCables; ++i) {
    const CableSolution& s = solution.cables[i];
    CableLine& c = lines[i];
    c.fl = s.horizontal_force_n;
    c.fz = s.force_n[2];
    c.end = p.chain[i].empty()
                ? UniformCableEnd(c.fl, c.fz, s.unstretched_length_m, p.ea_n[i], g.w[i])
                : ChainCableEnd(c.fl, c.fz, s.unstretched_length_m, p.ea_n[i], g.w[i], p.chain[i],
                                p.gravity_m_per_s2);
    const CatenaryEnd<double>& e = c.end.end;
    const double n0 = e.drise[2], n1 = -e.dspan[2];
    const double inv_qq = 1.0 / (n0 * e.dspan[1] + n1 * e.drise[1]);
    c.a = -(n0 * e.dspan[0] + n1 * e.drise[0]) * inv_qq;
    c.nu0 = -n0 * inv_qq;
    c.nu1 = -n1 * inv_qq;
    // From the state alone: the solver's own end evaluation (EvaluateEnds' CableEndpoint,
    // which a uniform cable's end above is; a chain's is evaluated again in double).
    double t = s.lower_tension_n;
    if (tensions_from_state) {
      t = p.chain[i].empty()
              ? e.lower_tension_n
              : CableEndpoint(p, i, c.fl, c.fz, s.unstretched_length_m, g.w[i]).lower_tension_n;
    }
    out.tension_n[i] = t;
    d1[i] = (c.fl + c.a * c.fz) / t;
    const Vector3T<double>& r = g.r[i];
    a_matrix.col(i) << g.ux[i], g.uy[i], c.a, r[1] * c.a + r[2] * g.uy[i],
        r[0] * c.a + r[2] * g.ux[i], r[1] * g.ux[i] - r[0] * g.uy[i];
  }
  Matrix6d k;
  if (!Invert6(a_matrix, &k)) return StaticsStatus::kSingular;
  k = d1.asDiagonal() * k;
  const Eigen::Matrix3d& rotation = pose.rotation;
  for (int i = 0; i < kNumCables; ++i) {
    const CableLine& c = lines[i];
    const Vector3T<double>& r = g.r[i];
    // The tensions' response to a unit shift db_i of the cable's line.
    Vector6d beta = -k.col(2) - r[1] * k.col(3) - r[0] * k.col(4);
    beta[i] += c.fz / out.tension_n[i];
    const CableEnd& e = c.end;
    out.linear_density_kg_per_m[i] =
        (c.nu0 * e.dspan_dw + c.nu1 * e.drise_dw) * p.gravity_m_per_s2 * beta;
    out.ea_n[i] = (c.nu0 * e.dspan_dea + c.nu1 * e.drise_dea) * beta;
    for (int j = 0; j < p.chain[i].num_attachments; ++j) {
      out.chain_value[i][j] = (c.nu0 * e.dspan_dvalue[j] + c.nu1 * e.drise_dvalue[j]) * beta;
    }
    if (!geometry) continue;
    Matrix63d chord, lever;
    GeometryColumns(g, k, i, c, beta, &chord, &lever);
    out.tower_top_m[i] = chord;  // c = B - (R a + p)
    out.anchor_m[i] = (lever - chord) * rotation;
  }
  out.mass_centre_cabin_m = g.weight_n * (k.col(4) * rotation.row(0) + k.col(3) * rotation.row(1));
  out.cabin_mass_kg = p.gravity_m_per_s2 * (k.col(2) + g.e[1] * k.col(3) + g.e[0] * k.col(4));
  return StaticsStatus::kOk;
}

}  // namespace fastcal::internal
