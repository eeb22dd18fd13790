// What both identifications (ERA, modal_identification.h; SSI, subspace_identification.h)
// do to a record first: average it over blocks of D samples, D the largest that keeps 4
// samples a period of the band's top frequency f_max,
//     D = max(1, floor(1 / (4 f_max dt))),
// an FIR filter and a decimation (a damped sinusoid stays one, with its frequency and
// decay; white noise stays white at the new interval D dt); then centre each channel and
// scale it by its spread, sigma_c = sqrt(sum_k y_ck^2 / n), so that metres, degrees and kN
// weigh alike.
#ifndef FASTCAL_SRC_DYNAMICS_RECORD_PREPARATION_H_
#define FASTCAL_SRC_DYNAMICS_RECORD_PREPARATION_H_

#include <Eigen/Core>

namespace fastcal::internal {

// D above (>= 1).
int DecimationFactor(double sample_interval_s, double max_frequency_hz);

// The channels (channels x samples) averaged over blocks of `factor`, centred and scaled.
Eigen::MatrixXd DecimatedScaled(const Eigen::MatrixXd& channels, int factor);

}  // namespace fastcal::internal

#endif  // FASTCAL_SRC_DYNAMICS_RECORD_PREPARATION_H_
