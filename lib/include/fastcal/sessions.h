// Sessions: several surveys of one installation fitted jointly (docs/calibration.md,
// "Sessions"; data: docs/data-format.md, "Sessions").
//
// The paper (Sect. 5) reports that the cabin's structure, and with it the mass centre,
// changes during operation. Two surveys calibrated one at a time each re-estimate the
// cables and sensors from half the data, and the difference of their mass centres is
// buried in that shared nuisance. The joint fit shares every parameter between the
// sessions except the free parameters of the groups a spec names in sessions.separate:
// those get one copy per session, named NAME@LABEL (`mass_centre_m.x@B`), and a sample of
// session s depends on session s's copy alone. The shared parameters' error then cancels
// from the difference of two copies:
//   d = theta[p@to] - theta[p@from],   var d = a^T P_total a,   a = e[p@to] - e[p@from]
// with P_total the full covariance of the estimates (statistical, widened by misfit and
// time correlation, plus the consider part: uncertainty.h), which holds the copies'
// covariance through the shared parameters.
#ifndef FASTCAL_SESSIONS_H_
#define FASTCAL_SESSIONS_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"

namespace fastcal {

// The label a file's samples get when files are merged: the file name without its
// directory and its last extension ("data/day-2.csv" -> "day-2").
std::string SessionLabelOfPath(const std::string& path);

// Merges datasets read from several files into one, one session per file in the order
// given: a file with a `session` column keeps its labels, a file without one is labelled
// by SessionLabelOfPath. A label met in two files is an error naming both (two files of
// one session would need one label; rename a file or give it a session column), as is a
// file name that is not a valid label. The merged dataset keeps an optional column group
// (planned attitude, unstretched lengths) only when every file has it; samples keep the
// line numbers of their own file; `path` is the files' names joined by ','.
bool MergeSessionFiles(const std::vector<Dataset>& files, Dataset* merged, std::string* error);

// Reads each file (ReadDataset) and merges them (MergeSessionFiles); one path is read as
// it is (no session labels added).
bool ReadSessionDatasets(const std::vector<std::string>& paths, const DatasetReadOptions& options,
                         Dataset* dataset, std::string* error);

// Cutting one survey into sessions at times (fastcal calibrate --sessions-at, after a
// change scan found a step): sample times at or after cut k (and before cut k+1) form
// session k+1, labelled SessionCutLabel(k) = "s1", "s2", ... in time order. A sample
// within kSessionCutToleranceS before a cut counts as after it (a cut written as text to
// the microsecond, time_text.h). `cuts_s` must increase, in the data's time_s (Unix
// seconds when its times are absolute).
inline constexpr double kSessionCutToleranceS = 1e-6;
std::string SessionCutLabel(int index);
// The session (0-based) of a sample at `time_s`.
int SessionOfTime(const std::vector<double>& cuts_s, double time_s);
// False, with *error, when `cuts_s` is empty, not finite or not increasing.
bool CheckSessionCuts(const std::vector<double>& cuts_s, std::string* error);
// Sets data's sessions by the cuts. Refuses data that has sessions already (a session
// column, several files) and a cut that leaves a session without samples (naming its
// times as the data's times read, time_text.h).
bool CutSessionsAt(const std::vector<double>& cuts_s, Dataset* data, std::string* error);

// "mass_centre_m.x@B".
std::string SessionParameterName(const std::string& name, const std::string& label);
// The name without its "@LABEL" ("mass_centre_m.x").
std::string SharedParameterName(const std::string& name);

// The joint fit's spec: every free parameter of a group in spec.separate_groups replaced,
// in place, by one copy per label (ParameterSpec::session, name NAME@LABEL), each with the
// parameter's initial value and prior. With fewer than two labels, or no separate groups,
// the spec unchanged.
CalibrationSpec SeparateSessionParameters(const CalibrationSpec& spec,
                                          const std::vector<std::string>& labels);

// One separate parameter's change between consecutive sessions.
struct SessionDifference {
  std::string name;  // shared name, e.g. "mass_centre_m.x"
  std::string unit;
  std::string from, to;      // session labels, `to` the later one
  double difference = 0.0;   // estimate@to - estimate@from, in `unit`
  double sigma_total = 0.0;  // from the full total covariance (see above)
  double Sigmas() const { return sigma_total > 0.0 ? difference / sigma_total : 0.0; }
};

// The difference of each separate parameter between each session and the one before it
// (sessions in the order of Dataset::session_labels: first sample first). `free`: the free
// parameters in fit order with their sessions; `theta_si` and `total_covariance` (SI) in the
// same order.
std::vector<SessionDifference> ConsecutiveSessionDifferences(
    const std::vector<ParameterSpec>& free, const std::vector<double>& theta_si,
    const Eigen::MatrixXd& total_covariance, const std::vector<std::string>& labels);

// How many sigma_total a separate parameter's difference must reach to count as a change
// between sessions: 3 per component (two-sided 0.27% each by chance; for the three axes
// of the mass centre about 0.8% that one of them does).
inline constexpr double kSessionChangeSigmas = 3.0;

// One sentence for the verdict: per pair of consecutive sessions, what moved by more than
// kSessionChangeSigmas and by how much, or that nothing did (with the largest).
std::string SessionVerdict(const std::vector<SessionDifference>& differences);

// Every sample's session is an index into data.session_labels (0 without labels); false,
// naming the first sample that is not, otherwise.
bool CheckSessions(const Dataset& data, std::string* error);

}  // namespace fastcal

#endif  // FASTCAL_SESSIONS_H_
