// One cable: the elastic catenary (Irvine 1981; paper eqs. 6, 11-18; docs/model.md).
//
// Each cable is a plane problem in its vertical plane. With w = rho g (N/m, negative: z
// up), the lower end at the origin, Fl > 0 the horizontal and Fz the vertical force
// applied ON the cable at its lower end by the cabin, and s0 the unstretched length, the
// upper end lands at horizontal distance L (the span) and height Z (the rise):
//
//   L = Fl s0/EA + (Fl/w) [asinh((Fz + w s0)/Fl) - asinh(Fz/Fl)]
//   Z = -Fz s0/EA - w s0^2/(2 EA) - (1/w) [T1 - T0]
//   T0 = sqrt(Fl^2 + Fz^2)  (lower-end tension),  T1 = sqrt(Fl^2 + (Fz + w s0)^2)  (upper)
//
// Implemented in a cancellation-free form so the limits w -> 0 (straight elastic bar)
// and EA -> infinity (inextensible catenary) stay accurate:
//   S = T0 + T1,  P = Fz (2 Fz + w s0)/S,  Q = T0 - P
//   T1 - T0 = w s0 (2 Fz + w s0)/S
//   asinh(a1) - asinh(a0) = asinh(w s0 Q / Fl^2)      [asinh x - asinh y = asinh(x sqrt(1+y^2) - y
//   sqrt(1+x^2))]
// and the partial derivatives (for Newton and for implicit differentiation):
//   dL/dFl = s0/EA + D/w - s0 Q/(T0 T1)         D = asinh(w s0 Q/Fl^2)
//   dL/dFz = -Fl s0 (2 Fz + w s0)/(S T0 T1)
//   dL/ds0 = Fl/EA + Fl/T1
//   dZ/dFl = Fl s0 (2 Fz + w s0)/(S T0 T1)
//   dZ/dFz = -s0/EA - s0 Q/(T0 T1)
//   dZ/ds0 = -(Fz + w s0)/EA - (Fz + w s0)/T1
//
// Everything here is templated on the scalar so ceres::Jet passes through. The inverse
// solves iterate in double; for a Jet they end with one Newton step in Jet arithmetic
// from the converged point, which carries exactly the implicit-function derivatives.
#ifndef FASTCAL_CATENARY_H_
#define FASTCAL_CATENARY_H_

#include <cmath>
#include <string>
#include <type_traits>
#include <vector>

#include "fastcal/scalar.h"

