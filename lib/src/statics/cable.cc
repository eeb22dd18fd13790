// One cable as one object (cable.h): the elastic catenary's end, inverse, tension and
// shape for a uniform cable (catenary.h) or a chain between attachments
// (catenary_chain.h), its mass, and its lumped chain of N segments.
#include "fastcal/cable.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <utility>

namespace fastcal {
namespace {

// Newton's step on (Fl, Fz) is halved until Fl stays positive, at most this often.
constexpr int kMaxHalvings = 30;

}  // namespace

Cable::Cable(double ea_n, double linear_density_kg_per_m, std::vector<CableAttachment> attachments)
    : ea_n_(ea_n),
      linear_density_kg_per_m_(linear_density_kg_per_m),
      attachments_(std::move(attachments)),
      chain_(MakeCatenaryChain(attachments_)) {}

Cable Cable::Of(const CableProperties& properties) {
  return Cable(properties.ea_n, properties.linear_density_kg_per_m, properties.attachments);
}

bool Cable::IsValid(std::string* error) const {
  if (!(ea_n_ > 0.0) || !std::isfinite(ea_n_) || !(linear_density_kg_per_m_ > 0.0) ||
      !std::isfinite(linear_density_kg_per_m_)) {
    *error = "cable: EA and linear density must be > 0 and finite";
    return false;
  }
  if (attachments_.size() > static_cast<size_t>(kMaxAttachmentsPerCable)) {
    *error = "cable: at most " + std::to_string(kMaxAttachmentsPerCable) + " attachments";
    return false;
  }
  for (size_t j = 0; j < attachments_.size(); ++j) {
    std::string why;
    if (!attachments_[j].IsValid(&why)) {
      *error = "cable: attachment " + std::to_string(j + 1) + ": " + why;
      return false;
    }
  }
  return true;
}

CatenaryEnd<double> Cable::End(double fl_n, double fz_n, double s0_m,
                               double gravity_m_per_s2) const {
  return EndOf(fl_n, fz_n, s0_m, ea_n_, WeightPerLengthN(gravity_m_per_s2), chain_,
               gravity_m_per_s2);
}

CatenaryStatus Cable::Forces(double span_m, double rise_m, double s0_m, double gravity_m_per_s2,
                             const CatenarySolverOptions& options, const CatenaryForces* guess,
                             CatenaryForces* forces, int* iterations) const {
  const double w = WeightPerLengthN(gravity_m_per_s2);
  // A uniform cable has catenary.h's solver; a chain starts from the bare cable's answer.
  const CatenaryStatus start = SolveCatenaryForcesDouble(
      span_m, rise_m, s0_m, ea_n_, w, options, uniform() ? guess : nullptr, forces, iterations);
  if (uniform() || start == CatenaryStatus::kInvalidInput ||
      start == CatenaryStatus::kVerticalChord) {
    return start;
  }
  if (guess != nullptr) *forces = *guess;
  const double tolerance_m = options.relative_tolerance * std::hypot(span_m, rise_m);
  for (int k = 1; k <= options.max_iterations; ++k) {
    *iterations = k;
    const CatenaryEnd<double> e = End(forces->fl_n, forces->fz_n, s0_m, gravity_m_per_s2);
    const Eigen::Vector2d miss(e.span_m - span_m, e.rise_m - rise_m);
    if (!miss.allFinite()) return CatenaryStatus::kNotConverged;
    if (miss.cwiseAbs().maxCoeff() <= tolerance_m) return CatenaryStatus::kOk;
    Eigen::Matrix2d j;
    j << e.dspan[0], e.dspan[1], e.drise[0], e.drise[1];
    Eigen::Vector2d step = -j.partialPivLu().solve(miss);
    for (int h = 0; h < kMaxHalvings && !(forces->fl_n + step[0] > 0.0); ++h) step *= 0.5;
    if (!(forces->fl_n + step[0] > 0.0) || !step.allFinite()) return CatenaryStatus::kNotConverged;
    forces->fl_n += step[0];
    forces->fz_n += step[1];
  }
  return CatenaryStatus::kNotConverged;
}

double Cable::Tension(double fl_n, double fz_n, double s_m, double gravity_m_per_s2) const {
  double fz = fz_n + WeightPerLengthN(gravity_m_per_s2) * s_m;
  for (const CableAttachment& a : attachments_) {
    if (a.kind == AttachmentKind::kPointMass) {
      if (a.at_m <= s_m) fz += a.mass_kg * gravity_m_per_s2;
    } else {
      const double covered = std::min(a.to_m, s_m) - a.from_m;
      if (covered > 0.0) fz += a.added_density_kg_per_m * covered * gravity_m_per_s2;
    }
  }
  return std::hypot(fl_n, fz);
}

double Cable::MassKg(double s0_m) const {
  double mass = linear_density_kg_per_m_ * s0_m;
  for (const CableAttachment& a : attachments_) {
    if (a.StartM() >= s0_m) continue;  // not on the cable (CatenaryChainBeyond)
    mass += a.kind == AttachmentKind::kPointMass
                ? a.mass_kg
                : a.added_density_kg_per_m * (std::min(a.to_m, s0_m) - a.from_m);
  }
  return mass;
}

bool Cable::Lumped(const Eigen::Vector3d& lower_m, const Eigen::Vector3d& upper_m, double fl_n,
                   double fz_n, double s0_m, double gravity_m_per_s2, int segments,
                   LumpedChain* chain, std::string* error) const {
  if (!uniform()) {
    *error = "a lumped chain needs a uniform cable (no attachments)";
    return false;
  }
  if (segments < 2) {
    *error = "a lumped chain needs at least 2 segments";
    return false;
  }
  Eigen::Vector3d horizontal = upper_m - lower_m;
  horizontal.z() = 0.0;
  horizontal.normalize();
  const double w = WeightPerLengthN(gravity_m_per_s2);
  const std::vector<CatenaryPoint> points = CatenaryShape(fl_n, fz_n, s0_m, ea_n_, w, segments + 1);
  chain->nodes_m.resize(points.size());
  for (size_t j = 0; j < points.size(); ++j) {
    chain->nodes_m[j] =
        lower_m + points[j].span_m * horizontal + Eigen::Vector3d(0.0, 0.0, points[j].rise_m);
  }
  const double miss_m = (chain->nodes_m.back() - upper_m).norm();
  if (!(miss_m <= kLumpedClosureFraction * (upper_m - lower_m).norm())) {
    *error = "the catenary misses its upper end by " + std::to_string(miss_m) + " m";
    return false;
  }
  chain->segment_length_m = s0_m / segments;
  chain->node_mass_kg = linear_density_kg_per_m_ * chain->segment_length_m;
  chain->ea_n = ea_n_;
  chain->tension_n.resize(segments);
  for (int j = 0; j < segments; ++j) {
    chain->tension_n[j] = CatenaryTension(fl_n, fz_n, (j + 0.5) * chain->segment_length_m, w);
  }
  return true;
}

Eigen::Matrix3d Cable::SegmentStiffness(const Eigen::Vector3d& chord_m, double tension_n,
                                        double ea_n, double l0_m) {
  const double l = chord_m.norm();
  return SegmentStiffnessAlong(chord_m / l, l, tension_n, ea_n, l0_m);
}

}  // namespace fastcal
