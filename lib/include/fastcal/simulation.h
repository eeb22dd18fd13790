// Synthetic telemetry: what the cabin's pose sensors and the six cable-tension sensors
// would record along a planned trajectory, for a known ("truth") model.
//
// Per planned pose n at time t_n = n dt (position p, planned attitude a_plan):
//   actual attitude     a_act  = a_plan + c_n,  c the attitude control error, per rpy
//                                angle AR(1) with sigma attitude_control_sigma_deg and
//                                correlation time attitude_control_time_s (0: white)
//   actual position     p_act  = p                        (the position is held exactly)
//   mass centre         e_n    = e + d_n + sum_{k: t_k <= t_n} s_k, d per axis AR(1) with
//                                sigma mass_centre_drift_m and correlation time
//                                mass_centre_drift_time_s (with mass_centre_drift_centred,
//                                minus its mean over the sample's session); s_k the steps
//                                at times t_k (mass_centre_steps: the structure changed)
//   joint values        q_n    = the joint plan's (joint_plan.h), for a model with moving parts
//   truth statics       T_i, s0_i = SolveStatics(truth with e_n + the parts' shift at q_n,
//                                               (p_act, R(a_act)))
//   sensor reading      y_i    = sensor_gain_i T_i + sensor_bias_n_i
//   measured tension    m_i    = y_i (1 + N(0, tension_noise_percent / 100) + u_i,n)
//                                + N(0, 1000 tension_noise_kn)
//                        u_i per cable AR(1) with sigma tension_drift_percent / 100 and
//                        correlation time tension_drift_time_s (a slow sensor error);
//                        with tension_drift_kn > 0 the slow error is instead
//                        sqrt(kn^2 + (pct/100 y_i)^2) v_i,n in newtons, v_i the standardised
//                        process (slow_error.h)
//                        or, with probability outlier_fraction, an outlier
//                        m_i    = y_i (1 + U(-s, s) / 100),  s = outlier_scale_percent
//   measured length     l_i    = s0_i + o_i + N(0, length_noise_m)   (a winch's encoder,
//                                o_i its zero offset: the truth model's length_offset_m)
//   measured attitude   a_meas = a_act + N(0, attitude_measurement_sigma_deg)  per rpy angle
//   measured position   p_meas = p + N(0, position_measurement_sigma_m)        per axis
//   with a measured frame (the truth's cabin.measured_frame, measured_frame.h), p, a_act
//   and a_plan above are that frame's at q_n (its pose from the cabin's: (1)-(2) there):
//   the data are what the telescope's pose sensors see, the statics the cabin's
// with R(a) = RotationFromRpyDeg(a) and a_plan = RpyDegFromRotation(planned rotation).
// An AR(1) process x with sigma s and correlation time tau starts stationary,
// x_0 = s N(0, 1), and steps x_n = phi x_{n-1} + s sqrt(1 - phi^2) N(0, 1),
// phi = exp(-dt / tau) (phi = 0, white, for tau = 0).
// Drawn once, before the trajectory (the truth model written out has them): each cable's
// linear density times (1 + N(0, density_mismatch_percent / 100)) (non-uniform cables:
// sensors, wiring); its sensor gain times (1 + N(0, sensor_gain_spread_percent / 100));
// its sensor bias plus N(0, 1000 sensor_bias_spread_kn) N; its length encoder's offset plus
// N(0, length_offset_spread_m).
//
// Random numbers: std::mt19937_64, converted by hand (uniform from the top 53 bits,
// Gaussian by Box-Muller), so a seed gives the same dataset with every standard library.
// Each error source has its own generator derived from the seed, and every draw is made
// whatever its sigma, so changing one sigma changes only that source's numbers.
#ifndef FASTCAL_SIMULATION_H_
#define FASTCAL_SIMULATION_H_

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/dataset.h"
#include "fastcal/joint_plan.h"
#include "fastcal/pose.h"
#include "fastcal/statics.h"

