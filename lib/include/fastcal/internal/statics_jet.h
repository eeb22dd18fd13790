// ModelLowerTensions: the statics solution replayed in scalar T (see statics_core.h).
#ifndef FASTCAL_INTERNAL_STATICS_JET_H_
#define FASTCAL_INTERNAL_STATICS_JET_H_

#include <array>
#include <cmath>

#include "fastcal/internal/statics_core.h"

namespace fastcal {

// SolveStatics for parameters already flattened per cable (statics.h).
StaticsStatus SolveStaticsWithParameters(const StaticsParameters<double>& parameters,
                                         const Pose& pose, const StaticsOptions& options,
                                         StaticsSolution* solution);

// The same at a sample's joint values: `parameters` with the mass centre moved by the
// cabin's moving parts `parts` at `joints` (moving_parts.h eq. (1)); without parts, as
// above, at no cost.
StaticsStatus SolveStaticsWithParameters(const StaticsParameters<double>& parameters,
                                         const MovingParts& parts, const JointValues& joints,
                                         const Pose& pose, const StaticsOptions& options,
                                         StaticsSolution* solution);

template <typename T>
StaticsStatus ModelLowerTensions(const StaticsParameters<T>& p, const Pose& pose,
                                 const StaticsOptions& options,
                                 std::array<T, kNumCables>* tension_n, StaticsSolution* solution,
                                 std::array<T, kNumCables>* length_m) {
  using std::sqrt;
  StaticsSolution local;
  StaticsSolution* sol = solution != nullptr ? solution : &local;
  StaticsOptions cold = options;
  cold.warm_start = solution != nullptr && options.warm_start;
  StaticsStatus status;
  if constexpr (kIsDouble<T>) {
    status = SolveStaticsWithParameters(p, pose, cold, sol);
    if (status != StaticsStatus::kOk) return status;
    for (int i = 0; i < kNumCables; ++i) (*tension_n)[i] = sol->cables[i].lower_tension_n;
    for (int i = 0; i < kNumCables && length_m != nullptr; ++i) {
      (*length_m)[i] = sol->cables[i].unstretched_length_m;
    }
    return status;
  } else {
    status = SolveStaticsWithParameters(ScalarParameters(p), pose, cold, sol);
    if (status != StaticsStatus::kOk) return status;
    internal::PoseGeometry<T> g;
    int cable = -1, iterations = 0;
    status =
        internal::ComputeGeometry(p, pose, options.catenary.vertical_span_fraction, &g, &cable);
    if (status != StaticsStatus::kOk) return status;
    std::array<internal::CableState<T>, kNumCables> st;
    if (options.method == StaticsMethod::kExact) {
      for (int i = 0; i < kNumCables; ++i) {
        const CableSolution& c = sol->cables[i];
        st[i] = {T(c.horizontal_force_n), T(c.force_n[2]), T(c.unstretched_length_m)};
      }
      status = internal::ReducedNewtonStep(p, g, &st, &cable, nullptr, nullptr);
      if (status != StaticsStatus::kOk) return status;
    } else {
      std::array<CatenaryForces, kNumCables> low, high;
      for (int i = 0; i < kNumCables; ++i) {
        low[i] = sol->cables[i].secant_low;
        high[i] = sol->cables[i].secant_high;
      }
      std::array<T, kNumCables> a, b, fl;
      status = internal::AasLines(p, g, options, true, &low, &high, &a, &b, &cable, &iterations);
      if (status != StaticsStatus::kOk) return status;
      if (!internal::SolveEquilibrium(g, a, b, &fl)) return StaticsStatus::kSingular;
      for (int i = 0; i < kNumCables; ++i) st[i] = {fl[i], a[i] * fl[i] + b[i], T(0)};
      if (options.method == StaticsMethod::kAasRefined) {
        const StaticsParameters<double> pd = ScalarParameters(p);
        internal::PoseGeometry<double> gd;
        internal::ComputeGeometry(pd, pose, options.catenary.vertical_span_fraction, &gd, &cable);
        // The double solve's steps, as many as it took to meet its tolerance.
        for (int step = 0; step < sol->outer_iterations; ++step) {
          std::array<CatenaryCurvePoint, kNumCables> guess;
          for (int i = 0; i < kNumCables; ++i) {
            guess[i] = internal::CurveGuess(ScalarValue(st[i].fl), gd, i, pd.ea_n[i], low[i],
                                            high[i], options, /*model_corrected=*/true);
          }
          status = internal::ProjectOnCurves(p, g, internal::AasLengthStageOptions(options), guess,
                                             &st, &cable, &iterations);
          if (status != StaticsStatus::kOk) return status;
          status = internal::ReducedNewtonStep(p, g, &st, &cable, nullptr, nullptr);
          if (status != StaticsStatus::kOk) return status;
        }
      }
    }
    for (int i = 0; i < kNumCables; ++i) {
      (*tension_n)[i] = sqrt(st[i].fl * st[i].fl + st[i].fz * st[i].fz);
    }
    for (int i = 0; i < kNumCables && length_m != nullptr; ++i) {
      (*length_m)[i] = options.method == StaticsMethod::kExact
                           ? st[i].s0
                           : T(sol->cables[i].unstretched_length_m);
    }
    return StaticsStatus::kOk;
  }
}

}  // namespace fastcal

#endif  // FASTCAL_INTERNAL_STATICS_JET_H_