namespace fastcal {

// D = asinh((Fz + w s0)/Fl) - asinh(Fz/Fl) (eq. 14's bracket). In general D = asinh(x)
// with x = sinh D = w s0 Q / Fl^2 (the form that does not cancel, docs/model.md). For
// double, where Fz and Fz1 = Fz + w s0 have one sign (always for FAST: Fz1 < Fz < 0) and
// |D| >= 1/16, exp D = (Fz1 + T1) / (Fz + T0) with each factor in whichever of its forms,
// F + T or Fl^2 / (T - F), does not cancel: one division like x's, and no square root
// (asinh's sqrt(1 + x^2) sat on every evaluation's critical path). Below |D| = 1/16 the
// log of a ratio near 1 loses relative accuracy, and asinh is used.
template <typename T>
FASTCAL_ALWAYS_INLINE T CatenaryAngleDifference(const T& fz_n, const T& fz1_n, const T& t0_n,
                                                const T& t1_n, const T& ws, const T& q,
                                                const T& fl2) {
  if constexpr (std::is_same_v<T, double>) {
    constexpr double kMinRatio = 0.9394130628134758;  // exp(-1/16)
    constexpr double kMaxRatio = 1.0644944589178593;  // exp(1/16)
    const bool up = fz_n >= 0.0;
    if (up == (fz1_n >= 0.0)) {
      const double ratio = up ? (fz1_n + t1_n) / (fz_n + t0_n) : (t0_n - fz_n) / (t1_n - fz1_n);
      if (ratio <= kMinRatio || ratio >= kMaxRatio) return std::log(ratio);
    }
  }
  return Asinh(ws * q / fl2);
}

// Span and rise of the upper end and their partials with respect to (Fl, Fz, s0).
template <typename T>
struct CatenaryEnd {
  T span_m;
  T rise_m;
  T dspan[3];         // d span / d(Fl, Fz, s0)
  T drise[3];         // d rise / d(Fl, Fz, s0)
  T lower_tension_n;  // T0, computed on the way (free where a caller needs it)
  T upper_tension_n;  // T1
};

// Forward map (eqs. 14-16 in the cable plane). Requires fl > 0, s0 > 0, ea > 0, w != 0.
// Always inlined: the compiler then drops the partials a caller does not use, and the
// batch solves' loops see the whole evaluation (~10% of a statics solve).
template <typename T>
FASTCAL_ALWAYS_INLINE CatenaryEnd<T> CatenaryEndpoint(const T& fl_n, const T& fz_n, const T& s0_m,
                                                      const T& ea_n, const T& w_n_per_m) {
  using std::sqrt;
  // 1/w first, off the critical path: D comes from a logarithm, and a division after it
  // would add its latency to every evaluation.
  const T inv_w = T(1) / w_n_per_m;
  const T ws = w_n_per_m * s0_m;
  const T fz1 = fz_n + ws;
  const T fl2 = fl_n * fl_n;
  const T t0 = sqrt(fl2 + fz_n * fz_n);
  const T t1 = sqrt(fl2 + fz1 * fz1);
  const T s = t0 + t1;
  const T t0t1 = t0 * t1;
  // One division for 1/S, 1/(T0 T1) and 1/T1: divisions dominate the cost of a solve.
  const T inv_s_t0t1 = T(1) / (s * t0t1);
  const T inv_s = inv_s_t0t1 * t0t1;
  const T inv_t0t1 = inv_s_t0t1 * s;
  const T inv_t1 = inv_t0t1 * t0;
  const T inv_ea = T(1) / ea_n;
  const T two_fz_ws = fz_n + fz1;
  const T p = fz_n * two_fz_ws * inv_s;
  const T q = t0 - p;
  const T d = CatenaryAngleDifference(fz_n, fz1, t0, t1, ws, q, fl2);
  const T d_over_w = d * inv_w;
  const T cross = s0_m * two_fz_ws * inv_s_t0t1;
  const T s0_q_t0t1 = s0_m * q * inv_t0t1;
  CatenaryEnd<T> end;
  end.lower_tension_n = t0;
  end.upper_tension_n = t1;
  end.span_m = (fl_n * s0_m) * inv_ea + fl_n * d_over_w;
  end.rise_m = -(fz_n + T(0.5) * ws) * s0_m * inv_ea - s0_m * two_fz_ws * inv_s;
  end.dspan[0] = s0_m * inv_ea + d_over_w - s0_q_t0t1;
  end.dspan[1] = -fl_n * cross;
  end.dspan[2] = fl_n * (inv_ea + inv_t1);
  end.drise[0] = fl_n * cross;
  end.drise[1] = -s0_m * inv_ea - s0_q_t0t1;
  end.drise[2] = -fz1 * (inv_ea + inv_t1);
  return end;
}

// Tension at unstretched arc length s from the lower end (eq. 6).
template <typename T>
T CatenaryTension(const T& fl_n, const T& fz_n, const T& s_m, const T& w_n_per_m) {
  using std::sqrt;
  const T fz1 = fz_n + w_n_per_m * s_m;
  return sqrt(fl_n * fl_n + fz1 * fz1);
}

enum class CatenaryStatus {
  kOk = 0,
  kInvalidInput,   // non-finite, non-positive s0/EA, zero density or non-positive Fl given
  kVerticalChord,  // span ~ 0: the horizontal force direction is undefined
  kNotConverged,   // Newton did not reach the tolerance in max_iterations
};
const char* CatenaryStatusName(CatenaryStatus status);

struct CatenarySolverOptions {
  // Converged when both end-point residuals are below this fraction of the chord length.
  double relative_tolerance = 1e-12;
  // Newton iterations before giving up with kNotConverged.
  int max_iterations = 50;
  // A chord whose span is below this fraction of its length counts as vertical.
  double vertical_span_fraction = 1e-9;
};

// Lower-end forces, optionally the starting point of a solve.
struct CatenaryForces {
  double fl_n = 0.0;
  double fz_n = 0.0;
};

// Inverse problem at fixed length: the (Fl, Fz), Fl > 0, that put the upper end at
// (span, rise) for unstretched length s0. `guess` (may be null) starts Newton; otherwise
// a start from the parabolic elastic-catenary approximation is used, which converges for
// s0 in [0.95 k, 1.05 k] across the FAST workspace (tests/catenary_test.cc).
CatenaryStatus SolveCatenaryForcesDouble(double span_m, double rise_m, double s0_m, double ea_n,
                                         double w_n_per_m, const CatenarySolverOptions& options,
                                         const CatenaryForces* guess, CatenaryForces* forces,
                                         int* iterations);

// Inverse problem at fixed horizontal force: the (Fz, s0) for which a cable pulled with
// horizontal force fl reaches (span, rise). This is the point on the cable's Fz(Fl) curve
// (the one-parameter family of lengths) at Fl = fl.
struct CatenaryCurvePoint {
  double fz_n = 0.0;
  double s0_m = 0.0;
};
CatenaryStatus SolveCatenaryLengthDouble(double span_m, double rise_m, double fl_n, double ea_n,
                                         double w_n_per_m, const CatenarySolverOptions& options,
                                         const CatenaryCurvePoint* guess, CatenaryCurvePoint* point,
                                         int* iterations);

// Starting point used when no guess is given: solves the parabolic approximation
//   s0^2 (1 + H k/(L EA))^2 - k^2 = w^2 L^4 / (12 H^2)
// for the horizontal force H, then Fz from the inextensible catenary with that H.
CatenaryForces CatenaryInitialGuess(double span_m, double rise_m, double s0_m, double ea_n,
                                    double w_n_per_m);
// coth(lambda) for the starts' inextensible-catenary Fz, given also 1/lambda: its Laurent
// series to lambda^5 below lambda = 0.5 (within 1e-6 relative, plenty for a start that is
// itself ~1e-3 off; FAST's cables have lambda in ~[0.05, 0.6]), else from one exp (tanh
// costs three times as much).
inline double StartCoth(double lambda, double inv_lambda) {
  if (lambda < 0.5) {
    const double l2 = lambda * lambda;
    return inv_lambda + lambda * (1.0 / 3.0 + l2 * (-1.0 / 45.0 + l2 * (2.0 / 945.0)));
  }
  const double e = std::exp(-2.0 * lambda);
  return (1.0 + e) / (1.0 - e);
}

// The same parabolic relation for one chord, solved for s0 at a given H = Fl (explicit),
// Fz as above: a point near the cable's Fz(Fl) curve. Its error varies slowly along the
// family of lengths; the statics' AAS corrects it by its error at the two secant points,
// where the exact points are known. Inline: evaluated three times per cable, side by side.
class ParabolicCatenaryModel {
 public:
  ParabolicCatenaryModel(double span_m, double rise_m, double ea_n, double w_n_per_m)
      : ParabolicCatenaryModel(span_m, rise_m, std::sqrt(span_m * span_m + rise_m * rise_m), ea_n,
                               w_n_per_m) {}
  // With the chord k = sqrt(span^2 + rise^2) already known.
  ParabolicCatenaryModel(double span_m, double rise_m, double chord_m, double ea_n,
                         double w_n_per_m)
      : k_(chord_m),
        c_(k_ / (span_m * ea_n)),
        b_(w_n_per_m * w_n_per_m * (span_m * span_m) * (span_m * span_m) / 12.0),
        half_w_(0.5 * w_n_per_m),
        half_abs_w_(0.5 * std::abs(w_n_per_m)),
        rise_m_(rise_m),
        lambda_h_(half_abs_w_ * span_m),
        inv_lambda_h_(1.0 / lambda_h_) {}

