// `fastcal locate`: where the cabin hangs, given the six unstretched lengths the winches
// have paid out (the forward statics, fastcal/locate.h), for one set of lengths or a file
// of them; with a measured attitude and tensions, the pose that fits all of them.
#include <gflags/gflags.h>

#include <chrono>
#include <cmath>
#include <deque>
#include <iostream>
#include <limits>
#include <sstream>

#include "cli_util.h"
#include "columns_flag.h"
#include "commands.h"
#include "common_flags.h"
#include "fastcal/cable_robot.h"
#include "fastcal/calibration_spec.h"
#include "fastcal/dataset.h"
#include "fastcal/gross_errors.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/column_reading.h"
#include "fastcal/internal/csv.h"
#include "fastcal/internal/quote.h"
#include "fastcal/locate.h"
#include "fastcal/plausibility.h"

DECLARE_string(spec);    // calibrate_command.cc; here the sigmas of its noise
DECLARE_string(joints);  // solve_command.cc

DEFINE_string(tensions_kN, "", "locate: with --lengths, the six measured tensions (kN).");
DEFINE_string(use, "",
              "locate: what the pose fits: lengths[,attitude][,tensions]; default all given.");
DEFINE_double(length_sigma_m, 0.01, "locate: sigma of a measured length (m).");
DEFINE_double(tension_sigma_percent, 3.0, "locate: relative sigma of a tension reading (%).");
DEFINE_double(tension_sigma_kN, 0.0, "locate: absolute sigma of a tension reading (kN).");
DEFINE_double(attitude_sigma_deg, 0.05, "locate: sigma of the measured attitude per axis (deg).");
DEFINE_double(search_radius_m, 2.0,
              "locate: look for other equilibria this far from the answer (m); 0: none.");

