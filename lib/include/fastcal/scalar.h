// Helpers that let one templated implementation serve double and ceres::Jet (the
// Sophus/manif habit): the scalar part of a value, and asinh, which Ceres 2.1's Jet lacks.
//   d/dx asinh(x) = 1 / sqrt(1 + x^2)
#ifndef FASTCAL_SCALAR_H_
#define FASTCAL_SCALAR_H_

#include <ceres/jet.h>

#include <cmath>
#include <type_traits>

// For the few small functions on the statics' hot path that the compiler's heuristics
// leave out of line.
#if defined(__GNUC__)
#define FASTCAL_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define FASTCAL_ALWAYS_INLINE inline
#endif

namespace fastcal {

inline double ScalarValue(double x) { return x; }
template <typename T, int N>
double ScalarValue(const ceres::Jet<T, N>& x) {
  return ScalarValue(x.a);
}

// asinh x = sign(x) log(|x| + sqrt(x^2 + 1)). The log form loses ~eps/|x| of relative
// accuracy as |x| -> 0, below kAsinhLogFormMin glibc's log1p-based asinh is used (exact
// there, twice the cost). Catenary solves in the FAST workspace meet |x| in ~[0.1, 1].
inline constexpr double kAsinhLogFormMin = 0.0625;
inline double Asinh(double x) {
  const double a = std::abs(x);
  if (!(a >= kAsinhLogFormMin && a <= 1e150)) return std::asinh(x);  // and no overflow
  return std::copysign(std::log(a + std::sqrt(a * a + 1.0)), x);
}
template <typename T, int N>
ceres::Jet<T, N> Asinh(const ceres::Jet<T, N>& x) {
  using std::sqrt;
  return ceres::Jet<T, N>(Asinh(x.a), x.v / sqrt(T(1) + x.a * x.a));
}

template <typename T>
inline constexpr bool kIsDouble = std::is_same_v<T, double>;

}  // namespace fastcal

#endif  // FASTCAL_SCALAR_H_
