// One cable as one object (issue 54): its description (axial stiffness EA, density per
// unstretched length, attachments) and what the statics, the modes, the dynamics in time
// and identification ask of it, in double.
//
//   End:       the upper end relative to the lower end, (span L, rise Z), at lower-end
//              forces (Fl, Fz) on the cable and unstretched length s0, with the partials
//              d(L, Z)/d(Fl, Fz, s0): the elastic catenary (catenary.h, paper eqs. 14-16),
//              or the chain of uniform pieces between attachments (catenary_chain.h).
//   Forces:    the inverse at fixed s0: the (Fl, Fz) that put the upper end at (L, Z);
//              Newton on End (catenary.h's solver for a uniform cable).
//   Tension:   T(s) = sqrt(Fl^2 + Fz(s)^2), Fz(s) the vertical force below arc length s.
//   Mass:      rho s0 plus the attachments on the cable.
//   Lumped:    N segments of unstretched length l0 = s0/N, nodes at s_j = j l0 on the
//              catenary, interior node masses rho l0 and each segment's tension at its
//              middle (the modes' and the dynamics' discretisation, docs/model.md).
//   SegmentStiffness: a taut segment's tangent stiffness
//              K = (EA/l0) n n^T + (T/l)(I - n n^T), n = d/l its unit chord (geometric
//              plus elastic: Irvine 1981, ch. 4; the lumped-mass lines of MoorDyn).
//
// The statics' templated core (internal/statics_core.h) evaluates the same kernels,
// catenary.h and catenary_chain.h, on ceres::Jet parameters; this object is their face
// in double for everything else.
#ifndef FASTCAL_CABLE_H_
#define FASTCAL_CABLE_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fastcal/cable_attachment.h"
#include "fastcal/cable_robot.h"
#include "fastcal/catenary.h"
#include "fastcal/catenary_chain.h"

namespace fastcal {

// A cable as N lumped segments on its catenary, lower end first (global frame).
struct LumpedChain {
  std::vector<Eigen::Vector3d> nodes_m;  // N + 1 nodes: 0 the lower end, N the upper
  std::vector<double> tension_n;         // each segment's, at its middle on the catenary
  double segment_length_m = 0.0;         // l0 = s0 / N, unstretched
  double node_mass_kg = 0.0;             // rho l0, an interior node's
  double ea_n = 0.0;
  int segments() const { return static_cast<int>(tension_n.size()); }
};

class Cable {
 public:
  Cable() = default;
  Cable(double ea_n, double linear_density_kg_per_m, std::vector<CableAttachment> attachments = {});
  // The cable of a model (cable_robot.h): its EA, density and attachments.
  static Cable Of(const CableProperties& properties);

  double ea_n() const { return ea_n_; }
  double linear_density_kg_per_m() const { return linear_density_kg_per_m_; }
  const std::vector<CableAttachment>& attachments() const { return attachments_; }
  bool uniform() const { return attachments_.empty(); }
  // Weight per unstretched length of the bare cable, w = rho g (N/m; negative, z up).
  double WeightPerLengthN(double gravity_m_per_s2) const {
    return linear_density_kg_per_m_ * gravity_m_per_s2;
  }
  // EA > 0, density > 0, both finite, attachments valid (what End needs).
  bool IsValid(std::string* error) const;

  // The upper end at lower-end forces (fl > 0, fz) on the cable, unstretched length s0.
  CatenaryEnd<double> End(double fl_n, double fz_n, double s0_m, double gravity_m_per_s2) const;

  // The (Fl, Fz) that put the upper end at (span, rise) with unstretched length s0.
  // `guess` may be null. *iterations: Newton's.
  CatenaryStatus Forces(double span_m, double rise_m, double s0_m, double gravity_m_per_s2,
                        const CatenarySolverOptions& options, const CatenaryForces* guess,
                        CatenaryForces* forces, int* iterations) const;

  // The tension at unstretched arc length s from the lower end.
  double Tension(double fl_n, double fz_n, double s_m, double gravity_m_per_s2) const;

  // Its mass at unstretched length s0 (kg): the bare cable's and every attachment's part
  // on it.
  double MassKg(double s0_m) const;

  // The lumped chain of `segments` >= 2 segments from `lower_m` to `upper_m` (global, the
  // upper end must be where the catenary lands, within kLumpedClosureFraction of the
  // chord) at lower-end forces (fl, fz): a uniform cable only. False with *error.
  bool Lumped(const Eigen::Vector3d& lower_m, const Eigen::Vector3d& upper_m, double fl_n,
              double fz_n, double s0_m, double gravity_m_per_s2, int segments, LumpedChain* chain,
              std::string* error) const;

  // The end point in any scalar (T may be a ceres::Jet): a cable of axial stiffness EA,
  // weight per length w and attachments `chain` (empty: uniform). The one kernel End and
  // the statics' templated core (internal/statics_core.h, so the calibration) evaluate.
  template <typename T>
  FASTCAL_ALWAYS_INLINE static CatenaryEnd<T> EndOf(const T& fl_n, const T& fz_n, const T& s0_m,
                                                    const T& ea_n, const T& w_n_per_m,
                                                    const CatenaryChain<T>& chain,
                                                    double gravity_m_per_s2) {
    if (chain.empty()) return CatenaryEndpoint(fl_n, fz_n, s0_m, ea_n, w_n_per_m);
    return CatenaryChainEndpoint(fl_n, fz_n, s0_m, ea_n, w_n_per_m, chain, gravity_m_per_s2);
  }

  // A taut segment's tangent stiffness: chord d (m), tension T, unstretched length l0.
  static Eigen::Matrix3d SegmentStiffness(const Eigen::Vector3d& chord_m, double tension_n,
                                          double ea_n, double l0_m);
  // The same from the chord's unit vector n and length l (a caller that has them).
  static Eigen::Matrix3d SegmentStiffnessAlong(const Eigen::Vector3d& unit, double length_m,
                                               double tension_n, double ea_n, double l0_m) {
    const Eigen::Matrix3d nn = unit * unit.transpose();
    return (ea_n / l0_m) * nn + (tension_n / length_m) * (Eigen::Matrix3d::Identity() - nn);
  }

 private:
  double ea_n_ = 0.0;
  double linear_density_kg_per_m_ = 0.0;
  std::vector<CableAttachment> attachments_;
  CatenaryChain<double> chain_;  // the attachments as the kernels take them
};

// How far the lumped chain's upper node may miss the upper end, as a fraction of the
// chord: the forces given are not the catenary's between the two ends.
inline constexpr double kLumpedClosureFraction = 1e-7;

}  // namespace fastcal

#endif  // FASTCAL_CABLE_H_