namespace fastcal::cli {
namespace {

constexpr char kCommand[] = "locate";

const char kHelp[] =
    R"(fastcal locate: where the FAST cabin hangs, from the six unstretched cable lengths.

Usage:
  fastcal locate --lengths=L1,L2,L3,L4,L5,L6 [--rpy=r,p,y | --quat=w,x,y,z]
                 [--tensions-kN=T1,...,T6] [options]
  fastcal locate --data=FILE.csv [options]

The forward statics (docs/model.md, "Forward statics"): the pose and the six cable forces
that close every cable's catenary at the given unstretched lengths s0 and hold the cabin
in equilibrium (24 equations, 24 unknowns, Newton on the analytic Jacobian). Each row
starts from the previous row's answer moved to its lengths (--warm-start, default true);
the first row, and any whose warm start fails, follows the equilibrium from the home pose
as the lengths move from the home pose's to the row's: the equilibrium the cabin reaches
when the winches bring it there. Every answer is checked as `fastcal solve` checks its
own (each cable's end conditions, the equilibrium, the model's range).

Stability: the stiffness of the cabin's potential energy with the lengths held (its
smallest eigenvalue, min_stiffness_kN_per_m): 'stable' when positive definite,
'unstable' when a small push would move the cabin away, 'marginal' at a fold. Other
equilibria of the same lengths are looked for within --search-radius-m=2 of the answer
(anchors' move; 0: no search); found ones are counted (other_equilibria) and the
nearest's distance given: the lengths alone then do not say where the cabin is.

Measurements:
  --lengths=L1,...,L6   unstretched lengths (m), cable 1 first, as the winches give them
  --data=FILE.csv       one instant per row: s0_1_m..s0_6_m required; time_s,
                        roll_deg,pitch_deg,yaw_deg (or qw,qx,qy,qz), T1_kN..T6_kN and
                        x_m,y_m,z_m optional (docs/data-format.md, "Lengths files"); a
                        dataset of calibrate or simulate with s0 columns works. Its
                        positions are not used to locate: the summary compares them
                        with the answers.
  With --lengths: --rpy=r,p,y or --quat=w,x,y,z (measured attitude), --tensions-kN=...
  (the sensors' readings; the model's sensor_gain and sensor_bias_kN apply).
  With a measured attitude or tensions the pose is the least-squares fit of all of
  them, each reading divided by its sigma; --use=lengths,attitude,tensions chooses
  (default: all that are given; lengths are always used). Lengths alone: the exact
  forward solution.
  Sigmas (the fit's weights and the answer's sigmas): --length-sigma-m=0.01,
  --tension-sigma-percent=3 and --tension-sigma-kN=0 (sigma^2 = abs^2 + (pct/100
  predicted reading)^2, as a calibration spec's noise), --attitude-sigma-deg=0.05.
  --spec=SPEC.yaml takes them from a calibration spec's noise (tension_sigma_kN,
  tension_sigma_percent, and length_sigma_m when it has one); a flag given overrides.

Model: --model=FILE.yaml (docs/model-format.md; a calibrated model from fastcal
calibrate works); default the nominal FAST model. Model range: --max-strain=0.05,
--max-length-ratio=1.5, --reflector-clearance=0 (as in solve). A model with moving parts
(cabin.moving_parts) takes each row's joint values from the --data file's joint columns,
or --joints=v1,... (the model's joint order, deg and m) with --lengths; default all 0.

Output: CSV to stdout or --output=FILE (written only when everything succeeded; an
existing FILE is refused unless --force). Columns, units in the names:
  row,line,time_s          row number (0-based), the file's line, its time (empty if none)
  x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg   the pose, R = Rz(yaw) Ry(pitch) Rx(roll)
  status                   ok, or why not: no_equilibrium, sagging_cable,
                           overstretched_cable, reflector_contact, not_converged, ...
  stability                stable, unstable, marginal (unknown on failure)
  T1_kN..T6_kN             lower-end tensions at the answer (the model's true tensions)
  sigma_x_m,sigma_y_m,sigma_z_m,sigma_roll_deg,sigma_pitch_deg,sigma_yaw_deg
                           the answer's standard deviations from the sigmas above
  min_stiffness_kN_per_m   the stiffness's smallest eigenvalue (rotations scaled by the
                           cabin's size; negative: unstable)
  other_equilibria,nearest_other_m   other equilibria found, the nearest's distance
  readings,chi2            readings the pose fits, their whitened residuals squared
                           (lengths alone: 6 and 0)
  error_estimate_m         the next Newton step's size after the last: the pose's error
  message                  the account of the row ("" when ok, stable, alone and, for a
                           fit, chi2 below what a correct noise model exceeds once in 1000
                           rows: beyond it "the measurements disagree")
A row that fails (no equilibrium, or one outside the model's range) is an error naming
the row and line (exit 1, no output) unless --keep-going, which writes it with its status
and message and empty numbers. An unstable or non-unique answer is not a failure: it is
written, and the summary on stderr counts and names it; so is a fit whose measurements
disagree.

Examples:
  fastcal locate --lengths=312.61,312.61,312.61,312.61,312.61,312.61
  fastcal simulate --trajectory=random --samples=50 --out=out/survey.csv  # s0 columns
  fastcal locate --data=out/survey.csv --output=out/located.csv
  fastcal solve --trajectory=circle --output=out/solved.csv  # solve's own output
  fastcal locate --data=out/solved.csv --use=lengths     # back to its poses

--data may also be solve's output (its x_m..yaw_deg, T<i>_kN and s0_<i>_m columns; rows
whose status is not ok are left out and counted), or an export read through
--columns=MAP.yaml (docs/data-format.md, "Column maps"); .gz files are read as they are.
)";

// clang-format off
const std::set<std::string> kFlags = {
    "model", "data", "lengths", "rpy", "quat", "tensions-kN", "use", "spec", "length-sigma-m",
    "tension-sigma-percent", "tension-sigma-kN", "attitude-sigma-deg", "search-radius-m",
    "warm-start", "output", "force", "keep-going", "max-strain", "max-length-ratio",
    "reflector-clearance", "joints", "columns"};
// clang-format on

// One instant to locate, and what the file said of it.
struct Row {
  int line = 0;  // 0 for --lengths
  bool has_time = false;
  double time_s = 0.0;
  bool has_position = false;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // the file's, compared only
  LocateMeasurement measurement;
  JointValues joints{};  // a model with moving parts: the row's joint values
};

// What locate found at one row (LocateSolution is large; only what is written is kept).
struct Answer {
  StaticsStatus status = StaticsStatus::kInvalidInput;
  Stability stability = Stability::kUnknown;
  std::string message;
  Pose pose;   // the data's frame's (the model's measured frame; else the cabin's)
  Pose cabin;  // the cabin's, as located
  std::array<double, kNumCables> tension_n{};
  Eigen::Matrix<double, 6, 1> sigma = Eigen::Matrix<double, 6, 1>::Zero();  // m, deg
  double min_stiffness_n_per_m = 0.0;
  int other_equilibria = 0;
  double nearest_other_m = 0.0;
  int readings = 0;
  double chi2 = 0.0;
  bool misfit = false;  // the fit's chi2 beyond what its noise model allows (MisfitLimit)
  double error_estimate_m = 0.0;
};

// A fit's chi2 that a correct noise model exceeds once in 1000 rows: beyond it the
// measurements disagree with the model or one another. Wilson and Hilferty's cube-root
// normal approximation of the chi-square quantile (within 1% from 3 degrees of freedom).
constexpr double kMisfitTail = 1e-3;
double MisfitLimit(int dof) {
  const double z = TwoSidedNormalQuantile(2.0 * kMisfitTail);  // one-sided kMisfitTail
  const double a = 2.0 / (9.0 * dof);
  return dof * std::pow(1.0 - a + z * std::sqrt(a), 3);
}

// Which measurements the fit uses (--use); lengths always.
struct Use {
  bool attitude = true, tensions = true;
};

bool ParseUse(Use* use, std::string* error) {
  if (FLAGS_use.empty()) return true;
  use->attitude = use->tensions = false;
  std::stringstream ss(FLAGS_use);
  std::string item;
  bool lengths = false;
  while (std::getline(ss, item, ',')) {
    if (item == "lengths") {
      lengths = true;
    } else if (item == "attitude") {
      use->attitude = true;
    } else if (item == "tensions") {
      use->tensions = true;
    } else {
      *error = "--use: unknown measurement " + internal::Quote(item) +
               " (lengths, attitude, tensions, comma-separated)";
      return false;
    }
  }
  if (!lengths) {
    *error = "--use must include lengths: the pose is located from them (got " +
             internal::Quote(FLAGS_use) + ")";
    return false;
  }
  return true;
}

// The sigmas: --spec's noise (its length_sigma_m when it has one), each overridden by its
// flag when given; the flags' defaults without --spec.
bool NoiseFromFlags(const CableRobot& robot, LocateNoise* noise, std::string* error) {
  noise->length_sigma_m = FLAGS_length_sigma_m;
  noise->tension_sigma_percent = FLAGS_tension_sigma_percent;
  noise->tension_sigma_n = FLAGS_tension_sigma_kN * kNPerKn;
  noise->attitude_sigma_deg = FLAGS_attitude_sigma_deg;
  if (!FLAGS_spec.empty()) {
    CalibrationSpec spec;
    if (!LoadCalibrationSpec(FLAGS_spec, robot, &spec, error)) return false;
    if (spec.UsesLengths() && !FlagGiven("length-sigma-m")) {
      noise->length_sigma_m = spec.length_sigma_m;
    }
    if (!FlagGiven("tension-sigma-percent")) {
      noise->tension_sigma_percent = spec.tension_sigma_percent;
    }
    if (!FlagGiven("tension-sigma-kN")) noise->tension_sigma_n = spec.tension_sigma_n;
  }
  if (noise->IsValid(error)) return true;
  *error = WithFlagNames(*error, {{"length_sigma_m", "--length-sigma-m"},
                                  {"tension_sigma_n", "--tension-sigma-kN"},
                                  {"tension_sigma_percent", "--tension-sigma-percent"},
                                  {"attitude_sigma_deg", "--attitude-sigma-deg"}});
  return false;
}

bool OptionsFromFlags(LocateOptions* options, std::string* error) {
  options->warm_start = FLAGS_warm_start;
  options->search_radius_m = FLAGS_search_radius_m;
  if (!ModelRangeFromFlags(&options->statics, error)) return false;
  if (options->IsValid(error)) return true;
  *error = WithFlagNames(*error, {{"search_radius_m", "--search-radius-m"}});
  return false;
}

// --lengths with its attitude and tension flags: one row.
bool RowFromFlags(std::vector<Row>* rows, std::string* error) {
  Row row;
  LocateMeasurement& m = row.measurement;
  if (!ParseSix("lengths", FLAGS_lengths, &m.length_m, error)) return false;
  const PlausibilityLimits limits;
  for (int i = 0; i < kNumCables; ++i) {
    if (std::string why; !CheckUnstretchedLengthM(m.length_m[i], limits, &why)) {
      *error = "--lengths: cable " + std::to_string(i + 1) + ": " + why;
      return false;
    }
  }
  if (!FLAGS_rpy.empty() && !FLAGS_quat.empty()) {
    *error = "give at most one of --rpy and --quat";
    return false;
  }
  if (!FLAGS_rpy.empty()) {
    Eigen::Vector3d rpy;
    if (!ParseRpyDeg("rpy", FLAGS_rpy, &rpy, error)) return false;
    m.has_attitude = true;
    m.rotation = RotationFromRpyDeg(rpy[0], rpy[1], rpy[2]);
  } else if (!FLAGS_quat.empty()) {
    Eigen::Vector4d q;
    std::string why;
    if (!ParseVector4("quat", FLAGS_quat, &q, error)) return false;
    if (!RotationFromQuaternion(q[0], q[1], q[2], q[3], &m.rotation, &why)) {
      *error = "--quat: " + why;
      return false;
    }
    m.has_attitude = true;
  }
  if (!FLAGS_tensions_kN.empty()) {
    if (!ParseSix("tensions-kN", FLAGS_tensions_kN, &m.tension_n, error)) return false;
    for (int i = 0; i < kNumCables; ++i) {
      m.tension_n[i] *= kNPerKn;
      if (std::string why; !CheckTensionN(m.tension_n[i], limits, &why)) {
        *error = "--tensions-kN: cable " + std::to_string(i + 1) + ": " + why;
        return false;
      }
    }
    m.has_tensions = true;
  }
  rows->assign(1, row);
  return true;
}

// --data=FILE: a lengths file (dataset.h, DatasetColumns::kLengths).
// solve's output (its header starts "node," and has status and message columns) as a
// lengths file: the pose, tension and s0 columns kept, the rows solve did not solve
// (status not ok) and the other columns left out, and every other line kept as a comment,
// so that messages name the file's own lines. *text is left empty for any other file.
bool SolveOutputAsLengths(const std::string& path, std::string* text, int* left_out,
                          std::string* error) {
  constexpr long long kMaxBytes = 1LL << 30;  // solve's output of ~10^6 poses
  {  // Its first bytes say whether it is solve's output (a dataset is read as one below).
    internal::RegularFileReader reader;
    std::string start;
    bool end = false;
    if (!reader.Open(path, std::numeric_limits<long long>::max(), "dataset", error) ||
        !reader.Read(5, &start, &end, error)) {
      return false;
    }
    if (start != "node,") return true;
  }
  std::string content;
  if (!internal::ReadRegularFile(path, kMaxBytes, "solve output", &content, error)) return false;
  std::vector<std::string> keep = {"x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg"};
  for (int i = 1; i <= kNumCables; ++i) keep.push_back("T" + std::to_string(i) + "_kN");
  for (int i = 1; i <= kNumCables; ++i) keep.push_back("s0_" + std::to_string(i) + "_m");
  std::vector<int> field_of(keep.size(), -1);
  int status_field = -1;
  std::vector<std::string_view> fields;
  std::deque<std::string> scratch;
  std::string out, why;
  size_t start = 0;
  for (long line = 1; start < content.size(); ++line) {
    const size_t end = std::min(content.find('\n', start), content.size());
    const std::string_view record(content.data() + start, end - start);
    start = end + 1;
    scratch.clear();
    if (!internal::SplitRecord(record, ',', &fields, &scratch, &why)) {
      *error = path + ":" + std::to_string(line) + ": " + why;
      return false;
    }
    if (line == 1) {
      for (size_t f = 0; f < fields.size(); ++f) {
        if (fields[f] == "status") status_field = static_cast<int>(f);
        for (size_t k = 0; k < keep.size(); ++k) {
          if (fields[f] == keep[k]) field_of[k] = static_cast<int>(f);
        }
      }
      for (size_t k = 0; k < keep.size(); ++k) {
        if (field_of[k] < 0 || status_field < 0) {
          *error = path + ":1: solve's output without its column " +
                   internal::Quote(field_of[k] < 0 ? keep[k] : "status") +
                   " (locate reads solve's CSV, --format=csv)";
          return false;
        }
      }
    }
    const bool ok = line == 1 || (static_cast<int>(fields.size()) > status_field &&
                                  fields[status_field] == "ok");
    if (!ok) {
      *left_out += record.empty() ? 0 : 1;
      out += "#\n";  // the line kept, so that messages name the file's own lines
      continue;
    }
    for (size_t k = 0; k < keep.size(); ++k) {
      out += (k > 0 ? "," : "");
      out += line == 1                                       ? keep[k]
             : static_cast<int>(fields.size()) > field_of[k] ? std::string(fields[field_of[k]])
                                                             : std::string();
    }
    out += "\n";
  }
  *text = std::move(out);
  return true;
}

bool RowsFromFile(const CableRobot& robot, std::vector<Row>* rows, std::string* error) {
  if (!FLAGS_lengths.empty() || !FLAGS_rpy.empty() || !FLAGS_quat.empty() ||
      !FLAGS_tensions_kN.empty()) {
    *error =
        "--data brings its own lengths, attitudes and tensions: drop --lengths, --rpy, "
        "--quat and --tensions-kN";
    return false;
  }
  DatasetReadOptions read;
  read.required_columns = DatasetColumns::kLengths;
  SetJointColumns(robot.moving_parts, &read);
  if (!ColumnsFromFlag(&read.columns, error)) return false;
  Dataset data;
  std::string solved;  // solve's output as a lengths file, when --data is one
  int left_out = 0;
  if (read.columns == nullptr && !SolveOutputAsLengths(FLAGS_data, &solved, &left_out, error)) {
    return false;
  }
  if (!(solved.empty() ? ReadDataset(FLAGS_data, read, &data, error)
                       : ParseDataset(solved, FLAGS_data, read, &data, error))) {
    return false;
  }
  if (left_out > 0) {
    std::cerr << "fastcal locate: " << left_out << " of " << left_out + data.samples.size()
              << " rows of " << FLAGS_data << " left out: solve did not solve them (status)"
              << std::endl;
  }
  rows->clear();
  rows->reserve(data.samples.size());
  for (const Sample& s : data.samples) {
    Row row;
    row.line = s.line;
    row.has_time = data.has_time;
    row.time_s = s.time_s;
    row.has_position = data.has_position;
    row.position_m = s.pose.position_m;
    row.measurement.length_m = s.unstretched_length_m;
    row.measurement.has_attitude = data.has_measured_attitude;
    row.measurement.rotation = s.pose.rotation;
    row.measurement.has_tensions = data.has_tensions;
    row.measurement.tension_n = s.tension_n;
    row.joints = s.joint;
    rows->push_back(row);
  }
  return true;
}

// The sigmas of the data's pose: position (m) and roll, pitch, yaw (deg), from the
// covariance of the cabin's (r_p, rotation vector in global axes). The measured point
// m = r_p + w, w = m - r_p fixed to the cabin, moves by dr_p - [w]x dtheta, and the
// measured frame turns with the cabin (measured_frame.h (1)-(2)).
Eigen::Matrix<double, 6, 1> Sigmas(const LocateSolution& s, const Pose& data) {
  Eigen::Matrix<double, 6, 6> to_data = Eigen::Matrix<double, 6, 6>::Identity();
  const Eigen::Vector3d w = data.position_m - s.pose.position_m;
  to_data.topRightCorner<3, 3>() << 0.0, w.z(), -w.y(), -w.z(), 0.0, w.x(), w.y(), -w.x(), 0.0;
  const Eigen::Matrix<double, 6, 6> c = to_data * s.fit.covariance * to_data.transpose();
  const Eigen::Matrix3d j = RpyDegPerRotationVector(data.rotation);
  const Eigen::Matrix3d rpy = j * c.bottomRightCorner<3, 3>() * j.transpose();
  Eigen::Matrix<double, 6, 1> sigma;
  for (int k = 0; k < 3; ++k) {
    sigma[k] = std::sqrt(std::max(0.0, c(k, k)));
    sigma[3 + k] = std::sqrt(std::max(0.0, rpy(k, k)));
  }
  return sigma;
}

// `loaded`: the model as loaded (its measured frame and parts), `joints` the row's.
Answer AnswerOf(const LocateSolution& s, const CableRobot& loaded, const JointValues& joints) {
  Answer a;
  a.status = s.status;
  a.stability = s.stability;
  const bool ok = s.status == StaticsStatus::kOk;
  a.message = ok && s.stability == Stability::kStable && s.other_equilibria == 0
                  ? ""
                  : DescribeLocateStatus(s);
  a.cabin = s.pose;
  a.pose = loaded.MeasuredPose(s.pose, joints);
  for (int i = 0; i < kNumCables; ++i) a.tension_n[i] = s.statics.cables[i].lower_tension_n;
  if (ok) a.sigma = Sigmas(s, a.pose);
  a.min_stiffness_n_per_m = s.min_stiffness_n_per_m;
  a.other_equilibria = s.other_equilibria;
  a.nearest_other_m = s.nearest_other.distance_m;
  a.readings = s.fit.readings;
  a.chi2 = s.fit.chi2;
  const int dof = s.fit.readings - 6;
  a.misfit = ok && s.fit.fitted && dof > 0 && s.fit.chi2 > MisfitLimit(dof);
  if (a.misfit) {
    a.message += (a.message.empty() ? "" : "; ") + std::string("the measurements disagree: chi2 ") +
                 FormatDouble(s.fit.chi2, 4) + " over " + std::to_string(dof) +
                 " degrees of freedom, where a correct noise model stays below " +
                 FormatDouble(MisfitLimit(dof), 3) +
                 " in 999 rows of 1000 (a slipped encoder, a sensor's error, sigmas too "
                 "small, or another model)";
  }
  a.error_estimate_m = s.error_estimate_m;
  return a;
}

// "row 3 (line 5)" or "row 3".
std::string RowName(const std::vector<Row>& rows, size_t n) {
  return "row " + std::to_string(n) +
         (rows[n].line > 0 ? " (" + FLAGS_data + " line " + std::to_string(rows[n].line) + ")"
                           : "");
}

// `cabin`: the model declares a measured frame: x_m..yaw_deg are its pose (the data's)
// and cabin_x_m..cabin_yaw_deg the cabin's.
std::string Csv(const std::vector<Row>& rows, const std::vector<Answer>& answers, bool cabin) {
  std::ostringstream out;
  // A string stream that runs out of memory only sets badbit and returns what it has:
  // a truncated table written with exit 0 (issue 37). Out of memory is thrown instead.
  out.exceptions(std::ios::badbit);
  out << "row,line,time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg";
  if (cabin) out << ",cabin_x_m,cabin_y_m,cabin_z_m,cabin_roll_deg,cabin_pitch_deg,cabin_yaw_deg";
  out << ",status,stability";
  for (int i = 1; i <= kNumCables; ++i) out << ",T" << i << "_kN";
  out << ",sigma_x_m,sigma_y_m,sigma_z_m,sigma_roll_deg,sigma_pitch_deg,sigma_yaw_deg"
         ",min_stiffness_kN_per_m,other_equilibria,nearest_other_m,readings,chi2,"
         "error_estimate_m,message\n";
  for (size_t n = 0; n < rows.size(); ++n) {
    const Answer& a = answers[n];
    const bool ok = a.status == StaticsStatus::kOk;
    auto put = [&](double v) { out << "," << (ok ? FormatDouble(v) : ""); };
    out << n << "," << (rows[n].line > 0 ? std::to_string(rows[n].line) : "") << ","
        << (rows[n].has_time ? FormatDouble(rows[n].time_s, 17) : "");
    for (const Pose* p : {&a.pose, cabin ? &a.cabin : nullptr}) {
      if (p == nullptr) continue;
      for (int k = 0; k < 3; ++k) put(p->position_m[k]);
      const Eigen::Vector3d rpy = RpyDegFromRotation(p->rotation);
      for (int k = 0; k < 3; ++k) put(rpy[k]);
    }
    out << "," << StaticsStatusName(a.status) << "," << StabilityName(a.stability);
    for (double t : a.tension_n) put(t / kNPerKn);
    for (int k = 0; k < 6; ++k) put(a.sigma[k]);
    put(a.min_stiffness_n_per_m / kNPerKn);
    out << "," << (ok ? std::to_string(a.other_equilibria) : "") << ","
        << (ok && a.other_equilibria > 0 ? FormatDouble(a.nearest_other_m) : "");
    out << "," << (ok ? std::to_string(a.readings) : "");
    put(a.chi2);
    put(a.error_estimate_m);
    out << "," << internal::QuotedCsvField(a.message) << "\n";
  }
  return out.str();
}

// The summary's account of the rows: failures, unstable and non-unique answers, and how
// far the answers are from the file's positions.
std::string Findings(const std::vector<Row>& rows, const std::vector<Answer>& answers,
                     size_t* failed) {
  std::ostringstream s;
  // A string stream that runs out of memory only sets badbit and returns what it has:
  // a truncated table written with exit 0 (issue 37). Out of memory is thrown instead.
  s.exceptions(std::ios::badbit);
  size_t unstable = 0, others = 0, compared = 0, worst_row = 0, misfits = 0;
  std::string first_unusual, first_misfit;
  double sum2 = 0.0, worst = 0.0;
  *failed = 0;
  for (size_t n = 0; n < rows.size(); ++n) {
    const Answer& a = answers[n];
    if (a.status != StaticsStatus::kOk) {
      ++*failed;
      continue;
    }
    const bool unusual = a.stability != Stability::kStable || a.other_equilibria > 0;
    unstable += a.stability != Stability::kStable ? 1 : 0;
    others += a.other_equilibria > 0 ? 1 : 0;
    if (unusual && first_unusual.empty()) first_unusual = RowName(rows, n) + ": " + a.message;
    misfits += a.misfit ? 1 : 0;
    if (a.misfit && first_misfit.empty()) first_misfit = RowName(rows, n) + ": " + a.message;
    if (rows[n].has_position) {
      const double d = (a.pose.position_m - rows[n].position_m).norm();
      sum2 += d * d;
      ++compared;
      if (d >= worst) {
        worst = d;
        worst_row = n;
      }
    }
  }
  if (unstable + others > 0) {
    s << "\n  " << unstable << " not stable, " << others
      << " with another equilibrium nearby; first: " << first_unusual;
  }
  if (misfits > 0) {
    s << "\n  " << misfits << " whose measurements disagree; first: " << first_misfit;
  }
  if (compared > 0) {
    s << "\n  against the file's x_m,y_m,z_m: RMS " << FormatDouble(std::sqrt(sum2 / compared), 4)
      << " m, largest " << FormatDouble(worst, 4) << " m at " << RowName(rows, worst_row);
  }
  return s.str();
}

std::string Fitted(const std::vector<Row>& rows, const Use& use) {
  bool attitude = false, tensions = false;
  for (const Row& r : rows) {
    attitude = attitude || (use.attitude && r.measurement.has_attitude);
    tensions = tensions || (use.tensions && r.measurement.has_tensions);
  }
  if (!attitude && !tensions) return "lengths alone (the forward statics)";
  return std::string("lengths") + (attitude ? ", attitude" : "") + (tensions ? ", tensions" : "") +
         " fitted together";
}

}  // namespace

int RunLocate(int argc, char** argv) {
  int exit_code = 0;
  if (!StartCommand(argc, argv, kCommand, kHelp, kFlags, &exit_code)) return exit_code;
  std::string error;
  CableRobot robot;
  LocateOptions options;
  LocateNoise noise;
  Use use;
  std::vector<Row> rows;
  const bool from_file = !FLAGS_data.empty();
  const bool ok =
      CheckCanWrite("output", FLAGS_output, FLAGS_force, &error) &&
      CheckFlagsApply({{"force", !FLAGS_output.empty() && FLAGS_output != "-", "--output=FILE"}},
                      "output to stdout", &error) &&
      LoadModelFlag("model", FLAGS_model, &robot, &error) && OptionsFromFlags(&options, &error) &&
      NoiseFromFlags(robot, &noise, &error) && ParseUse(&use, &error);
  if (!ok) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  if (!from_file && FLAGS_lengths.empty()) {
    PrintError(kCommand, "give --lengths=L1,...,L6 or --data=FILE.csv (see fastcal locate --help)");
    return kExitUsage;
  }
  if (from_file && !FLAGS_joints.empty()) {
    PrintError(kCommand,
               "--data brings its own joint values (the model's joint columns): drop "
               "--joints");
    return kExitUsage;
  }
  // As loaded: its parts and measured frame, before --joints fixes the mass centre.
  const CableRobot loaded = robot;
  JointValues flag_joints{};
  if (!(from_file ? RowsFromFile(robot, &rows, &error) : RowFromFlags(&rows, &error)) ||
      !MassCentreAtJointsFlag(FLAGS_joints, &robot, &error, &flag_joints)) {
    PrintError(kCommand, error);
    return kExitUsage;
  }
  if (!from_file) rows.front().joints = flag_joints;
  std::vector<Answer> answers;
  answers.reserve(rows.size());
  LocateSolution solution;
  const auto start = std::chrono::steady_clock::now();
  for (Row& row : rows) {
    row.measurement.has_attitude = row.measurement.has_attitude && use.attitude;
    row.measurement.has_tensions = row.measurement.has_tensions && use.tensions;
    // The measured attitude is the data's frame's: the cabin's follows from the joints.
    Pose attitude;
    attitude.rotation = row.measurement.rotation;
    row.measurement.rotation = loaded.CabinPose(attitude, row.joints).rotation;
    if (robot.moving_parts.empty()) {
      LocateFromMeasurements(robot, row.measurement, noise, options, &solution);
    } else {  // the row's own mass centre (moving_parts.h eq. (1))
      CableRobot at = robot;
      at.mass_centre_cabin_m = robot.MassCentreAt(row.joints);
      at.moving_parts.parts.clear();
      LocateFromMeasurements(at, row.measurement, noise, options, &solution);
    }
    answers.push_back(AnswerOf(solution, loaded, row.joints));
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (size_t n = 0; n < rows.size() && !FLAGS_keep_going; ++n) {
    if (answers[n].status != StaticsStatus::kOk) {
      PrintError(kCommand, RowName(rows, n) + ": " + answers[n].message);
      return kExitFailure;
    }
  }
  // The output was checked before the work: a failure now is the machine's (a full disk).
  if (!WriteOutput(FLAGS_output, Csv(rows, answers, loaded.measured_frame.has_value()), &error,
                   FLAGS_force)) {
    PrintError(kCommand, error);
    return kExitFailure;
  }
  size_t failed = 0;
  const std::string findings = Findings(rows, answers, &failed);
  std::ostream& summary = FLAGS_output.empty() || FLAGS_output == "-" ? std::cerr : std::cout;
  summary << "fastcal locate: " << rows.size() << (rows.size() == 1 ? " row" : " rows");
  if (failed > 0) summary << " (" << failed << " failed, written with their status)";
  summary << ", model " << internal::Escape(ModelName(FLAGS_model)) << ", " << Fitted(rows, use)
          << "; " << FormatDouble(1e6 * seconds / rows.size(), 3) << " us/row" << findings
          << std::endl;
  return 0;
}

}  // namespace fastcal::cli