namespace fastcal {

// The mass centre moves by shift_m (cabin frame) at time_s and stays there.
struct MassCentreStep {
  double time_s = 0.0;
  Eigen::Vector3d shift_m = Eigen::Vector3d::Zero();
};

// One sensor re-zeroed: cable `cable`'s bias (0-based) moves by shift_n at time_s and
// stays there (a maintenance day).
struct SensorBiasStep {
  double time_s = 0.0;
  int cable = 0;
  double shift_n = 0.0;
};

// The cabin's actual state at a sample when something other than the statics at the
// planned pose gives it (SimulationOptions::actual_source; the dynamics in time,
// dynamic_survey.h): the sample's time from the first (start_time_s is added), the actual
// pose, the true lower-end tensions and the winches' unstretched lengths.
struct ActualSample {
  double time_s = 0.0;
  Pose pose;
  std::array<double, kNumCables> lower_tension_n{};
  std::array<double, kNumCables> unstretched_length_m{};
};
// Called for each sample n = 0, 1, ... in order with its planned pose and the truth model
// in use (after the drawn density mismatch and sensor spreads); false with *error stops
// the simulation.
using ActualSource = std::function<bool(long long n, const Pose& planned, const CableRobot& truth,
                                        ActualSample* actual, std::string* error)>;

struct SimulationOptions {
  // Attitude control error: standard deviation of the actual minus the planned roll,
  // pitch and yaw (deg, each axis independent). >= 0; default 0.
  double attitude_control_sigma_deg = 0.0;
  // Its correlation time (s): 0 draws it afresh for every sample (white); a real
  // controller's error is smooth. >= 0; default 0.
  double attitude_control_time_s = 0.0;
  // Slow (time-correlated) relative tension error per cable, AR(1): standard deviation
  // in percent of the reading and correlation time (s). >= 0; default 0 (none).
  double tension_drift_percent = 0.0;
  double tension_drift_time_s = 0.0;
  // Its absolute part (kN), >= 0, default 0: the slow error's sd is then
  // sqrt(kn^2 + (percent/100 reading)^2) (slow_error.h's process), one process per cable.
  double tension_drift_kn = 0.0;
  // Drift of the cabin's mass centre about the truth model's, per axis AR(1): standard
  // deviation (m) and correlation time (s). >= 0; default 0 (none). The truth model
  // written out keeps the mean; SimulationSummary has the realised average.
  double mass_centre_drift_m = 0.0;
  double mass_centre_drift_time_s = 0.0;
  // Each session's drift made of zero mean (the process drawn for the session, its mean
  // over the session's samples subtracted per axis): a wander inside each day about a
  // level that stays the truth model's. Default false (the process as drawn: its day
  // means differ by about sigma sqrt(2 tau / day) when tau is short).
  bool mass_centre_drift_centred = false;
  // Spread of the per-cable sensor gains (percent) and biases (kN) drawn once about the
  // truth model's. >= 0; default 0.
  double sensor_gain_spread_percent = 0.0;
  double sensor_bias_spread_kn = 0.0;
  // Attitude sensor error: standard deviation of the measured minus the actual roll,
  // pitch and yaw (deg). >= 0; default 0.
  double attitude_measurement_sigma_deg = 0.0;
  // Position sensor error: standard deviation of the measured minus the actual position
  // per axis (m). The actual position is the planned one. >= 0; default 0.
  double position_measurement_sigma_m = 0.0;
  // Relative tension-sensor noise: standard deviation in percent of the reading. >= 0;
  // default 3 (the paper's sensors).
  double tension_noise_percent = 3.0;
  // Absolute tension-sensor noise: standard deviation in kN, added to the relative one.
  // >= 0; default 0.
  double tension_noise_kn = 0.0;
  // Probability that a tension reading is an outlier instead of reading + noise. In
  // [0, 1]; default 0.
  double outlier_fraction = 0.0;
  // Half-width of an outlier's uniform relative error, in percent of the reading. In
  // [0, 100) so that outliers stay positive; default 30.
  double outlier_scale_percent = 30.0;
  // Standard deviation of the per-cable density factor of the truth model, in percent.
  // >= 0; default 0 (the truth model as given).
  double density_mismatch_percent = 0.0;
  // Spread of the per-cable length-encoder offsets drawn once about the truth model's
  // (m), and the white noise of each length reading (m). >= 0; default 0: the datasets'
  // s0 columns are then the truth's unstretched lengths exactly.
  double length_offset_spread_m = 0.0;
  double length_noise_m = 0.0;
  // Seed of all generators; default 1.
  std::uint64_t seed = 1;
  // Statics method of the truth tensions and lengths; default exact.
  StaticsMethod method = StaticsMethod::kExact;
  // Time between samples (s): sample n has time_s = start_time_s + n * sample_interval_s
  // (plus the session gaps). > 0; default 1.
  double sample_interval_s = 1.0;
  // Time of the first sample (s): 0, or a Unix time (e.g. 1714593600 for
  // 2024-05-01T20:00:00Z) for telemetry with absolute times. Finite; default 0.
  double start_time_s = 0.0;
  // Steps of the mass centre: from the first sample at or after each time on, the mass
  // centre is moved by the step's shift (steps add up). Finite; default none. The truth
  // model written out keeps the mass centre before the first step.
  std::vector<MassCentreStep> mass_centre_steps;
  // The samples cut into this many consecutive sessions of equal length (the first ones
  // one sample longer when it does not divide), labelled "1" .. "N" in the dataset's
  // session column (docs/data-format.md, "Sessions"). >= 1; 1: no session column.
  int sessions = 1;
  // Time between the end of one session and the start of the next (s), added to the
  // time stamps; the slow processes (drift, control error) decorrelate over it as over any
  // time. >= 0; default 0.
  double session_gap_s = 0.0;
  // Sensors re-zeroed at the start of each session after the first: each cable's bias
  // moves by N(0, sensor_rezero_kn) kN. >= 0; default 0. The truth model written out has
  // the first session's biases; SimulationSummary::session_bias_n has every session's.
  double sensor_rezero_kn = 0.0;
  // Single sensors re-zeroed at given times (steps add up). Finite times and shifts, cables
  // 0..5; default none. The truth model written out has the biases before any of them.
  std::vector<SensorBiasStep> sensor_bias_steps;
  // The truth model's moving parts (moving_parts.h): their joint values per sample
  // (joint_plan.h), written in the dataset's joint columns and moving its mass centre.
  // Unused for a model without moving parts; default: every joint at zero.
  JointPlanOptions joints;
  // The actual state from elsewhere (empty: the statics at the planned pose, the
  // default): the sample times, poses, tensions and lengths it gives are measured as
  // above. Then no attitude control error, mass-centre drift or steps, one session, and a
  // truth model without moving parts: the source's model has its own.
  ActualSource actual_source;

