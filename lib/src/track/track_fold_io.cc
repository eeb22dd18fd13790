// Fold tasks and folds as bytes (track_fold.h): a tag, then fields in a fixed order, each
// number little-endian (int64 for integers and counts, IEEE double for reals), each string
// as its length (int64) then its bytes, each matrix as rows, columns, then its entries
// row by row. docs/calibration.md, "Tracking: files", lists the fields.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "fastcal/track_fold.h"

namespace fastcal {
namespace {

// Version 4 added the fine scan's blocks and columns; a version 3 task is read as one
// without them.
constexpr char kTaskTag[] = "fastcal-fold-task-4";
constexpr char kTaskTag3[] = "fastcal-fold-task-3";
constexpr char kFoldTag[] = "fastcal-fold-1";
// Bounds on what a reader accepts, against corrupt or hostile bytes.
constexpr std::int64_t kMaxCount = 1LL << 31;

class Writer {
 public:
  void Int(std::int64_t v) { Raw(&v, sizeof(v)); }
  void Real(double v) { Raw(&v, sizeof(v)); }
  void Text(const std::string& s) {
    Int(static_cast<std::int64_t>(s.size()));
    out_ += s;
  }
  void Matrix(const Eigen::MatrixXd& m) {
    Int(m.rows());
    Int(m.cols());
    for (Eigen::Index r = 0; r < m.rows(); ++r) {
      for (Eigen::Index c = 0; c < m.cols(); ++c) Real(m(r, c));
    }
  }
  void Reals(const std::vector<double>& v) {
    Int(static_cast<std::int64_t>(v.size()));
    for (double x : v) Real(x);
  }
  void Process(const SlowErrorProcess& p) {
    Real(p.sigma_n);
    Real(p.sigma_percent);
    Real(p.time_constant_s);
  }
  std::string& str() { return out_; }

