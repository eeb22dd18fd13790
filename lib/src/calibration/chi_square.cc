// The chi-square tail and quantile (internal/chi_square.h).
#include "fastcal/internal/chi_square.h"

#include <algorithm>
#include <cmath>

namespace fastcal::internal {

double ChiSquareTailProbability(double x, int dof) {
  // Q(k/2, x/2): for even k, e^-h sum_{j < k/2} h^j / j!; for odd k,
  // erfc(sqrt h) + e^-h sum_{j < (k-1)/2} h^(j + 1/2) / Gamma(j + 3/2); h = x / 2.
  if (!(x > 0.0)) return 1.0;
  const double h = x / 2.0;
  double sum = 0.0, term = 0.0;
  if (dof % 2 == 0) {
    term = 1.0;  // h^j / j!
    for (int j = 0; j < dof / 2; ++j) {
      if (j > 0) term *= h / j;
      sum += term;
    }
    return std::min(1.0, std::exp(-h) * sum);
  }
  // Odd: erfc(sqrt(h)) + e^-h sum_{j < (dof-1)/2} h^(j + 1/2) / Gamma(j + 3/2).
  term = std::sqrt(h) / (std::sqrt(M_PI) / 2.0);
  for (int j = 0; j < (dof - 1) / 2; ++j) {
    if (j > 0) term *= h / (j + 0.5);
    sum += term;
  }
  return std::min(1.0, std::erfc(std::sqrt(h)) + std::exp(-h) * sum);
}

double ChiSquareQuantile(double upper_tail, int dof) {
  double lo = 0.0, hi = std::max(1.0, 2.0 * dof);
  while (ChiSquareTailProbability(hi, dof) > upper_tail && hi < 1e6) hi *= 2.0;
  for (int it = 0; it < 200 && hi - lo > 1e-12 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (ChiSquareTailProbability(mid, dof) > upper_tail ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace fastcal::internal