  // For 0 < Fl below ~1e150 N (k Fl and Fl (1 + c Fl) must stay within double's range;
  // beyond that s0 is not finite): far above any cable's force.
  CatenaryCurvePoint AtHorizontalForce(double fl_n) const {
    // 1/Fl and 1/(1 + c Fl) from one division; s0 = sqrt(k^2 + b/Fl^2)/(1 + c Fl).
    const double q = 1.0 + c_ * fl_n;
    const double inv_fl_q = 1.0 / (fl_n * q);
    const double inv_fl = q * inv_fl_q;
    const double s0_m = std::sqrt(k_ * k_ * (fl_n * fl_n) + b_) * inv_fl_q;
    // Fz of CatenaryInitialGuess (the inextensible catenary), lambda = lambda_h / H.
    const double coth = StartCoth(lambda_h_ * inv_fl, fl_n * inv_lambda_h_);
    return CatenaryCurvePoint{-half_w_ * s0_m - half_abs_w_ * rise_m_ * coth, s0_m};
  }

 private:
  double k_, c_, b_, half_w_, half_abs_w_, rise_m_, lambda_h_, inv_lambda_h_;
};

// Templated wrappers. For T = double they are the solves above; for a Jet they add one
// Newton step in Jet arithmetic at the converged point (implicit differentiation).
template <typename T>
CatenaryStatus SolveCatenaryForces(const T& span_m, const T& rise_m, const T& s0_m, const T& ea_n,
                                   const T& w_n_per_m, const CatenarySolverOptions& options,
                                   const CatenaryForces* guess, T* fl_n, T* fz_n,
                                   int* iterations = nullptr) {
  CatenaryForces f;
  int it = 0;
  const CatenaryStatus status =
      SolveCatenaryForcesDouble(ScalarValue(span_m), ScalarValue(rise_m), ScalarValue(s0_m),
                                ScalarValue(ea_n), ScalarValue(w_n_per_m), options, guess, &f, &it);
  if (iterations != nullptr) *iterations = it;
  if (status != CatenaryStatus::kOk) return status;
  if constexpr (kIsDouble<T>) {
    *fl_n = f.fl_n;
    *fz_n = f.fz_n;
  } else {
    const T fl(f.fl_n), fz(f.fz_n);
    const CatenaryEnd<T> e = CatenaryEndpoint(fl, fz, s0_m, ea_n, w_n_per_m);
    const T r0 = e.span_m - span_m, r1 = e.rise_m - rise_m;
    const T det = e.dspan[0] * e.drise[1] - e.dspan[1] * e.drise[0];
    *fl_n = fl - (e.drise[1] * r0 - e.dspan[1] * r1) / det;
    *fz_n = fz - (-e.drise[0] * r0 + e.dspan[0] * r1) / det;
  }
  return CatenaryStatus::kOk;
}

template <typename T>
CatenaryStatus SolveCatenaryLength(const T& span_m, const T& rise_m, const T& fl_n, const T& ea_n,
                                   const T& w_n_per_m, const CatenarySolverOptions& options,
                                   const CatenaryCurvePoint* guess, T* fz_n, T* s0_m,
                                   int* iterations = nullptr) {
  CatenaryCurvePoint c;
  int it = 0;
  const CatenaryStatus status =
      SolveCatenaryLengthDouble(ScalarValue(span_m), ScalarValue(rise_m), ScalarValue(fl_n),
                                ScalarValue(ea_n), ScalarValue(w_n_per_m), options, guess, &c, &it);
  if (iterations != nullptr) *iterations = it;
  if (status != CatenaryStatus::kOk) return status;
  if constexpr (kIsDouble<T>) {
    *fz_n = c.fz_n;
    *s0_m = c.s0_m;
  } else {
    const T fz(c.fz_n), s0(c.s0_m);
    const CatenaryEnd<T> e = CatenaryEndpoint(fl_n, fz, s0, ea_n, w_n_per_m);
    const T r0 = e.span_m - span_m, r1 = e.rise_m - rise_m;
    // Columns (Fz, s0) of the Jacobian.
    const T det = e.dspan[1] * e.drise[2] - e.dspan[2] * e.drise[1];
    *fz_n = fz - (e.drise[2] * r0 - e.dspan[2] * r1) / det;
    *s0_m = s0 - (-e.drise[1] * r0 + e.dspan[1] * r1) / det;
  }
  return CatenaryStatus::kOk;
}

// Several independent solves at once, with the same iterations and results as one at a
// time, run in lockstep so that the processor overlaps their latency chains (square
// roots, divisions and a logarithm per evaluation): the statics' twelve AAS secant solves
// take ~40% less time this way. At most kMaxCatenaryBatch problems; `guess` may be null;
// forces[j] / points[j] are written when statuses[j] is kOk.
inline constexpr int kMaxCatenaryBatch = 16;
struct CatenaryProblem {  // SolveCatenaryForcesDouble's arguments
  double span_m = 0.0, rise_m = 0.0, s0_m = 0.0, ea_n = 0.0, w_n_per_m = 0.0;
  const CatenaryForces* guess = nullptr;
};
// jacobians (may be null): d(span, rise)/d(Fl, Fz), row-major, at each solve's last
// evaluation (the returned forces, or one final Newton step before them), where ok.
void SolveCatenaryForcesBatch(int n, const CatenaryProblem* problems,
                              const CatenarySolverOptions& options, CatenaryForces* forces,
                              CatenaryStatus* statuses, int* iterations,
                              double (*jacobians)[4] = nullptr);
struct CatenaryLengthProblem {  // SolveCatenaryLengthDouble's arguments
  double span_m = 0.0, rise_m = 0.0, fl_n = 0.0, ea_n = 0.0, w_n_per_m = 0.0;
  const CatenaryCurvePoint* guess = nullptr;
};
// jacobians (may be null): d(span, rise)/d(Fz, s0), row-major, at each solve's last
// evaluation (the returned point, or one final Newton step before it), where ok.
void SolveCatenaryLengthBatch(int n, const CatenaryLengthProblem* problems,
                              const CatenarySolverOptions& options, CatenaryCurvePoint* points,
                              CatenaryStatus* statuses, int* iterations,
                              double (*jacobians)[4] = nullptr);

// A point of the cable's shape (eqs. 11-13, in the cable plane) with the tension there.
struct CatenaryPoint {
  double s_m;     // unstretched arc length from the lower end
  double span_m;  // horizontal distance from the lower end
  double rise_m;  // height above the lower end
  double tension_n;
};
// n >= 2 points evenly spaced in s over [0, s0].
std::vector<CatenaryPoint> CatenaryShape(double fl_n, double fz_n, double s0_m, double ea_n,
                                         double w_n_per_m, int n);

}  // namespace fastcal

#endif  // FASTCAL_CATENARY_H_
