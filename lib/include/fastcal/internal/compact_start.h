// A statics warm start small enough to keep one per sample (issue 20: the calibration
// kept a whole StaticsSolution, 1240 bytes, per sample as its warm start: 1.2 GB at 10^6).
//
// What a warm start at the same pose reads from the solution before (statics.cc,
// PreviousSolve): exact, each cable's state (Fl, Fz, s0); aas and aas-refined, each
// cable's secant forces (Fl, Fz at the low and the high secant). Four numbers a cable:
// 192 bytes. Doubles, not floats: aas's secant solves stop at a tolerance, so their
// result moves with the start; from a float-rounded start the fit's cost became rough at
// that level and Levenberg-Marquardt took 11 iterations on a circle where exact takes 6
// (CalibrationTest.AasForwardModelConvergesLikeExact). Path extrapolation (has_previous)
// is not kept: the calibration restarts each sample at its own pose.
#ifndef FASTCAL_INTERNAL_COMPACT_START_H_
#define FASTCAL_INTERNAL_COMPACT_START_H_

#include <algorithm>
#include <array>
#include <vector>

#include "fastcal/statics.h"

namespace fastcal::internal {

struct CompactStart {
  // Per cable: exact (Fl, Fz, s0, 0); aas, aas-refined (low Fl, low Fz, high Fl, high Fz).
  // All zero: no start (the solve starts cold).
  std::array<std::array<double, 4>, kNumCables> v{};

  bool has_start() const { return v[0][0] > 0.0; }

  // From a solution of `method` (none when it did not succeed).
  static CompactStart Of(const StaticsSolution& s) {
    CompactStart c;
    if (s.status != StaticsStatus::kOk) return c;
    for (int i = 0; i < kNumCables; ++i) {
      const CableSolution& k = s.cables[i];
      if (s.method == StaticsMethod::kExact) {
        c.v[i] = {static_cast<double>(k.horizontal_force_n), static_cast<double>(k.force_n[2]),
                  static_cast<double>(k.unstretched_length_m), 0.0};
      } else {
        c.v[i] = {static_cast<double>(k.secant_low.fl_n), static_cast<double>(k.secant_low.fz_n),
                  static_cast<double>(k.secant_high.fl_n), static_cast<double>(k.secant_high.fz_n)};
      }
    }
    return c;
  }

  // Makes `s` a warm start for `method` at `pose` (status ok), or a cold one without a
  // start (status other than ok).
  void Restore(const Pose& pose, StaticsMethod method, StaticsSolution* s) const {
    s->status = has_start() ? StaticsStatus::kOk : StaticsStatus::kInvalidInput;
    s->method = method;
    s->pose = pose;
    s->has_previous = false;
    for (int i = 0; i < kNumCables; ++i) {
      CableSolution& k = s->cables[i];
      if (method == StaticsMethod::kExact) {
        k.horizontal_force_n = v[i][0];
        k.force_n[2] = v[i][1];
        k.unstretched_length_m = v[i][2];
      } else {
        k.secant_low = {v[i][0], v[i][1]};
        k.secant_high = {v[i][2], v[i][3]};
      }
    }
  }
};

// One warm start per sample, packed: exact keeps 3 numbers a cable (144 bytes a sample),
// aas and aas-refined 4 (192 bytes). A CompactStart array spent 4 on every method: 48 MB
// at 10^6 samples for the zeros of exact's (issue 28). Unset samples have no start.
class CompactStarts {
 public:
  explicit CompactStarts(StaticsMethod method = StaticsMethod::kExact)
      : method_(method), stride_(method == StaticsMethod::kExact ? 3 : 4) {}

  StaticsMethod method() const { return method_; }
  size_t size() const { return values_.size() / (kNumCables * stride_); }
  bool empty() const { return values_.empty(); }
  // `count` samples, every one without a start.
  void Reset(size_t count) { values_.assign(count * kNumCables * stride_, 0.0); }
  // Sample t's start from a solution of method() (none when it did not succeed).
  void Set(size_t t, const StaticsSolution& s) { Set(t, CompactStart::Of(s)); }
  void Set(size_t t, const CompactStart& c) {
    double* v = values_.data() + t * kNumCables * stride_;
    for (int i = 0; i < kNumCables; ++i) {
      for (int k = 0; k < stride_; ++k) v[i * stride_ + k] = c.v[i][k];
    }
  }
  // The starts of samples [begin, end), as samples 0 .. end - begin (a piece of a pass).
  CompactStarts Slice(size_t begin, size_t end) const {
    CompactStarts piece(method_);
    const size_t per_sample = kNumCables * stride_;
    piece.values_.assign(values_.begin() + begin * per_sample, values_.begin() + end * per_sample);
    return piece;
  }
  // Sample t's start (CompactStart's layout).
  CompactStart At(size_t t) const {
    CompactStart c;
    const double* v = values_.data() + t * kNumCables * stride_;
    for (int i = 0; i < kNumCables; ++i) {
      for (int k = 0; k < stride_; ++k) c.v[i][k] = v[i * stride_ + k];
    }
    return c;
  }

  // The parameters theta of a model (identified by its address: the calibration's
  // CalibrationModel) at which every start is its sample's converged solution: said by a
  // pass that solved them all there (the calibration's Predict), so that a pass
  // evaluating rows through the same model at the same theta takes them as solved
  // (FittedSamples::starts_solved; issue 41). A pass that writes starts at any other
  // theta must Forget first; one at the same theta keeps it (its solutions are solutions
  // there too). Set does not forget: it runs on many threads at once.
  void MarkSolvedAt(const void* model, const double* theta, int n) {
    solved_model_ = model;
    solved_at_.assign(theta, theta + n);
  }
  void ForgetSolved() {
    solved_model_ = nullptr;
    solved_at_.clear();
  }
  bool SolvedAt(const void* model, const double* theta, int n) const {
    return model != nullptr && model == solved_model_ && static_cast<int>(solved_at_.size()) == n &&
           std::equal(theta, theta + n, solved_at_.begin());
  }

 private:
  StaticsMethod method_;
  int stride_;
  std::vector<double> values_;
  const void* solved_model_ = nullptr;  // null: not known
  std::vector<double> solved_at_;
};

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_COMPACT_START_H_
