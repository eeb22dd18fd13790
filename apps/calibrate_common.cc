// What calibrate and evaluate share (calibrate_common.h).
#include "calibrate_common.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.h"
#include "columns_flag.h"
#include "common_flags.h"
#include "fastcal/file_digest.h"
#include "fastcal/internal/paper_reference.h"
#include "fastcal/internal/quote.h"
#include "fastcal/version.h"

namespace fastcal::cli {
namespace {

namespace fs = std::filesystem;

// The per-cable tables of calibrate's and evaluate's consoles share one layout: a label
// column, then T1..T6, so that every row lines up under its header.
constexpr int kLabelWidth = 40;

std::string Digest(const std::string& path) {
  std::string hex, error;
  return !path.empty() && FileSha256(path, &hex, &error) ? hex : "";
}

}  // namespace

// The digests of --data's files, joined by ',' like the names.
std::string DataDigest() {
  std::string digests;
  const std::vector<std::string> paths = DataPaths();
  for (size_t k = 0; k < paths.size(); ++k) digests += (k ? "," : "") + Digest(paths[k]);
  return digests;
}

// --residuals-every must be >= 0 (0: no residuals.csv).
bool CheckResidualsEvery(std::string* error) {
  if (FLAGS_residuals_every >= 0) return true;
  *error = "--residuals-every=" + std::to_string(FLAGS_residuals_every) +
           ": must be 0 (no residuals.csv), 1 (every sample) or more (one sample in K)";
  return false;
}

// CheckOutputDirectory for --out, with --force: `outputs` may be replaced.
bool CheckOutFlag(const std::vector<std::string>& outputs, std::string* error) {
  return CheckOutputDirectory("out", FLAGS_out, error, FLAGS_force ? &outputs : nullptr);
}

std::string CableHeader(const std::string& title, const char* prefix) {
  char buf[160];
  std::string names[kNumCables];
  for (int i = 0; i < kNumCables; ++i) names[i] = prefix + std::to_string(i + 1);
  std::snprintf(buf, sizeof(buf), "  %-*s %8s %8s %8s %8s %8s %8s\n", kLabelWidth, title.c_str(),
                names[0].c_str(), names[1].c_str(), names[2].c_str(), names[3].c_str(),
                names[4].c_str(), names[5].c_str());
  return buf;
}

std::string CableRow(const std::string& label, const std::array<double, kNumCables>& values,
                     double scale) {
  char buf[160];
  std::snprintf(buf, sizeof(buf), "  %-*.*s", kLabelWidth, kLabelWidth, label.c_str());
  std::string row = buf;
  for (double v : values) {
    std::snprintf(buf, sizeof(buf), " %8.3f", v * scale + 0.0);  // + 0.0: no "-0.000"
    row += std::string(buf) == " -0.000" ? "    0.000" : buf;
  }
  return row + "\n";
}

std::string RmsTable(const std::vector<VariantEvaluation>& variants) {
  std::string s = CableHeader("RMS model - measured (kN)");
  for (const VariantEvaluation& v : variants) {
    for (int part = 0; part < 2; ++part) {
      const CableErrorStats& st = part == 0 ? v.fit : v.holdout;
      if (st.samples == 0) continue;
      s += CableRow(v.name + (part == 1 ? " [hold-out]" : ""), st.rms_n, 1.0 / kNPerKn);
    }
  }
  return s;
}

// The paper's published Table 6 under the RMS table when the data fly its measured circle
// (PaperCircleMatcher: by the positions, whoever made the file); "" otherwise.
// With `simulated` data (SimulatedProvenance), the lines say that the comparison is a
// simulation's noise against the telescope's (issue 59).
std::string PaperTable6Lines(const PaperCircleMatcher& positions, bool simulated) {
  if (!positions.Matches()) return "";
  const char* labels[] = {"paper's Table 6: AAS", "paper's Table 6: actual attitudes",
                          "paper's Table 6: + corrected mass centre"};
  std::string s = "  the same circle on the telescope (the paper's published RMS, kN):\n";
  if (simulated) {
    s = "  the same circle on the real telescope (the paper's published RMS, kN); THESE DATA\n"
        "  ARE SIMULATED (fastcal simulate): their RMS is the simulation's noise, not an\n"
        "  improvement over the paper's:\n";
  }
  for (size_t k = 0; k < internal::kPaperTable6.size(); ++k) {
    s += CableRow(labels[k], internal::kPaperTable6[k].rms_kn, 1.0);
  }
  return s;
}

// --data's files: split at ',' (one session each, sessions.h), unless the whole value names
// an existing file.
std::vector<std::string> DataPaths() {
  std::error_code ec;
  if (fs::exists(FLAGS_data, ec)) return {FLAGS_data};
  std::vector<std::string> paths;
  std::string_view rest(FLAGS_data);
  while (true) {
    const size_t comma = rest.find(',');
    paths.emplace_back(rest.substr(0, comma));
    if (comma == std::string_view::npos) return paths;
    rest.remove_prefix(comma + 1);
  }
}

// Issue 59: the data files' provenance when `fastcal simulate` made them (the leading
// comment it writes: "# Simulated by fastcal VERSION", the command, the truth model),
// their lines without "# " joined by '\n' (each prefixed with its file's name when --data
// names several); "" when no file says so. Only the first 8 KiB of each are read (a
// gzipped file decompressed); a file that cannot be read says nothing here (its reader
// says why).
std::string SimulatedProvenance() {
  constexpr char kMark[] = "# Simulated by fastcal";
  const std::vector<std::string> paths = DataPaths();
  std::string out;
  for (const std::string& path : paths) {
    internal::RegularFileReader reader;
    std::string text, error;
    bool end = false;
    if (!reader.Open(path, std::numeric_limits<long long>::max(), "--data", &error) ||
        !reader.Read(8192, &text, &end, &error) || text.rfind(kMark, 0) != 0) {
      continue;
    }
    for (size_t start = 0; start < text.size() && text[start] == '#';) {
      const size_t newline = text.find('\n', start);
      if (newline == std::string::npos) break;  // a line cut by the 8 KiB
      std::string line = text.substr(start, newline - start);
      line.erase(0, line.find_first_not_of("# "));
      if (!line.empty() && line.back() == '\r') line.pop_back();
      out += (out.empty() ? "" : "\n") + (paths.size() > 1 ? path + ": " : "") + line;
      start = newline + 1;
    }
  }
  return out;
}

// --model's model and --data's files (checked: given, no empty name).
bool LoadModelAndDataPaths(CableRobot* robot, std::vector<std::string>* paths, std::string* error) {
  if (!LoadModelFlag("model", FLAGS_model, robot, error)) return false;
  if (FLAGS_data.empty()) {
    *error = "--data=FILE.csv is required";
    return false;
  }
  *paths = DataPaths();
  if (std::find(paths->begin(), paths->end(), "") != paths->end()) {
    *error = "--data=" + internal::Quote(FLAGS_data) +
             " has an empty file name (a stray comma?); several files are FILE.csv,FILE.csv";
    return false;
  }
  return true;
}

// Lists the rows --skip-invalid-rows skipped (malformed, or a pose the model cannot solve)
// on stderr. False, with the message, when no sample is left.
// `samples`: how many are left (data.samples.size() unless streamed).
bool ReportSkipped(const char* command, const Dataset& data, long long samples,
                   std::string* error) {
  if (data.skipped.empty()) return true;
  std::cerr << "fastcal " << command << ": --skip-invalid-rows skipped " << data.skipped.size()
            << (data.skipped.size() == 1 ? " row" : " rows") << " of " << data.path << ", "
            << samples << " left:\n";
  for (const std::string& s : data.skipped) std::cerr << "  " << s << "\n";
  if (samples > 0) return true;
  *error = data.path + ": no sample left: the model cannot solve any valid row";
  return false;
}

bool ReportSkipped(const char* command, const Dataset& data, std::string* error) {
  return ReportSkipped(command, data, static_cast<long long>(data.samples.size()), error);
}

// " (3 rows skipped)" for the summary line; "" when none was.
std::string SkippedNote(const Dataset& data) {
  const size_t n = data.skipped.size();
  return n == 0 ? "" : " (" + std::to_string(n) + (n == 1 ? " row" : " rows") + " skipped)";
}

// What to add to the message of a pose the model cannot solve.
std::string SkipHint() {
  return FLAGS_skip_invalid_rows ? "" : " (--skip-invalid-rows skips such rows, and lists them)";
}

// When `model` cannot solve at least two rows and the nominal FAST model solves most of
// them, the model or spec, not the data, is the likely cause: the message that says so,
// naming the values furthest from nominal; "" otherwise (unsolvable_rows.h).
std::string BlameText(const UnsolvableRows& d, const std::string& model_name) {
  if (!d.model_likely) return "";
  return DescribeUnsolvableRows(d, model_name) +
         (FLAGS_skip_invalid_rows ? " (not skipped: --skip-invalid-rows is for bad rows, and "
                                    "would fit the rest with this model)"
                                  : "");
}

// Which threshold the gross-error screen used, one console line (the report and
// summary.json have the sentence, DescribeGrossErrorThreshold).
std::string ThresholdLine(const std::string& indent, const GrossErrorThreshold& t) {
  char buf[200];
  std::snprintf(buf, sizeof(buf),
                "%sthreshold: %s (floor %.3g, family-wise %.3g for %lld readings)\n",
                indent.c_str(), t.family_wise_decides() ? "family-wise" : "the floor",
                t.floor_sigmas, t.family_wise_sigmas, t.readings);
  return buf;
}

// Where a list cut short on the console is whole: summary.json when the run writes one
// (with --out), else that --out would write it. `key`: the list's key there, or empty.
std::string SummaryPlace(bool summary_written, const std::string& key) {
  return std::string("in summary.json") + (key.empty() ? "" : " (" + key + ")") +
         (summary_written ? "" : " with --out=DIR");
}

// The first few readings of `list`, one line each, then how many more and where they are.
std::string ReadingLines(const std::vector<ReadingResidual>& list, const std::string& indent,
                         bool summary_written) {
  constexpr size_t kShown = 5;
  std::ostringstream s;
  for (size_t k = 0; k < std::min(list.size(), kShown); ++k) {
    const ReadingResidual& e = list[k];
    char buf[200];
    if (e.length) {
      std::snprintf(buf, sizeof(buf),
                    "%sline %d, length of cable %d: measured %.4f m, predicted %.4f m, %+.1f "
                    "sigma%s\n",
                    indent.c_str(), e.line, e.cable, e.measured_m, e.predicted_m, e.residual_sigma,
                    e.held_out ? " (held out)" : "");
    } else {
      std::snprintf(buf, sizeof(buf),
                    "%sline %d, cable %d: measured %.3f kN, predicted %.3f kN, %+.1f sigma%s\n",
                    indent.c_str(), e.line, e.cable, e.measured_n / kNPerKn,
                    e.predicted_n / kNPerKn, e.residual_sigma, e.held_out ? " (held out)" : "");
    }
    s << buf;
  }
  if (list.size() > kShown) {
    s << indent << "... " << list.size() - kShown << " more " << (summary_written ? "" : "listed ")
      << SummaryPlace(summary_written, "outliers") << "\n";
  }
  return s.str();
}

// Writes `files` and the report files into --out as one directory (built as a hidden
// sibling and renamed into place). False, with the error printed, on failure.
// `more` (may be null) writes further files into the directory being built.
// `more` writes further files into the directory; with `more_beside_report` it runs on
// its own thread while the report is rendered (both only read their inputs: calibrate's
// residuals.csv, ~1 s each at 10^6 samples).
bool WriteOutDirectory(const char* command,
                       const std::vector<std::pair<std::string, std::string>>& files,
                       const ReportInputs& report, const std::vector<std::string>& outputs,
                       const std::function<bool(const std::string&, std::string*)>& more,
                       bool more_beside_report) {
  std::string error;
  const auto write = [&](const std::string& dir, std::string* why) {
    if (!more) return WriteReportFiles(dir, report, why);
    if (!more_beside_report) return WriteReportFiles(dir, report, why) && more(dir, why);
    std::string more_why;
    std::future<bool> extra = AsyncOrDeferred([&] { return more(dir, &more_why); });
    const bool reported = WriteReportFiles(dir, report, why);
    const bool extra_written = extra.get();
    if (reported && !extra_written) *why = more_why;
    return reported && extra_written;
  };
  if (WriteDirectoryAtomically(FLAGS_out, files, write, FLAGS_force ? &outputs : nullptr, &error)) {
    return true;
  }
  PrintError(command, error);
  return false;
}

// A dataset beside `data_path` to check a calibrated model on: the first other .csv file
// of its directory (by name) whose header is a dataset's; "" when there is none.
std::string OtherDataset(const std::string& data_path) {
  std::error_code ec;
  const fs::path data = fs::path(data_path);
  const fs::path dir = data.has_parent_path() ? data.parent_path() : fs::path(".");
  std::vector<fs::path> candidates;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.path().extension() == ".csv" && entry.is_regular_file(ec) &&
        !fs::equivalent(entry.path(), data, ec)) {
      candidates.push_back(entry.path());
    }
  }
  std::sort(candidates.begin(), candidates.end());
  for (const fs::path& candidate : candidates) {
    std::ifstream in(candidate);
    std::string line;
    while (std::getline(in, line) && (line.empty() || line[0] == '#')) {
    }
    if (line.find("T1_kN") != std::string::npos && line.find("x_m") != std::string::npos) {
      return (data.has_parent_path() ? dir / candidate.filename() : candidate.filename()).string();
    }
  }
  return "";
}

// The report's provenance, common to calibrate and evaluate: the input files (the spec's
// only when there is one), their digests, the software, the command line and the time.
ReportInputs ReportProvenance(int argc, char** argv, bool with_spec,
                              const std::string* data_digest) {
  ReportInputs report;
  report.model_path = FLAGS_model;
  report.data_path = FLAGS_data;
  report.model_digest = Digest(FLAGS_model);
  report.columns_path = FLAGS_columns;
  report.columns_digest = ColumnsDigest();
  report.data_digest = data_digest != nullptr ? *data_digest : DataDigest();
  if (with_spec) {
    report.spec_path = FLAGS_spec;
    report.spec_digest = Digest(FLAGS_spec);
  }
  report.software_version = FASTCAL_VERSION;
  report.command_line = CommandLine(argc, argv);
  report.run_utc = UtcNow();
  report.simulated_provenance = SimulatedProvenance();
  return report;
}

}  // namespace fastcal::cli