  // False, with the offending field named in *error (may be null), for a value out of range.
  bool IsValid(std::string* error) const;
};

// What Simulate added, for a summary.
struct SimulationSummary {
  int samples = 0;
  // Per cable: RMS of measured minus sensor reading (N), outliers included; RMS of
  // measured / reading - 1 (dimensionless); number of outliers.
  std::array<double, kNumCables> tension_noise_rms_n{};
  std::array<double, kNumCables> tension_noise_rms_relative{};
  std::array<int, kNumCables> outliers{};
  // Noise draws redrawn because they would have made a reading or a density <= 0 (the
  // noise is then a truncated Gaussian; at realistic levels this count is 0).
  int redrawn = 0;
  // RMS over samples and axes of actual minus planned and measured minus actual
  // attitude (deg, rpy), and of measured minus actual position (m).
  double attitude_control_rms_deg = 0.0;
  double attitude_measurement_rms_deg = 0.0;
  double position_measurement_rms_m = 0.0;
  // Density factors applied to the truth model, cable i at index i-1.
  std::array<double, kNumCables> density_factor{};
  // Per cable: the length encoder's offset of the truth model used (m), and the RMS of the
  // length noise added (m).
  std::array<double, kNumCables> length_offset_m{};
  std::array<double, kNumCables> length_noise_rms_m{};
  // Per cable: RMS of the slow tension error u (dimensionless).
  std::array<double, kNumCables> tension_drift_rms_relative{};
  // Each session's sensor biases (N), first session first (they differ when re-zeroed).
  std::vector<std::array<double, kNumCables>> session_bias_n;
  // Average over the samples of the actual mass centre (cabin frame, m), and the RMS
  // over samples and axes of its drift about the truth model's.
  Eigen::Vector3d mass_centre_mean_m = Eigen::Vector3d::Zero();
  double mass_centre_drift_rms_m = 0.0;
};

// Simulates telemetry at the `planned` poses (position and planned attitude) with the
// `truth` model, its sensor gains and biases included. Fills *dataset with one sample per
// planned pose, in order: time, measured position and attitude (as roll/pitch/yaw;
// Sample::measured_rpy_deg and pose.rotation agree exactly), the planned attitude
// (planned_rpy_deg = RpyDegFromRotation(planned rotation), planned_rotation rebuilt from
// those angles, so equal to the planned rotation to rounding), the measured tensions and
// the measured lengths (the truth solution's unstretched lengths through the encoders:
// offset and noise). Every value is such
// that WriteDataset then ReadDataset gives back the same dataset. *truth_used receives
// the truth model after the density mismatch (the model the tensions come from).
//
// Returns false with *error set (the outputs untouched) when the options or the truth
// model are invalid, there are no poses, a pose is not finite, or the truth model cannot
// hold an actual pose (the message names the 0-based node, its position and the
// DescribeStatus account). Any of dataset, truth_used, summary and error may be null.
bool Simulate(const CableRobot& truth, const std::vector<Pose>& planned,
              const SimulationOptions& options, Dataset* dataset, CableRobot* truth_used,
              SimulationSummary* summary, std::string* error);

// The same simulation handing each sample to `sink` as it is made, in order, instead of
// keeping them: memory independent of the number of samples (fastcal simulate streams
// them into a DatasetWriter). The samples, *truth_used and *summary are those Simulate
// gives. `sink` returning false stops the simulation with its *error. Samples already
// handed over stay with the sink when a later pose fails.
using SampleSink = std::function<bool(const Sample& sample, std::string* error)>;
bool SimulateStream(const CableRobot& truth, const std::vector<Pose>& planned,
                    const SimulationOptions& options, const SampleSink& sink,
                    CableRobot* truth_used, SimulationSummary* summary, std::string* error);

// Planned poses handed out one at a time: `next` gives pose n on its n-th call,
// n = 0 .. count - 1 (e.g. a PositionStream of trajectory.h with an attitude law).
struct PoseStream {
  long long count = 0;
  std::function<Pose()> next;
};
// The same simulation drawing the planned poses from `planned` as it goes (a copy of it:
// the caller's stream is not advanced), so that neither the poses nor the samples are
// held: fastcal simulate's memory is then independent of the number of samples. A
// non-finite pose is found when it is drawn (the samples before it already handed over).
bool SimulateStream(const CableRobot& truth, PoseStream planned, const SimulationOptions& options,
                    const SampleSink& sink, CableRobot* truth_used, SimulationSummary* summary,
                    std::string* error);

// The column groups of a simulated dataset (planned attitude, unstretched lengths,
// roll/pitch/yaw) and, for more than one session, the session labels "1" .. "N"
// (SimulationOptions::sessions), and the truth model's joint columns, with no samples:
// the layout a DatasetWriter of SimulateStream needs.
Dataset SimulatedDatasetLayout(int sessions = 1,
                               const std::vector<std::string>& joint_columns = {});

}  // namespace fastcal

#endif  // FASTCAL_SIMULATION_H_
