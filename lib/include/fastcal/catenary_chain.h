// A cable as built: a chain of uniform elastic catenary segments (Irvine, "Cable
// Structures", 1981, ch. 2; the multi-segment lines of mooring codes such as MoorPy and
// MAP++ are solved this way; docs/model.md, "Cables as built").
//
// The cable carries point masses m_j at arc lengths a_j and added weight per length d_k
// over ranges [A_k, B_k] (cable_attachment.h), s being unstretched arc length from the
// lower end. Cut the cable at every a_j, A_k and B_k below s0: between two cuts it is a
// uniform elastic catenary of weight per length w_seg = (rho + sum of the d_k covering
// it) g, length L_seg. Along the chain the horizontal force Fl is the same; the vertical
// force on the cable at s from below steps by w_seg L_seg over each segment and by m_j g
// at each point mass:
//   Fz(s) = Fz + sum_{segments below s} w_seg L_seg + sum_{a_j <= s} m_j g.
// The upper end lies at the sum of the segments' end-to-end vectors, each segment's from
// catenary.h with its own w_seg and its own lower-end force (Fl, Fz(s_seg)):
//   L = sum_seg span(Fl, Fz(s_seg), L_seg, EA, w_seg),  Z = sum_seg rise(...).
// The unknowns are the uniform cable's (Fl, Fz, s0): Fz(s_seg) - Fz does not depend on
// them, and only the last segment's length does on s0 (L_last = s0 - s_last), so
//   d(L, Z)/dFl = sum_seg d(span, rise)_seg/dFl,   d/dFz = sum_seg d_seg/dFz,
//   d(L, Z)/ds0 = d(span, rise)_last/dL_last.
// The lower-end tension (the sensor's, below every attachment) is sqrt(Fl^2 + Fz^2), the
// upper one sqrt(Fl^2 + Fz(s0)^2). Added density that reaches beyond s0 covers the rest
// of the cable; a point mass or a range starting at or beyond s0 is not on the cable
// (CatenaryChainBeyond).
//
// Templated on the scalar like catenary.h: the attachments' masses and densities may be
// ceres::Jets (a calibration estimates them); their positions are data (double).
#ifndef FASTCAL_CATENARY_CHAIN_H_
#define FASTCAL_CATENARY_CHAIN_H_

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "fastcal/cable_attachment.h"
#include "fastcal/catenary.h"
#include "fastcal/scalar.h"

namespace fastcal {

// Where the chain is cut: at a point mass, or where added weight starts or ends.
struct ChainCut {
  double s_m = 0.0;
  int attachment = 0;  // index into CatenaryChain::value
  // +1: a range starts here, -1: a range ends here, 0: a point mass.
  int step = 0;
};

// One cable's attachments as the statics use them: the cuts sorted by s (double) and each
// attachment's mass or added density (scalar T). Fixed size: no allocation per solve.
template <typename T>
struct CatenaryChain {
  using Cut = ChainCut;
  int num_cuts = 0;  // 0: a uniform cable
  std::array<Cut, 2 * kMaxAttachmentsPerCable> cuts{};
  // mass_kg of a point mass, added_density_kg_per_m of a range, by attachment.
  std::array<T, kMaxAttachmentsPerCable> value{};
  int num_attachments = 0;

