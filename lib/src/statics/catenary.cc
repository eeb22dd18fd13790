// Newton solvers for the elastic catenary's two inverse problems (see catenary.h for the
// equations). Both iterate on the end-point residual (span, rise) with the analytic
// Jacobian, a step limit that keeps the positive unknown (Fl, or s0) positive, and
// backtracking on the residual norm, which is what makes a cold start robust. The norm is
// kept squared: it is only compared, and a square root on it sat on the critical path.
#include "fastcal/catenary.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fastcal {
namespace {

// Never let one Newton step shrink a positive unknown by more than this fraction: a
// Newton step through zero lands on the mirror solution with Fl < 0 (model.md).
constexpr double kMaxShrinkFraction = 0.9;
// Backtracking halvings per Newton step.
constexpr int kMaxBacktracks = 30;
// Newton's error after a step of relative size d is about C d^2; C measured <= 1.5 over
// the FAST workspace for both problems (tests/catenary_test.cc checks the outcome). A
// step with C d^2 below the tolerance is accepted without another evaluation.
constexpr double kQuadraticConstant = 2.0;
// Relative accuracy of the parabolic start's horizontal force: it is only a start, and
// the parabolic model itself is ~3e-3 off.
constexpr double kGuessRelativeTolerance = 1e-3;
constexpr int kGuessMaxIterations = 100;

// std::hypot guards against overflow we cannot meet here and costs ~30x a sqrt.
inline double Norm2(double a, double b) { return std::sqrt(a * a + b * b); }
inline double SquaredNorm(double a, double b) { return a * a + b * b; }

bool AllFinite(std::initializer_list<double> values) {
  for (double v : values) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

// The two inverse problems. Unknowns u = (Fl, Fz) at fixed s0 (kFixedLength), or
// u = (Fz, s0) at fixed Fl; u[kPositive] must stay > 0.
template <bool kFixedLength>
struct Problem {
  static constexpr int kPositive = kFixedLength ? 0 : 1;
  double span_m, rise_m, ea_n, w_n_per_m, fixed_value;

  // Residual and 2x2 Jacobian (row-major) with respect to u.
  FASTCAL_ALWAYS_INLINE void Evaluate(const double u[2], double r[2], double jac[4]) const {
    const CatenaryEnd<double> e = kFixedLength
                                      ? CatenaryEndpoint(u[0], u[1], fixed_value, ea_n, w_n_per_m)
                                      : CatenaryEndpoint(fixed_value, u[0], u[1], ea_n, w_n_per_m);
    constexpr int c0 = kFixedLength ? 0 : 1;
    r[0] = e.span_m - span_m;
    r[1] = e.rise_m - rise_m;
    jac[0] = e.dspan[c0];
    jac[1] = e.dspan[c0 + 1];
    jac[2] = e.drise[c0];
    jac[3] = e.drise[c0 + 1];
  }
  // Whether a Newton step is small enough to leave an error C d^2 below `tolerance`, d
  // measured relative to its scale: forces relative to the lower-end tension (Fz alone
  // may be near zero), the length relative to itself. Squared: no root, no division.
  bool StepIsFinal(const double u[2], const double step[2], double tolerance) const {
    if (kFixedLength) {
      return kQuadraticConstant * (step[0] * step[0] + step[1] * step[1]) <=
             tolerance * (u[0] * u[0] + u[1] * u[1]);
    }
    return kQuadraticConstant * step[0] * step[0] <=
               tolerance * (fixed_value * fixed_value + u[0] * u[0]) &&
           kQuadraticConstant * step[1] * step[1] <= tolerance * u[1] * u[1];
  }
};

// What Newton does next at u (residual r, Jacobian jac, iteration it).
enum class NewtonMove {
  kConverged,  // the residual is within tolerance: stop, u unchanged
  kFinal,      // a step small enough to end on was applied to u: stop
  kTry,        // try u + lambda step, lambda = *lambda (1 unless a positive unknown limits it)
  kFail,       // non-finite, singular or out of iterations
};

template <bool kFixedLength>
FASTCAL_ALWAYS_INLINE NewtonMove NextNewtonMove(const Problem<kFixedLength>& problem,
                                                double tolerance_m,
                                                const CatenarySolverOptions& options, int it,
                                                double u[2], const double r[2], const double jac[4],
                                                double norm, double step[2], double* lambda) {
  constexpr int positive = Problem<kFixedLength>::kPositive;
  if (!std::isfinite(norm)) return NewtonMove::kFail;
  if (std::max(std::abs(r[0]), std::abs(r[1])) <= tolerance_m) return NewtonMove::kConverged;
  if (it == options.max_iterations) return NewtonMove::kFail;
  const double det = jac[0] * jac[3] - jac[1] * jac[2];
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return NewtonMove::kFail;
  const double inv_det = 1.0 / det;
  step[0] = -(jac[3] * r[0] - jac[1] * r[1]) * inv_det;
  step[1] = -(-jac[2] * r[0] + jac[0] * r[1]) * inv_det;
  if (problem.StepIsFinal(u, step, options.relative_tolerance) &&
      u[positive] + step[positive] > 0.0) {
    u[0] += step[0];
    u[1] += step[1];
    return NewtonMove::kFinal;
  }
  *lambda = 1.0;
  if (u[positive] + step[positive] < (1.0 - kMaxShrinkFraction) * u[positive]) {
    *lambda = kMaxShrinkFraction * u[positive] / -step[positive];
  }
  return NewtonMove::kTry;
}

// Newton from u (with its residual r, Jacobian jac and squared norm) at iteration `it`, with
// backtracking on the residual norm.
template <bool kFixedLength>
CatenaryStatus NewtonFrom(const Problem<kFixedLength>& problem, double tolerance_m,
                          const CatenarySolverOptions& options, int it, double u[2], double r[2],
                          double jac[4], double norm, int* iterations) {
  for (; it <= options.max_iterations; ++it) {
    double step[2], lambda = 1.0;
    const NewtonMove move =
        NextNewtonMove(problem, tolerance_m, options, it, u, r, jac, norm, step, &lambda);
    if (move == NewtonMove::kConverged || move == NewtonMove::kFinal) {
      *iterations = move == NewtonMove::kFinal ? it + 1 : it;
      return CatenaryStatus::kOk;
    }
    if (move == NewtonMove::kFail) break;
    double trial[2], r_trial[2], jac_trial[4], norm_trial = norm;
    bool accepted = false;
    for (int b = 0; b < kMaxBacktracks; ++b, lambda *= 0.5) {
      trial[0] = u[0] + lambda * step[0];
      trial[1] = u[1] + lambda * step[1];
      problem.Evaluate(trial, r_trial, jac_trial);
      norm_trial = SquaredNorm(r_trial[0], r_trial[1]);
      if (std::isfinite(norm_trial) && norm_trial < norm) {
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      // No decrease along the Newton direction: either converged to rounding (accept if
      // already close) or stuck.
      if (norm <= 1e6 * tolerance_m * tolerance_m) {  // |r| <= 1e3 tolerance
        *iterations = it;
        return CatenaryStatus::kOk;
      }
      break;
    }
    u[0] = trial[0];
    u[1] = trial[1];
    std::copy(r_trial, r_trial + 2, r);
    std::copy(jac_trial, jac_trial + 4, jac);
    norm = norm_trial;
  }
  *iterations = options.max_iterations;
  return CatenaryStatus::kNotConverged;
}

// chord_m: Norm2(span_m, rise_m), computed once per problem by the caller.
CatenaryStatus CheckCommon(double span_m, double rise_m, double chord_m, double ea_n,
                           double w_n_per_m, const CatenarySolverOptions& options) {
  if (!AllFinite({span_m, rise_m, ea_n, w_n_per_m}) || !(ea_n > 0.0) || w_n_per_m == 0.0 ||
      span_m < 0.0) {
    return CatenaryStatus::kInvalidInput;
  }
  if (span_m <= options.vertical_span_fraction * chord_m) {
    return CatenaryStatus::kVerticalChord;
  }
  return CatenaryStatus::kOk;
}

}  // namespace

const char* CatenaryStatusName(CatenaryStatus status) {
  switch (status) {
    case CatenaryStatus::kOk:
      return "ok";
    case CatenaryStatus::kInvalidInput:
      return "invalid input";
    case CatenaryStatus::kVerticalChord:
      return "vertical chord";
    case CatenaryStatus::kNotConverged:
      return "not converged";
  }
  return "unknown";
}

namespace {

// Vertical force at the lower end of the inextensible catenary with horizontal force H:
// Fz = -(w/2) s0 - (|w|/2) Z coth(lambda), lambda = |w| L / (2H) (for gravity, w < 0:
// (|w|/2)(s0 - Z coth)); ten times closer than its parabolic limit -H Z/L - w s0/2 over
// the workspace.
double InextensibleLowerFz(double span_m, double rise_m, double s0_m, double h_n,
                           double w_n_per_m) {
  const double lambda = std::abs(w_n_per_m) * span_m / (2.0 * h_n);
  return -0.5 * w_n_per_m * s0_m -
         0.5 * std::abs(w_n_per_m) * rise_m * StartCoth(lambda, 1.0 / lambda);
}

// CatenaryInitialGuess in three steps, so that a batch can run them in lockstep (Guess,
// ColdStarts): the start's division chain (~4 divisions, then one per Newton step) is
// latency, and independent chains side by side overlap.
//
// g(H) = H^2 (s0^2 (1 + c H)^2 - k^2) - b has its one positive root above
// H_t = max(0, (k/s0 - 1)/c) and is increasing and convex there, so Newton from an
// upper bound decreases monotonically onto the root. Upper bounds, with D^3 = b/(2 k s0 c):
//   g(H_t + D) >= 0                  (as s0 (1 + c H_t) >= k, g(H_t + d) >= 2 k s0 c d^3 - b)
//   g(H_t + D^3/H_t^2) >= 0, s0 < k   (same, with (H_t + d)^2 >= H_t^2)
//   g(sqrt(b/(s0^2 - k^2))) >= 0, s0 > k   (as (1 + c H)^2 >= 1)
// Taking the smaller of the two that apply leaves 1-4 Newton steps over the workspace.
struct GuessState {
  double k, s0, c, b, h;
};

GuessState GuessSetup(double span_m, double k, double s0_m, double ea_n, double w_n_per_m) {
  GuessState st;
  st.k = k;
  st.s0 = s0_m;
  st.c = k / (span_m * ea_n);
  st.b = w_n_per_m * w_n_per_m * (span_m * span_m) * (span_m * span_m) / 12.0;
  const double d3 = st.b / (2.0 * k * s0_m * st.c);
  if (s0_m < k) {
    const double h_t = (k / s0_m - 1.0) / st.c;
    const double d = d3 / (h_t * h_t);
    st.h = h_t + (d * d * d <= d3 ? d : std::cbrt(d3));
  } else {
    const double h_s = s0_m > k ? std::sqrt(st.b / (s0_m * s0_m - k * k)) : HUGE_VAL;
    st.h = h_s * h_s * h_s <= d3 ? h_s : std::cbrt(d3);
  }
  return st;
}

// One Newton step on g; true when the start is final.
FASTCAL_ALWAYS_INLINE bool GuessStep(GuessState* st) {
  const double h = st->h;
  const double q = st->s0 * (1.0 + st->c * h);
  const double qk = q * q - st->k * st->k;
  const double step = (h * h * qk - st->b) / (2.0 * h * qk + 2.0 * h * h * q * st->s0 * st->c);
  if (!(step > 0.0)) return true;  // at the root to rounding
  st->h = h - step;
  return step <= kGuessRelativeTolerance * st->h;
}

// CatenaryInitialGuess with the chord k = Norm2(span_m, rise_m) already known.
CatenaryForces Guess(double span_m, double rise_m, double k, double s0_m, double ea_n,
                     double w_n_per_m) {
  GuessState st = GuessSetup(span_m, k, s0_m, ea_n, w_n_per_m);
  for (int i = 0; i < kGuessMaxIterations && !GuessStep(&st); ++i) {
  }
  return CatenaryForces{st.h, InextensibleLowerFz(span_m, rise_m, s0_m, st.h, w_n_per_m)};
}

// Cold starts of problems[j], j in which[0..n), written to u[j]. At fixed length: Guess,
// in lockstep with the same results.
void ColdStarts(int n, const int* which, const CatenaryProblem* problems, const double* chord_m,
                double (*u)[2]) {
  GuessState st[kMaxCatenaryBatch];
  int active[kMaxCatenaryBatch];
  for (int a = 0; a < n; ++a) {
    const CatenaryProblem& c = problems[which[a]];
    st[a] = GuessSetup(c.span_m, chord_m[which[a]], c.s0_m, c.ea_n, c.w_n_per_m);
    active[a] = a;
  }
  for (int i = 0, num_active = n; i < kGuessMaxIterations && num_active > 0; ++i) {
    int still = 0;
    for (int q = 0; q < num_active; ++q) {
      if (!GuessStep(&st[active[q]])) active[still++] = active[q];
    }
    num_active = still;
  }
  for (int a = 0; a < n; ++a) {
    const CatenaryProblem& c = problems[which[a]];
    u[which[a]][0] = st[a].h;
    u[which[a]][1] = InextensibleLowerFz(c.span_m, c.rise_m, c.s0_m, st[a].h, c.w_n_per_m);
  }
}

// At fixed horizontal force: the parabolic model's point (explicit, nothing to overlap).
void ColdStarts(int n, const int* which, const CatenaryLengthProblem* problems,
                const double* /*chord_m*/, double (*u)[2]) {
  for (int a = 0; a < n; ++a) {
    const CatenaryLengthProblem& c = problems[which[a]];
    const CatenaryCurvePoint start =
        ParabolicCatenaryModel(c.span_m, c.rise_m, c.ea_n, c.w_n_per_m).AtHorizontalForce(c.fl_n);
    u[which[a]][0] = start.fz_n;
    u[which[a]][1] = start.s0_m;
  }
}

}  // namespace

CatenaryForces CatenaryInitialGuess(double span_m, double rise_m, double s0_m, double ea_n,
                                    double w_n_per_m) {
  return Guess(span_m, rise_m, Norm2(span_m, rise_m), s0_m, ea_n, w_n_per_m);
}

namespace {

Problem</*kFixedLength=*/true> MakeProblem(const CatenaryProblem& c) {
  return {c.span_m, c.rise_m, c.ea_n, c.w_n_per_m, c.s0_m};
}
Problem</*kFixedLength=*/false> MakeProblem(const CatenaryLengthProblem& c) {
  return {c.span_m, c.rise_m, c.ea_n, c.w_n_per_m, c.fl_n};
}

// Checks a problem and writes its start to u, (Fl, Fz) at fixed length, from its guess;
// without one, *needs_guess is set and the caller runs ColdStarts for the batch.
CatenaryStatus Start(const CatenaryProblem& c, double chord_m, const CatenarySolverOptions& options,
                     double u[2], bool* needs_guess) {
  if (!std::isfinite(c.s0_m) || !(c.s0_m > 0.0)) return CatenaryStatus::kInvalidInput;
  const CatenaryStatus common =
      CheckCommon(c.span_m, c.rise_m, chord_m, c.ea_n, c.w_n_per_m, options);
  if (common != CatenaryStatus::kOk) return common;
  if (c.guess != nullptr && c.guess->fl_n > 0.0 && AllFinite({c.guess->fl_n, c.guess->fz_n})) {
    u[0] = c.guess->fl_n;
    u[1] = c.guess->fz_n;
  } else {
    *needs_guess = true;
  }
  return CatenaryStatus::kOk;
}

// The same at fixed horizontal force: u = (Fz, s0).
CatenaryStatus Start(const CatenaryLengthProblem& c, double chord_m,
                     const CatenarySolverOptions& options, double u[2], bool* needs_guess) {
  if (!std::isfinite(c.fl_n) || !(c.fl_n > 0.0)) return CatenaryStatus::kInvalidInput;
  const CatenaryStatus common =
      CheckCommon(c.span_m, c.rise_m, chord_m, c.ea_n, c.w_n_per_m, options);
  if (common != CatenaryStatus::kOk) return common;
  if (c.guess != nullptr && c.guess->s0_m > 0.0 && AllFinite({c.guess->fz_n, c.guess->s0_m})) {
    u[0] = c.guess->fz_n;
    u[1] = c.guess->s0_m;
  } else {
    *needs_guess = true;
  }
  return CatenaryStatus::kOk;
}

// Newton on n independent problems in lockstep: each takes exactly the iterations it
// would take alone (anything off the plain full-step path continues in NewtonFrom from
// that point), but each loop below runs over independent problems, so no iteration
// waits on another's square roots, divisions and logarithm. u[j] receives the solution
// and, when `jacobians` is not null, jacobians[j] its last evaluation's Jacobian.
template <typename Spec>
void SolveBatch(int n, const Spec* specs, const CatenarySolverOptions& options, double (*u)[2],
                CatenaryStatus* statuses, int* iterations, double (*jacobians)[4]) {
  using P = decltype(MakeProblem(specs[0]));
  struct State {
    P problem;
    double tolerance_m, norm, lambda;
    double r[2], jac[4], step[2], trial[2], r_trial[2], jac_trial[4];
  };
  State st[kMaxCatenaryBatch];
  int active[kMaxCatenaryBatch], num_active = 0;
  int cold[kMaxCatenaryBatch], num_cold = 0;
  double chord_m[kMaxCatenaryBatch];
  n = std::min(n, kMaxCatenaryBatch);
  for (int j = 0; j < n; ++j) {
    iterations[j] = 0;
    chord_m[j] = Norm2(specs[j].span_m, specs[j].rise_m);
    bool needs_guess = false;
    statuses[j] = Start(specs[j], chord_m[j], options, u[j], &needs_guess);
    if (statuses[j] != CatenaryStatus::kOk) continue;
    if (needs_guess) cold[num_cold++] = j;
    st[j].problem = MakeProblem(specs[j]);
    st[j].tolerance_m = options.relative_tolerance * chord_m[j];
    active[num_active++] = j;
  }
  if (num_cold > 0) ColdStarts(num_cold, cold, specs, chord_m, u);
  for (int a = 0; a < num_active; ++a) {
    State& s = st[active[a]];
    s.problem.Evaluate(u[active[a]], s.r, s.jac);
    s.norm = SquaredNorm(s.r[0], s.r[1]);
  }
  for (int it = 0; num_active > 0; ++it) {
    int pending[kMaxCatenaryBatch], num_pending = 0;
    for (int a = 0; a < num_active; ++a) {
      const int j = active[a];
      State& s = st[j];
      const NewtonMove move = NextNewtonMove(s.problem, s.tolerance_m, options, it, u[j], s.r,
                                             s.jac, s.norm, s.step, &s.lambda);
      if (move == NewtonMove::kConverged || move == NewtonMove::kFinal) {
        iterations[j] = move == NewtonMove::kFinal ? it + 1 : it;
      } else if (move == NewtonMove::kTry && s.lambda == 1.0) {
        pending[num_pending++] = j;
      } else {
        statuses[j] = NewtonFrom(s.problem, s.tolerance_m, options, it, u[j], s.r, s.jac, s.norm,
                                 &iterations[j]);
      }
    }
    for (int q = 0; q < num_pending; ++q) {
      const int j = pending[q];
      State& s = st[j];
      s.trial[0] = u[j][0] + s.step[0];
      s.trial[1] = u[j][1] + s.step[1];
      s.problem.Evaluate(s.trial, s.r_trial, s.jac_trial);
    }
    num_active = 0;
    for (int q = 0; q < num_pending; ++q) {
      const int j = pending[q];
      State& s = st[j];
      const double norm_trial = SquaredNorm(s.r_trial[0], s.r_trial[1]);
      if (std::isfinite(norm_trial) && norm_trial < s.norm) {
        std::copy(s.trial, s.trial + 2, u[j]);
        std::copy(s.r_trial, s.r_trial + 2, s.r);
        std::copy(s.jac_trial, s.jac_trial + 4, s.jac);
        s.norm = norm_trial;
        active[num_active++] = j;
      } else {
        statuses[j] = NewtonFrom(s.problem, s.tolerance_m, options, it, u[j], s.r, s.jac, s.norm,
                                 &iterations[j]);
      }
    }
  }
  for (int j = 0; j < n && jacobians != nullptr; ++j) {
    if (statuses[j] == CatenaryStatus::kOk) std::copy(st[j].jac, st[j].jac + 4, jacobians[j]);
  }
}

}  // namespace

namespace {

// SolveBatch with each solution converted to its public type, written where ok.
template <typename Spec, typename Out>
void SolveBatchInto(int n, const Spec* problems, const CatenarySolverOptions& options, Out* out,
                    CatenaryStatus* statuses, int* iterations, double (*jacobians)[4] = nullptr) {
  double u[kMaxCatenaryBatch][2];
  SolveBatch(n, problems, options, u, statuses, iterations, jacobians);
  for (int j = 0; j < std::min(n, kMaxCatenaryBatch); ++j) {
    if (statuses[j] == CatenaryStatus::kOk) out[j] = Out{u[j][0], u[j][1]};
  }
}

}  // namespace

void SolveCatenaryForcesBatch(int n, const CatenaryProblem* problems,
                              const CatenarySolverOptions& options, CatenaryForces* forces,
                              CatenaryStatus* statuses, int* iterations, double (*jacobians)[4]) {
  SolveBatchInto(n, problems, options, forces, statuses, iterations, jacobians);
}

void SolveCatenaryLengthBatch(int n, const CatenaryLengthProblem* problems,
                              const CatenarySolverOptions& options, CatenaryCurvePoint* points,
                              CatenaryStatus* statuses, int* iterations, double (*jacobians)[4]) {
  SolveBatchInto(n, problems, options, points, statuses, iterations, jacobians);
}

CatenaryStatus SolveCatenaryForcesDouble(double span_m, double rise_m, double s0_m, double ea_n,
                                         double w_n_per_m, const CatenarySolverOptions& options,
                                         const CatenaryForces* guess, CatenaryForces* forces,
                                         int* iterations) {
  const CatenaryProblem problem{span_m, rise_m, s0_m, ea_n, w_n_per_m, guess};
  CatenaryStatus status;
  SolveCatenaryForcesBatch(1, &problem, options, forces, &status, iterations);
  return status;
}

CatenaryStatus SolveCatenaryLengthDouble(double span_m, double rise_m, double fl_n, double ea_n,
                                         double w_n_per_m, const CatenarySolverOptions& options,
                                         const CatenaryCurvePoint* guess, CatenaryCurvePoint* point,
                                         int* iterations) {
  const CatenaryLengthProblem problem{span_m, rise_m, fl_n, ea_n, w_n_per_m, guess};
  CatenaryStatus status;
  SolveCatenaryLengthBatch(1, &problem, options, point, &status, iterations);
  return status;
}

std::vector<CatenaryPoint> CatenaryShape(double fl_n, double fz_n, double s0_m, double ea_n,
                                         double w_n_per_m, int n) {
  std::vector<CatenaryPoint> points;
  n = std::max(n, 2);
  points.reserve(n);
  for (int i = 0; i < n; ++i) {
    const double s = s0_m * i / (n - 1);
    CatenaryPoint p;
    p.s_m = s;
    if (i == 0) {
      p.span_m = 0.0;
      p.rise_m = 0.0;
    } else {
      const CatenaryEnd<double> e = CatenaryEndpoint(fl_n, fz_n, s, ea_n, w_n_per_m);
      p.span_m = e.span_m;
      p.rise_m = e.rise_m;
    }
    p.tension_n = CatenaryTension(fl_n, fz_n, s, w_n_per_m);
    points.push_back(p);
  }
  return points;
}

}  // namespace fastcal
