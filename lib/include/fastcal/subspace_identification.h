// Modes from ordinary operation: covariance-driven stochastic subspace identification
// (SSI-cov; Peeters and De Roeck 1999, "Reference-based stochastic subspace
// identification for output-only modal analysis", Mech. Syst. Signal Process. 13) of an
// ambient record, the cabin driven by the wind with no free decay (`fastcal modes
// --data --identification=ssi`; docs/model.md, "Modes from ordinary operation").
//
// The record y_k (channels centred, each scaled by its spread) is averaged over blocks of
// D samples (D the largest that keeps 4 samples a period of max_frequency_hz: an FIR
// filter and a decimation, as for ERA, modal_identification.h). Its output covariances
// R_j = E[y_{k+j} y_k^T] for j = 1 .. 2i - 1 fill the block Toeplitz matrix
//     T = [R_{i+r-c}]_{r,c = 0..i-1}  = O_i G_i,
// i block rows spanning two periods of min_frequency_hz. T = U S V^T truncated to the
// order n gives the observability matrix O = U_n S_n^(1/2); C its first block row and A
// from its shift, O_up A = O_down (least squares). Each eigenvalue mu of A is a pole
// s = ln(mu) / (D dt): f = |s| / 2 pi, zeta = -Re(s) / |s|, shape C psi.
//
// Which poles are modes (a stabilisation diagram): orders n = 2, 4, .. max_order; a pole
// of order n is stable when one of order n - 2 lies within 1% in frequency, 5% in
// damping (or 0.002 absolute) and has a modal assurance criterion above 0.95 with it.
// Stable poles of all orders are gathered into clusters (frequency within 1% of the
// cluster's first, MAC above 0.9); a cluster found at a fifth of the orders or more is a
// mode, its frequency and damping the medians of its poles. The `modes` most often found
// are returned, ascending in frequency.
//
// Sigmas by a delete-one-block jackknife (Quenouille-Tukey; the record cut into
// `blocks` parts, the covariances of all but one averaged and identified again, each
// mode matched to the nearest of the same): sigma^2 = (B - 1)/B sum (theta_-b - mean)^2.
//
// The synthetic ambient records the tests identify: each mode j a discrete-time
// oscillator with the exact poles exp(s_j dt) of f_j and zeta_j, driven by white noise,
//     q_k = a1 q_{k-1} + a2 q_{k-2} + e_k,  a1 = 2 r cos(w_d dt),  a2 = -r^2,
//     r = exp(-zeta w dt),  w_d = w sqrt(1 - zeta^2),  e_k ~ N(0, 1),
// scaled by its stationary spread sqrt((1 - a2) / ((1 + a2) ((1 - a2)^2 - a1^2))) and
// started after a burn-in of 10 time constants 1 / (zeta w); channel c is
// sum_j shape(c, j) q_j,k plus white noise of sigma noise_sigma[c].
#ifndef FASTCAL_SUBSPACE_IDENTIFICATION_H_
#define FASTCAL_SUBSPACE_IDENTIFICATION_H_

#include <cstdint>
#include <string>
#include <vector>

#include "fastcal/modal_identification.h"

namespace fastcal {

struct SsiOptions {
  // How many modes to return (>= 1): the most stable ones, ascending in frequency.
  int modes = 3;
  // The band of the modes sought (Hz, 0 < min < max): decimation and block rows as above.
  double min_frequency_hz = 0.1;
  double max_frequency_hz = 0.5;
  // The largest model order of the stabilisation diagram (even, >= 4).
  int max_order = 60;
  // Poles with a damping ratio outside (0, max_damping_ratio) are not modes.
  double max_damping_ratio = 0.1;
  // Jackknife blocks for the sigmas (>= 3); the record must hold at least 10 periods of
  // min_frequency_hz in each.
  int blocks = 8;

  bool IsValid(std::string* error) const;
};

// The record's modes by SSI-cov with jackknife sigmas. IdentifiedMode::amplitude holds
// the fraction of the model orders at which the mode was found stable. False with *error
// for a record too short for the band and blocks, or when fewer modes than asked are
// found stable.
bool IdentifyModesSsi(const VibrationRecord& record, const SsiOptions& options,
                      std::vector<IdentifiedMode>* modes, std::string* error);

struct AmbientRecordSpec {
  std::vector<double> frequency_hz;   // per mode, > 0, below the Nyquist frequency
  std::vector<double> damping_ratio;  // per mode, in (0, 1)
  Eigen::MatrixXd shape;              // channels x modes: each mode's spread per channel
  Eigen::VectorXd noise_sigma;        // per channel
  double sample_interval_s = 0.5;
  double duration_s = 3600.0;
  std::uint64_t seed = 1;
};
bool SimulateAmbientRecord(const AmbientRecordSpec& spec, VibrationRecord* record,
                           std::string* error);

}  // namespace fastcal

#endif  // FASTCAL_SUBSPACE_IDENTIFICATION_H_
