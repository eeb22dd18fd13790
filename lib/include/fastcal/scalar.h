// Helpers that let one templated implementation serve double and ceres::Jet (the
// Sophus/manif habit): the scalar part of a value, and asinh, which Ceres 2.1's Jet lacks;
// and an inline natural logarithm for the statics' hot path.
//   d/dx asinh(x) = 1 / sqrt(1 + x^2)
#ifndef FASTCAL_SCALAR_H_
#define FASTCAL_SCALAR_H_

#include <ceres/jet.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
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

// Natural logarithm, inline: a call to std::log makes the compiler spill every live
// floating-point register around it, which on the statics' hot path cost as much as the
// log itself. For a normal x > 0, x = 2^k m with m in [sqrt(1/2), sqrt(2)), f = m - 1
// (exact) and s = f / (2 + f):
//   log m = 2 atanh s = f - s (f - R),   R = 2 sum_{n=1..10} s^(2n) / (2n + 1),
// |s| <= 0.172, so the first omitted term is below 1e-18 of log m; log x = k ln2 + log m
// with ln2 split so that k ln2_hi is exact. Within 2 ulp of std::log
// (tests/catenary_test.cc); zero, negative, subnormal, infinite and NaN x go to std::log.
inline double Log(double x) {
  if (!(x >= std::numeric_limits<double>::min() && x <= std::numeric_limits<double>::max())) {
    return std::log(x);
  }
  constexpr double kSqrt2 = 1.4142135623730951;
  constexpr double kLn2Hi = 0.6931471805598903;     // 42 significant bits
  constexpr double kLn2Lo = 5.497923018708371e-14;  // ln 2 - kLn2Hi
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  int k = static_cast<int>(bits >> 52) - 1023;
  bits = (bits & 0x000fffffffffffffULL) | 0x3ff0000000000000ULL;
  double m;
  std::memcpy(&m, &bits, sizeof m);
  if (m > kSqrt2) {
    m *= 0.5;
    ++k;
  }
  const double f = m - 1.0;
  const double s = f / (2.0 + f);
  const double z = s * s;
  // R / (2 z) = 1/3 + z/5 + ... + z^9/21, by Horner.
  constexpr double kC[] = {1.0 / 3,  1.0 / 5,  1.0 / 7,  1.0 / 9,  1.0 / 11,
                           1.0 / 13, 1.0 / 15, 1.0 / 17, 1.0 / 19, 1.0 / 21};
  double p = kC[9];
  for (int n = 8; n >= 0; --n) p = kC[n] + z * p;
  const double r = 2.0 * z * p;
  const double kd = k;
  return kd * kLn2Hi + (f - (s * (f - r) - kd * kLn2Lo));
}

// asinh x = sign(x) log(|x| + sqrt(x^2 + 1)). The log form loses ~eps/|x| of relative
// accuracy as |x| -> 0, below kAsinhLogFormMin glibc's log1p-based asinh is used (exact
// there, twice the cost). Catenary solves in the FAST workspace meet |x| in ~[0.1, 1].
inline constexpr double kAsinhLogFormMin = 0.0625;
inline double Asinh(double x) {
  const double a = std::abs(x);
  if (!(a >= kAsinhLogFormMin && a <= 1e150)) return std::asinh(x);  // and no overflow
  return std::copysign(Log(a + std::sqrt(a * a + 1.0)), x);
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