 private:
  void Raw(const void* p, size_t n) { out_.append(static_cast<const char*>(p), n); }
  std::string out_;
};

class Reader {
 public:
  Reader(const std::string& bytes, const std::string& source) : in_(bytes), source_(source) {}
  bool ok() const { return ok_; }
  bool AtEnd() const { return pos_ == in_.size(); }
  std::string Error() const {
    return source_ + ": not a valid " + what_ + " (truncated or corrupt at byte " +
           std::to_string(pos_) + ")";
  }
  void What(const std::string& what) { what_ = what; }
  std::int64_t Int() {
    std::int64_t v = 0;
    Raw(&v, sizeof(v));
    return v;
  }
  // A count of items that each take at least one byte: no more than the bytes left.
  std::int64_t Count() {
    const std::int64_t v = Int();
    if (v < 0 || v > kMaxCount || v > static_cast<std::int64_t>(in_.size() - pos_)) ok_ = false;
    return ok_ ? v : 0;
  }
  double Real() {
    double v = 0.0;
    Raw(&v, sizeof(v));
    return v;
  }
  std::string Text() {
    const std::int64_t n = Count();
    if (!ok_ || n > static_cast<std::int64_t>(in_.size() - pos_)) {
      ok_ = false;
      return "";
    }
    std::string s = in_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  Eigen::MatrixXd Matrix() {
    const std::int64_t rows = Count(), cols = Count();
    if (!ok_ || (rows > 0 && cols > static_cast<std::int64_t>(in_.size() - pos_) / 8 / rows)) {
      ok_ = false;
      return Eigen::MatrixXd();
    }
    Eigen::MatrixXd m(rows, cols);
    for (Eigen::Index r = 0; r < rows; ++r) {
      for (Eigen::Index c = 0; c < cols; ++c) m(r, c) = Real();
    }
    return m;
  }
  std::vector<double> Reals() {
    const std::int64_t n = Count();
    if (!ok_ || n > static_cast<std::int64_t>(in_.size() - pos_) / 8) {
      ok_ = false;
      return {};
    }
    std::vector<double> v(n);
    for (double& x : v) x = Real();
    return v;
  }
  SlowErrorProcess Process() {
    SlowErrorProcess p;
    p.sigma_n = Real();
    p.sigma_percent = Real();
    p.time_constant_s = Real();
    return p;
  }

 private:
  void Raw(void* p, size_t n) {
    if (!ok_ || in_.size() - pos_ < n) {
      ok_ = false;
      std::memset(p, 0, n);
      return;
    }
    std::memcpy(p, in_.data() + pos_, n);
    pos_ += n;
  }
  const std::string& in_;
  std::string source_, what_ = "file";
  size_t pos_ = 0;
  bool ok_ = true;
};

void WriteParameter(const ParameterSpec& p, Writer* w) {
  w->Int(static_cast<int>(p.kind));
  w->Int(p.index);
  w->Int(p.component);
  w->Text(p.name);
  w->Text(p.unit);
  w->Real(p.to_si);
  w->Int(p.free);
  w->Int(p.has_initial);
  w->Real(p.initial_si);
  w->Int(p.has_prior);
  w->Real(p.prior_mean_si);
  w->Real(p.prior_sigma_si);
}

ParameterSpec ReadParameter(Reader* r) {
  ParameterSpec p;
  const std::int64_t kind = r->Int();
  if (kind < 0 || kind > static_cast<int>(kLastParameterKind)) r->Count();
  p.kind = static_cast<ParameterKind>(kind);
  p.index = static_cast<int>(r->Int());
  p.component = static_cast<int>(r->Int());
  p.name = r->Text();
  p.unit = r->Text();
  p.to_si = r->Real();
  p.free = r->Int() != 0;
  p.has_initial = r->Int() != 0;
  p.initial_si = r->Real();
  p.has_prior = r->Int() != 0;
  p.prior_mean_si = r->Real();
  p.prior_sigma_si = r->Real();
  return p;
}

bool CheckTag(Reader* r, const char* tag, const std::string& source, std::string* error) {
  r->What(tag);
  if (r->Text() == tag && r->ok()) return true;
  *error = source + ": not a " + tag + " (wrong tag: a file of another kind or version)";
  return false;
}

std::vector<FoldRole> ReadRoles(Reader* r) {
  std::vector<FoldRole> roles(r->Count());
  for (FoldRole& role : roles) {
    const std::int64_t v = r->Int();
    if (v < 0 || v > 2) r->Count();  // an impossible count marks the bytes invalid
    role = static_cast<FoldRole>(v < 0 || v > 2 ? 0 : v);
  }
  return roles;
}

void WriteRoles(const std::vector<FoldRole>& roles, Writer* w) {
  w->Int(static_cast<std::int64_t>(roles.size()));
  for (FoldRole role : roles) w->Int(static_cast<int>(role));
}

}  // namespace

bool FoldTask::IsValid(std::string* error) const {
  int free = 0;
  for (const ParameterSpec& p : parameters) free += p.free;
  std::string why;
  if (free == 0)
    why = "no columns";
  else if (static_cast<int>(roles.size()) != free)
    why = "a role per column is needed";
  else if (static_cast<int>(theta_si.size()) != free)
    why = "a value per column is needed";
  else if (!(tension_sigma_n >= 0.0 && tension_sigma_percent >= 0.0) ||
           tension_sigma_n + tension_sigma_percent <= 0.0) {
    why = "the white noise must be > 0";
  } else if (!slow_error.IsValid(&why)) {
    why = "slow error: " + why;
  } else if (blocks < 1 || threads < 1 || residual_samples < 0) {
    why = "blocks and threads must be >= 1";
  } else if (stride < 1) {
    why = "the stride must be >= 1";
  } else if (!fine_columns.empty() && (fine_first_block < 0 || fine_end_block < fine_first_block ||
                                       fine_end_block > blocks || stride != 1)) {
    why = "the fine scan's blocks must lie in [0, blocks], with every sample (stride 1)";
  }
  if (why.empty() && !fine_columns.empty()) {
    std::vector<ParameterSpec> columns;
    for (const ParameterSpec& p : parameters) {
      if (p.free) columns.push_back(p);
    }
    const std::vector<int> rows = BlockRowColumns(columns, roles);
    for (int c : fine_columns) {
      if (std::find(rows.begin(), rows.end(), c) == rows.end()) {
        why = "a fine scan's column is not one of the blocks' rows";
      }
    }
  }
  for (double v : theta_si) {
    if (why.empty() && !std::isfinite(v)) why = "a value is not finite";
  }
  if (why.empty()) return true;
  *error = "fold task " + label + ": " + why;
  return false;
}

std::string SerializeFoldTask(const FoldTask& t) {
  Writer w;
  w.Text(kTaskTag);
  w.Text(t.label);
  w.Text(t.samples_path);
  w.Int(static_cast<std::int64_t>(t.files.size()));
  for (const std::string& f : t.files) w.Text(f);
  w.Text(t.model_yaml);
  w.Int(static_cast<std::int64_t>(t.parameters.size()));
  for (const ParameterSpec& p : t.parameters) WriteParameter(p, &w);
  WriteRoles(t.roles, &w);
  w.Int(static_cast<int>(t.forward_model));
  w.Real(t.tension_sigma_n);
  w.Real(t.tension_sigma_percent);
  w.Int(t.detect_gross_errors);
  w.Real(t.gross_error_threshold_sigmas);
  w.Process(t.slow_error);
  w.Reals(t.theta_si);
  w.Int(t.blocks);
  w.Int(t.residual_samples);
  w.Int(t.threads);
  w.Int(t.stride);
  w.Int(t.fine_first_block);
  w.Int(t.fine_end_block);
  w.Int(static_cast<std::int64_t>(t.fine_columns.size()));
  for (int c : t.fine_columns) w.Int(c);
  return std::move(w.str());
}

bool ParseFoldTask(const std::string& bytes, FoldTask* task, std::string* error) {
  Reader peek(bytes, "fold task");
  const bool version3 = peek.Text() == kTaskTag3 && peek.ok();
  Reader r(bytes, "fold task");
  if (!CheckTag(&r, version3 ? kTaskTag3 : kTaskTag, "fold task", error)) return false;
  FoldTask t;
  t.label = r.Text();
  t.samples_path = r.Text();
  t.files.resize(r.Count());
  for (std::string& f : t.files) f = r.Text();
  t.model_yaml = r.Text();
  t.parameters.resize(r.Count());
  for (ParameterSpec& p : t.parameters) p = ReadParameter(&r);
  t.roles = ReadRoles(&r);
  t.forward_model = static_cast<StaticsMethod>(r.Int());
  t.tension_sigma_n = r.Real();
  t.tension_sigma_percent = r.Real();
  t.detect_gross_errors = r.Int() != 0;
  t.gross_error_threshold_sigmas = r.Real();
  t.slow_error = r.Process();
  t.theta_si = r.Reals();
  t.blocks = static_cast<int>(r.Int());
  t.residual_samples = static_cast<int>(r.Int());
  t.threads = static_cast<int>(r.Int());
  t.stride = static_cast<int>(r.Int());
  if (!version3) {
    t.fine_first_block = static_cast<int>(r.Int());
    t.fine_end_block = static_cast<int>(r.Int());
    t.fine_columns.resize(r.Count());
    for (int& c : t.fine_columns) c = static_cast<int>(r.Int());
  }
  if (!r.ok() || !r.AtEnd()) {
    *error = r.Error();
    return false;
  }
  *task = std::move(t);
  return true;
}

std::string SerializeWindowFold(const WindowFold& f) {
  Writer w;
  w.Text(kFoldTag);
  w.Text(f.label);
  w.Int(f.samples);
  w.Int(f.readings);
  w.Real(f.first_time_s);
  w.Real(f.last_time_s);
  w.Int(static_cast<std::int64_t>(f.columns.size()));
  for (const std::string& c : f.columns) w.Text(c);
  WriteRoles(f.roles, &w);
  w.Reals(f.theta_si);
  w.Process(f.slow_error);
  w.Real(f.gross_error_threshold_sigmas);
  w.Matrix(f.information);
  w.Matrix(f.gradient);
  w.Real(f.chi_square);
  w.Int(static_cast<std::int64_t>(f.block_samples.size()));
  for (long long n : f.block_samples) w.Int(n);
  for (size_t b = 0; b < f.block_samples.size(); ++b) {
    w.Real(f.block_first_time_s[b]);
    w.Real(f.block_last_time_s[b]);
  }
  w.Matrix(f.block_scores);
  w.Int(static_cast<std::int64_t>(f.block_information.size()));
  for (const Eigen::MatrixXd& m : f.block_information) w.Matrix(m);
  for (int i = 0; i < kNumCables; ++i) {
    w.Real(f.sum_sq_n2[i]);
    w.Int(f.count[i]);
  }
  w.Int(f.gross_error_count);
  w.Int(static_cast<std::int64_t>(f.gross_errors.size()));
  for (const FoldGrossError& g : f.gross_errors) {
    w.Int(g.file);
    w.Int(g.line);
    w.Int(g.cable);
    w.Real(g.measured_n);
    w.Real(g.predicted_n);
    w.Real(g.residual_sigma);
  }
  w.Int(static_cast<std::int64_t>(f.residuals.size()));
  for (const FoldResidual& r : f.residuals) {
    w.Real(r.time_s);
    for (int i = 0; i < kNumCables; ++i) {
      w.Real(r.x[i]);
      w.Real(r.sigma_n[i]);
      w.Real(r.reading_n[i]);
      w.Int(r.excluded[i]);
    }
  }
  // A fine scan's cuts (a fold of a track's window has none: its bytes end here, as
  // before the fine scans).
  if (!f.fine.empty()) {
    w.Int(static_cast<std::int64_t>(f.fine.columns.size()));
    for (int c : f.fine.columns) w.Int(c);
    w.Reals(f.fine.after_s);
    w.Reals(f.fine.before_s);
    w.Int(static_cast<std::int64_t>(f.fine.cross.size()));
    for (size_t k = 0; k < f.fine.cross.size(); ++k) {
      w.Matrix(f.fine.cross[k]);
      w.Matrix(f.fine.self[k]);
    }
  }
  return std::move(w.str());
}

namespace {

// Largest |entry| of a fold's information in SI (issue 37: finite nonsense passed, a
// sigma_total of 1e-150 m): a sigma of 1e-15 in any SI unit is far below any telemetry's.
constexpr double kMaxInformation = 1e30;
// Relative asymmetry of the information beyond rounding: not a fold's.
constexpr double kAsymmetry = 1e-9;
// Largest chi-square a reading contributes: residuals of 10^6 sigmas (a unit slip of 1000x
// gives about 10^3); beyond it a fold's chi-square is no telemetry's (issue 37: 1e300 gave
// a sigma_total of 2.4e145 m through the misfit's widening).
constexpr double kMaxChiSquarePerReading = 1e12;

bool AllFinite(const Eigen::MatrixXd& m) { return m.allFinite(); }

// "" when the blocks are parts of the window as a fold's are (track_fold.h); else which is
// not (issue 37: a block's information or score scaled by 1e10, with the state's digest
// forged, gave sigma_totals of 3e5 m, exit 0). Their samples add up to the window's, their
// scores to its gradient and each row of their information to a row of its information
// (to rounding); and by Cauchy-Schwarz over a block's whitened rows, no entry of a block's
// information exceeds sqrt(H_kk H_cc) of the window's, nor a block's score sqrt(H_cc c).
std::string BlocksDisagree(const WindowFold& f) {
  if (f.block_samples.empty()) return "";
  const Eigen::Index n = f.gradient.size();
  constexpr double kRelative = 1e-6;  // the identities hold to rounding (~1e-12)
  constexpr double kTiny = 1e-300;
  long long samples = 0;
  for (long long b : f.block_samples) samples += b;
  if (samples != f.samples) return "blocks of other samples than the window's";
  if (f.block_scores.cols() != n ||
      static_cast<size_t>(f.block_scores.rows()) != f.block_samples.size()) {
    return "block scores of another shape";
  }
  const Eigen::VectorXd root_h = f.information.diagonal().cwiseMax(0.0).cwiseSqrt();
  const double root_c = std::sqrt(std::max(f.chi_square, 0.0));
  for (Eigen::Index b = 0; b < f.block_scores.rows(); ++b) {
    for (Eigen::Index c = 0; c < n; ++c) {
      if (std::abs(f.block_scores(b, c)) > (1.0 + kRelative) * root_h[c] * root_c + kTiny) {
        return "a block score larger than the window's information and chi-square allow";
      }
    }
  }
  const Eigen::VectorXd scores = f.block_scores.colwise().sum().transpose();
  if ((scores - f.gradient).norm() > kRelative * root_h.norm() * root_c + kTiny) {
    return "block scores that do not add up to the gradient";
  }
  if (f.block_information.empty()) return "";
  Eigen::MatrixXd rows = Eigen::MatrixXd::Zero(f.block_information[0].rows(), n);
  for (const Eigen::MatrixXd& m : f.block_information) {
    if (m.rows() != rows.rows() || m.cols() != n) return "block informations of another shape";
    rows += m;
  }
  std::vector<Eigen::Index> column_of(rows.rows(), -1);
  for (Eigen::Index r = 0; r < rows.rows(); ++r) {
    for (Eigen::Index k = 0; k < f.information.rows() && column_of[r] < 0; ++k) {
      // Relative to the two rows themselves: the whole information scaled matches none.
      const double scale = rows.row(r).norm() + f.information.row(k).norm() + kTiny;
      if ((rows.row(r) - f.information.row(k)).norm() <= kRelative * scale) column_of[r] = k;
    }
    if (column_of[r] < 0) return "block informations that do not add up to the window's";
  }
  for (const Eigen::MatrixXd& m : f.block_information) {
    for (Eigen::Index r = 0; r < m.rows(); ++r) {
      for (Eigen::Index c = 0; c < n; ++c) {
        if (std::abs(m(r, c)) > (1.0 + kRelative) * root_h[column_of[r]] * root_h[c] + kTiny) {
          return "a block's information larger than the window's";
        }
      }
    }
  }
  return "";
}

// "" when every number of a parsed fold is in range; else which is not.
std::string OutOfRange(const WindowFold& f) {
  const auto finite_all = [](const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
  };
  if (f.samples < 0 || f.readings < 0 || f.gross_error_count < 0) return "a negative count";
  if (!std::isfinite(f.first_time_s) || !std::isfinite(f.last_time_s) ||
      f.first_time_s > f.last_time_s) {
    return "its time span is not one";
  }
  if (!finite_all(f.theta_si)) return "a point that is not finite";
  std::string why;
  if (!f.slow_error.IsValid(&why)) return "its slow error: " + why;
  if (!AllFinite(f.information) || !AllFinite(f.gradient) || !std::isfinite(f.chi_square) ||
      f.chi_square < 0.0) {
    return "information, gradient or chi-square not finite";
  }
  const double scale = f.information.size() > 0 ? f.information.cwiseAbs().maxCoeff() : 0.0;
  if (scale > kMaxInformation) return "information beyond any telemetry's";
  if (f.gradient.size() > 0 && f.gradient.cwiseAbs().maxCoeff() > kMaxInformation) {
    return "a gradient beyond any telemetry's";
  }
  const double readings = static_cast<double>(std::max<long long>(1, f.readings));
  if (f.chi_square > kMaxChiSquarePerReading * readings) {
    return "a chi-square beyond any telemetry's (" + std::to_string(f.chi_square) + " for " +
           std::to_string(f.readings) + " readings)";
  }
  if (f.information.size() > 0 &&
      (f.information - f.information.transpose()).cwiseAbs().maxCoeff() > kAsymmetry * scale) {
    return "an information matrix that is not symmetric";
  }
  for (Eigen::Index k = 0; k < f.information.rows(); ++k) {
    if (f.information(k, k) < 0.0) return "a negative information";
  }
  for (long long n : f.block_samples) {
    if (n < 0) return "a negative block";
  }
  if (!AllFinite(f.block_scores)) return "a block score not finite";
  if (f.block_scores.size() > 0 && f.block_scores.cwiseAbs().maxCoeff() > kMaxInformation) {
    return "a block score beyond any telemetry's";
  }
  // A block's information is part of the window's: no larger in any entry (issue 37:
  // x1e200 gave NaN sigma_totals in every window).
  for (const Eigen::MatrixXd& m : f.block_information) {
    if (!AllFinite(m)) return "a block's information not finite";
    if (m.size() > 0 && m.cwiseAbs().maxCoeff() > kMaxInformation) {
      return "a block's information beyond any telemetry's";
    }
  }
  if (const std::string why = BlocksDisagree(f); !why.empty()) return why;
  constexpr double kMaxSquaredReadingN2 = 1e18;  // a reading's residual of 10^9 N, squared
  for (int i = 0; i < kNumCables; ++i) {
    if (f.count[i] < 0 || !(f.sum_sq_n2[i] >= 0.0) || !std::isfinite(f.sum_sq_n2[i]) ||
        f.sum_sq_n2[i] > kMaxSquaredReadingN2 * static_cast<double>(std::max(1LL, f.count[i]))) {
      return "a cable's residual sums out of range";
    }
  }
  for (const FoldGrossError& g : f.gross_errors) {
    if (g.cable < 1 || g.cable > kNumCables) return "a gross error's cable out of range";  // 1..6
  }
  return "";
}

}  // namespace

bool ParseWindowFold(const std::string& bytes, const std::string& source, WindowFold* fold,
                     std::string* error) {
  Reader r(bytes, source);
  if (!CheckTag(&r, kFoldTag, source, error)) return false;
  WindowFold f;
  f.label = r.Text();
  f.samples = r.Int();
  f.readings = r.Int();
  f.first_time_s = r.Real();
  f.last_time_s = r.Real();
  f.columns.resize(r.Count());
  for (std::string& c : f.columns) c = r.Text();
  f.roles = ReadRoles(&r);
  f.theta_si = r.Reals();
  f.slow_error = r.Process();
  f.gross_error_threshold_sigmas = r.Real();
  f.information = r.Matrix();
  const Eigen::MatrixXd gradient = r.Matrix();
  if (gradient.cols() == 1) f.gradient = gradient;
  f.chi_square = r.Real();
  f.block_samples.resize(r.Count());
  for (long long& n : f.block_samples) n = r.Int();
  f.block_first_time_s.resize(f.block_samples.size());
  f.block_last_time_s.resize(f.block_samples.size());
  for (size_t b = 0; b < f.block_samples.size(); ++b) {
    f.block_first_time_s[b] = r.Real();
    f.block_last_time_s[b] = r.Real();
  }
  f.block_scores = r.Matrix();
  f.block_information.resize(r.Count());
  for (Eigen::MatrixXd& m : f.block_information) m = r.Matrix();
  for (int i = 0; i < kNumCables; ++i) {
    f.sum_sq_n2[i] = r.Real();
    f.count[i] = r.Int();
  }
  f.gross_error_count = r.Int();
  f.gross_errors.resize(r.Count());
  for (FoldGrossError& g : f.gross_errors) {
    g.file = static_cast<int>(r.Int());
    g.line = static_cast<int>(r.Int());
    g.cable = static_cast<int>(r.Int());
    g.measured_n = r.Real();
    g.predicted_n = r.Real();
    g.residual_sigma = r.Real();
  }
  f.residuals.resize(r.Count());
  for (FoldResidual& x : f.residuals) {
    x.time_s = r.Real();
    for (int i = 0; i < kNumCables; ++i) {
      x.x[i] = r.Real();
      x.sigma_n[i] = r.Real();
      x.reading_n[i] = r.Real();
      x.excluded[i] = r.Int() != 0;
    }
  }
  if (r.ok() && !r.AtEnd()) {
    f.fine.columns.resize(r.Count());
    for (int& c : f.fine.columns) c = static_cast<int>(r.Int());
    f.fine.after_s = r.Reals();
    f.fine.before_s = r.Reals();
    f.fine.cross.resize(r.Count());
    f.fine.self.resize(f.fine.cross.size());
    for (size_t k = 0; k < f.fine.cross.size(); ++k) {
      f.fine.cross[k] = r.Matrix();
      f.fine.self[k] = r.Matrix();
    }
  }
  const size_t n = f.columns.size();
  const bool shapes = f.roles.size() == n && f.theta_si.size() == n &&
                      f.information.rows() == static_cast<Eigen::Index>(n) &&
                      f.information.cols() == static_cast<Eigen::Index>(n) &&
                      f.gradient.size() == static_cast<Eigen::Index>(n);
  if (!r.ok() || !r.AtEnd() || !shapes) {
    *error = r.Error();
    return false;
  }
  if (const std::string why = OutOfRange(f); !why.empty()) {
    *error = source + ": " + why + " (a damaged fold: --refold folds the window again)";
    return false;
  }
  *fold = std::move(f);
  return true;
}

bool RunFoldTask(const std::string& task_bytes, std::string* fold_bytes, std::string* error) {
  FoldTask task;
  if (!ParseFoldTask(task_bytes, &task, error)) return false;
  WindowFold fold;
  if (!FoldWindow(task, &fold, error)) return false;
  *fold_bytes = SerializeWindowFold(fold);
  return true;
}

}  // namespace fastcal
