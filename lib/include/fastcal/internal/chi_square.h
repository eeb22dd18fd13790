// The chi-square distribution's upper tail and its quantile, for tests with integer
// degrees of freedom (the track's events and time-correlation check): closed forms of the
// regularised upper incomplete gamma function Q(k/2, x/2) (Abramowitz and Stegun 1964,
// 26.4.4 and 26.4.5), exact for every k, and bisection for the quantile.
#ifndef FASTCAL_INTERNAL_CHI_SQUARE_H_
#define FASTCAL_INTERNAL_CHI_SQUARE_H_

namespace fastcal::internal {

// P(chi-square with `dof` >= 1 degrees of freedom > x); 1 for x <= 0.
double ChiSquareTailProbability(double x, int dof);
// x with P(chi-square(dof) > x) = upper_tail, 0 < upper_tail < 1.
double ChiSquareQuantile(double upper_tail, int dof);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_CHI_SQUARE_H_