  bool empty() const { return num_cuts == 0; }
};

// The chain of `attachments` (at most kMaxAttachmentsPerCable; more are ignored, which
// CableRobot::IsValid refuses before), values in double.
inline CatenaryChain<double> MakeCatenaryChain(const std::vector<CableAttachment>& attachments) {
  CatenaryChain<double> chain;
  const int n = std::min<int>(static_cast<int>(attachments.size()), kMaxAttachmentsPerCable);
  chain.num_attachments = n;
  for (int j = 0; j < n; ++j) {
    const CableAttachment& a = attachments[j];
    chain.value[j] = a.Value();
    if (a.kind == AttachmentKind::kPointMass) {
      chain.cuts[chain.num_cuts++] = {a.at_m, j, 0};
    } else {
      chain.cuts[chain.num_cuts++] = {a.from_m, j, +1};
      chain.cuts[chain.num_cuts++] = {a.to_m, j, -1};
    }
  }
  std::stable_sort(chain.cuts.begin(), chain.cuts.begin() + chain.num_cuts,
                   [](const auto& x, const auto& y) { return x.s_m < y.s_m; });
  return chain;
}

// The same chain with its values in double (the statics iterate in double).
template <typename T>
CatenaryChain<double> ScalarChain(const CatenaryChain<T>& c) {
  CatenaryChain<double> d;
  d.num_cuts = c.num_cuts;
  d.cuts = c.cuts;
  d.num_attachments = c.num_attachments;
  for (int j = 0; j < c.num_attachments; ++j) d.value[j] = ScalarValue(c.value[j]);
  return d;
}

// The first attachment that starts at or beyond s0 (a point mass, or a range's start),
// as its index into the chain's attachments, or -1 when every one is on the cable.
// *start_m receives where it starts.
inline int CatenaryChainBeyond(const CatenaryChain<double>& chain, double s0_m, double* start_m) {
  for (int k = 0; k < chain.num_cuts; ++k) {
    const auto& cut = chain.cuts[k];
    if (cut.step >= 0 && cut.s_m >= s0_m) {
      *start_m = cut.s_m;
      return cut.attachment;
    }
  }
  return -1;
}

// End point of the chain (the file comment), with the same partials and tensions as
// CatenaryEndpoint: a drop-in for it. Requires fl > 0, s0 > 0, ea > 0, w != 0, values
// >= 0. Cuts at or beyond s0 are not reached (CatenaryChainBeyond tells the statics);
// evaluated with s0 = s it gives the cable's point at arc length s.
template <typename T>
FASTCAL_ALWAYS_INLINE CatenaryEnd<T> CatenaryChainEndpoint(const T& fl_n, const T& fz_n,
                                                           const T& s0_m, const T& ea_n,
                                                           const T& w_n_per_m,
                                                           const CatenaryChain<T>& chain,
                                                           double gravity_m_per_s2) {
  using std::sqrt;
  CatenaryEnd<T> end;
  end.span_m = end.rise_m = T(0);
  for (int k = 0; k < 3; ++k) end.dspan[k] = end.drise[k] = T(0);
  T fz_seg = fz_n;      // vertical force at the segment's lower end
  T w_seg = w_n_per_m;  // its weight per length
  double s_seg = 0.0;   // where it starts
  const double s0 = ScalarValue(s0_m);
  auto add = [&end](const CatenaryEnd<T>& e) {
    end.span_m += e.span_m;
    end.rise_m += e.rise_m;
    for (int k = 0; k < 2; ++k) {  // Fl, Fz: every segment's lower force moves with them
      end.dspan[k] += e.dspan[k];
      end.drise[k] += e.drise[k];
    }
  };
  for (int k = 0; k < chain.num_cuts; ++k) {
    const auto& cut = chain.cuts[k];
    if (cut.s_m >= s0) break;
    const double length_m = cut.s_m - s_seg;
    if (length_m > 0.0) {
      const T l(length_m);
      add(CatenaryEndpoint(fl_n, fz_seg, l, ea_n, w_seg));
      fz_seg += w_seg * l;
      s_seg = cut.s_m;
    }
    const T weight = chain.value[cut.attachment] * gravity_m_per_s2;
    if (cut.step == 0) {
      fz_seg += weight;
    } else {
      w_seg += cut.step > 0 ? weight : -weight;
    }
  }
  const CatenaryEnd<T> last = CatenaryEndpoint(fl_n, fz_seg, s0_m - s_seg, ea_n, w_seg);
  add(last);
  end.dspan[2] = last.dspan[2];
  end.drise[2] = last.drise[2];
  end.lower_tension_n = sqrt(fl_n * fl_n + fz_n * fz_n);
  end.upper_tension_n = last.upper_tension_n;
  return end;
}

// What the chain adds to the lower end's Fz at a given Fl, to first order, relative to a
// uniform cable of weight per length w: each added weight W at arc length s is shared
// between the two ends as on a taut straight string, its lower end taking W (1 - s/s0),
// and the lower end's force on the cable moves by minus that. Used to start the statics
// (exact starts from the uniform cables' AAS) near the chain's solution.
inline double CatenaryChainLowerShareN(const CatenaryChain<double>& chain, double s0_m,
                                       double gravity_m_per_s2) {
  double share = 0.0;
  for (int k = 0; k < chain.num_cuts; ++k) {
    const auto& cut = chain.cuts[k];
    if (cut.step == 0) {
      if (cut.s_m < s0_m) {
        share += chain.value[cut.attachment] * gravity_m_per_s2 * (1.0 - cut.s_m / s0_m);
      }
    } else if (cut.step > 0) {
      // The range's weight per length integrated against (1 - s/s0) over [a, min(b, s0)].
      double b = s0_m;
      for (int m = 0; m < chain.num_cuts; ++m) {
        if (chain.cuts[m].step < 0 && chain.cuts[m].attachment == cut.attachment) {
          b = std::min(chain.cuts[m].s_m, s0_m);
        }
      }
      const double a = cut.s_m;
      if (a < b) {
        const double w = chain.value[cut.attachment] * gravity_m_per_s2;
        share += w * ((b - a) - (b * b - a * a) / (2.0 * s0_m));
      }
    }
  }
  return -share;
}

}  // namespace fastcal

#endif  // FASTCAL_CATENARY_CHAIN_H_
