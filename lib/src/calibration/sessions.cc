// Sessions: merging files, the joint fit's spec, differences between sessions (sessions.h).
#include "fastcal/sessions.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <utility>

#include "fastcal/internal/number_text.h"
#include "fastcal/internal/quote.h"

namespace fastcal {
namespace {

constexpr char kSessionSeparator = '@';

// Whether p is in one of the groups, or is one of the parameters named among them.
bool InGroups(const ParameterSpec& p, const std::vector<std::string>& groups) {
  for (const std::string& g : groups) {
    if (g == ParameterGroupName(p.kind) || g == p.name) return true;
  }
  return false;
}

// Appends files[index]'s samples to `merged` as the session(s) it carries; `owner[k]`
// is the index of the file that brought label k.
bool AppendFile(const std::vector<Dataset>& files, size_t index, Dataset* merged,
                std::vector<size_t>* owner, std::string* error) {
  const Dataset& file = files[index];
  std::vector<std::string> labels = file.session_labels;
  if (labels.empty()) {
    const std::string stem = SessionLabelOfPath(file.path);
    if (!IsValidSessionLabel(stem)) {
      *error = file.path + ": the file's name " + internal::Quote(stem) +
               " is not a session label (letters, digits, '-' and '_'): rename the file or give "
               "it a `session` column";
      return false;
    }
    labels.push_back(stem);
  }
  std::vector<int> map;
  for (const std::string& label : labels) {
    for (size_t k = 0; k < merged->session_labels.size(); ++k) {
      if (merged->session_labels[k] != label) continue;
      *error = "session " + internal::Quote(label) + " is in both " + files[(*owner)[k]].path +
               " and " + file.path +
               ": one label per session (rename a file, or give it a `session` column)";
      return false;
    }
    map.push_back(static_cast<int>(merged->session_labels.size()));
    merged->session_labels.push_back(label);
    merged->session_paths.push_back(file.path);
    owner->push_back(index);
  }
  for (Sample s : file.samples) {
    s.session = map[file.session_labels.empty() ? 0 : s.session];
    merged->samples.push_back(std::move(s));
  }
  merged->skipped.insert(merged->skipped.end(), file.skipped.begin(), file.skipped.end());
  return true;
}

}  // namespace

std::string SessionLabelOfPath(const std::string& path) {
  return std::filesystem::path(path).stem().string();
}

bool MergeSessionFiles(const std::vector<Dataset>& files, Dataset* merged, std::string* error) {
  if (files.empty()) {
    *error = "no dataset files to merge";
    return false;
  }
  Dataset out;
  out.has_planned_attitude = true;
  out.has_unstretched_lengths = true;
  out.attitude_as_quaternion = files.front().attitude_as_quaternion;
  out.time_offset_s = files.front().time_offset_s;
  out.joint_columns = files.front().joint_columns;  // read with the same options
  std::vector<size_t> owner;
  for (size_t f = 0; f < files.size(); ++f) {
    out.path += (f == 0 ? "" : ",") + files[f].path;
    out.has_planned_attitude = out.has_planned_attitude && files[f].has_planned_attitude;
    out.has_unstretched_lengths = out.has_unstretched_lengths && files[f].has_unstretched_lengths;
    if (!AppendFile(files, f, &out, &owner, error)) return false;
  }
  *merged = std::move(out);
  return true;
}

bool ReadSessionDatasets(const std::vector<std::string>& paths, const DatasetReadOptions& options,
                         Dataset* dataset, std::string* error) {
  if (paths.size() == 1) return ReadDataset(paths.front(), options, dataset, error);
  std::vector<Dataset> files(paths.size());
  for (size_t f = 0; f < paths.size(); ++f) {
    if (!ReadDataset(paths[f], options, &files[f], error)) return false;
  }
  return MergeSessionFiles(files, dataset, error);
}

std::string SessionCutLabel(int index) { return "s" + std::to_string(index + 1); }

int SessionOfTime(const std::vector<double>& cuts_s, double time_s) {
  int session = 0;
  while (session < static_cast<int>(cuts_s.size()) &&
         time_s >= cuts_s[session] - kSessionCutToleranceS) {
    ++session;
  }
  return session;
}

bool CheckSessionCuts(const std::vector<double>& cuts_s, std::string* error) {
  if (cuts_s.empty()) {
    *error = "no time to cut at";
    return false;
  }
  for (size_t k = 0; k < cuts_s.size(); ++k) {
    if (!std::isfinite(cuts_s[k])) {
      *error = "cut " + std::to_string(k + 1) + " is not a finite time";
      return false;
    }
    if (k > 0 && !(cuts_s[k] > cuts_s[k - 1])) {
      *error = "the times must increase (" + internal::FormatDouble("%.17g", cuts_s[k - 1]) +
               " then " + internal::FormatDouble("%.17g", cuts_s[k]) + ")";
      return false;
    }
  }
  return true;
}

bool CutSessionsAt(const std::vector<double>& cuts_s, Dataset* data, std::string* error) {
  const TimeDisplay display = TimeDisplayOf(*data);
  if (!CheckSessionCuts(cuts_s, error)) return false;
  if (!data->session_labels.empty()) {
    *error = data->path + ": the data has sessions already (" +
             std::to_string(data->session_labels.size()) +
             ", from a session column or several files): cutting at times is for one survey";
    return false;
  }
  std::vector<long long> count(cuts_s.size() + 1, 0);
  for (const Sample& s : data->samples) ++count[SessionOfTime(cuts_s, s.time_s)];
  for (size_t k = 0; k < count.size(); ++k) {
    if (count[k] > 0) continue;
    const std::string from = k == 0 ? "the start" : TimeText(cuts_s[k - 1], display);
    const std::string to = k == cuts_s.size() ? "the end" : TimeText(cuts_s[k], display);
    *error = data->path + ": no sample from " + from + " to " + to + " (session " +
             SessionCutLabel(static_cast<int>(k)) + " would be empty): cut within the survey";
    return false;
  }
  data->session_labels.clear();
  for (size_t k = 0; k < count.size(); ++k) {
    data->session_labels.push_back(SessionCutLabel(static_cast<int>(k)));
  }
  data->session_paths.clear();
  for (Sample& s : data->samples) s.session = SessionOfTime(cuts_s, s.time_s);
  return true;
}

std::string SessionParameterName(const std::string& name, const std::string& label) {
  return name + kSessionSeparator + label;
}

std::string SharedParameterName(const std::string& name) {
  return name.substr(0, name.find(kSessionSeparator));
}

CalibrationSpec SeparateSessionParameters(const CalibrationSpec& spec,
                                          const std::vector<std::string>& labels) {
  if (labels.size() < 2 || spec.separate_groups.empty()) return spec;
  CalibrationSpec joint = spec;
  joint.parameters.clear();
  for (const ParameterSpec& p : spec.parameters) {
    if (!p.free || !InGroups(p, spec.separate_groups)) {
      joint.parameters.push_back(p);
      continue;
    }
    for (size_t s = 0; s < labels.size(); ++s) {
      ParameterSpec copy = p;
      copy.session = static_cast<int>(s);
      copy.name = SessionParameterName(p.name, labels[s]);
      joint.parameters.push_back(copy);
    }
  }
  return joint;
}

std::vector<SessionDifference> ConsecutiveSessionDifferences(
    const std::vector<ParameterSpec>& free, const std::vector<double>& theta_si,
    const Eigen::MatrixXd& total_covariance, const std::vector<std::string>& labels) {
  std::vector<SessionDifference> out;
  const int n = static_cast<int>(free.size());
  for (int a = 0; a < n; ++a) {
    if (free[a].session < 0) continue;
    for (int b = 0; b < n; ++b) {
      // The copy of the same parameter in the next session.
      if (free[b].session != free[a].session + 1 ||
          SharedParameterName(free[b].name) != SharedParameterName(free[a].name)) {
        continue;
      }
      SessionDifference d;
      d.name = SharedParameterName(free[a].name);
      d.unit = free[a].unit;
      d.from = labels[free[a].session];
      d.to = labels[free[b].session];
      d.difference = (theta_si[b] - theta_si[a]) / free[a].to_si;
      if (total_covariance.rows() == n) {
        const double var =
            total_covariance(a, a) + total_covariance(b, b) - 2.0 * total_covariance(a, b);
        d.sigma_total = std::sqrt(std::max(var, 0.0)) / free[a].to_si;
      }
      out.push_back(d);
    }
  }
  // By session pair, then in parameter order.
  std::stable_sort(out.begin(), out.end(), [&labels](const auto& x, const auto& y) {
    const auto rank = [&labels](const std::string& l) {
      return std::find(labels.begin(), labels.end(), l) - labels.begin();
    };
    return rank(x.to) < rank(y.to);
  });
  return out;
}

std::string SessionVerdict(const std::vector<SessionDifference>& differences) {
  std::string out;
  for (size_t k = 0; k < differences.size();) {
    // The differences of one session pair.
    size_t end = k;
    while (end < differences.size() && differences[end].to == differences[k].to) ++end;
    std::string moved;
    const SessionDifference* largest = &differences[k];
    for (size_t j = k; j < end; ++j) {
      const SessionDifference& d = differences[j];
      if (std::abs(d.Sigmas()) > std::abs(largest->Sigmas())) largest = &d;
      if (!(std::abs(d.Sigmas()) > kSessionChangeSigmas)) continue;
      moved += (moved.empty() ? "" : ", ") + d.name + " by " +
               internal::FormatDouble("%+.3g", d.difference) + " " + d.unit + " (" +
               internal::FormatDouble("%.1f", std::abs(d.Sigmas())) + " sigma_total)";
    }
    out += (out.empty() ? "" : "; ") + std::string("from session ") + differences[k].from + " to " +
           differences[k].to + ": ";
    out += moved.empty()
               ? "nothing separate changed by more than " +
                     internal::FormatDouble("%g", kSessionChangeSigmas) + " sigma_total (largest " +
                     largest->name + ", " + internal::FormatDouble("%+.3g", largest->difference) +
                     " " + largest->unit + ", " +
                     internal::FormatDouble("%.1f", std::abs(largest->Sigmas())) + " sigma_total)"
               : "moved " + moved;
    k = end;
  }
  return out;
}

bool CheckSessions(const Dataset& data, std::string* error) {
  const int sessions = std::max<int>(1, static_cast<int>(data.session_labels.size()));
  for (size_t t = 0; t < data.samples.size(); ++t) {
    const int s = data.samples[t].session;
    if (s >= 0 && s < sessions) continue;
    *error = data.path + ": samples[" + std::to_string(t) + "] (line " +
             std::to_string(data.samples[t].line) + "): session " + std::to_string(s) +
             " is not an index into the " + std::to_string(data.session_labels.size()) +
             " session labels";
    return false;
  }
  for (const std::string& label : data.session_labels) {
    if (!IsValidSessionLabel(label)) {
      *error = data.path + ": " + internal::Quote(label) + " is not a session label";
      return false;
    }
  }
  return true;
}

}  // namespace fastcal
