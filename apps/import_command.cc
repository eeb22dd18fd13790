// `fastcal import`: a telemetry export read through a column map, written as the canonical
// dataset CSV (docs/data-format.md), with its provenance, so that it is converted once.
#include <gflags/gflags.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <limits>
#include <sstream>

#include "cli_util.h"
#include "columns_flag.h"
#include "commands.h"
#include "common_flags.h"
#include "fastcal/dataset.h"
#include "fastcal/file_digest.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/quote.h"
#include "fastcal/sessions.h"
#include "fastcal/tension_scale.h"
#include "fastcal/time_text.h"
#include "fastcal/version.h"

namespace fastcal::cli {
namespace {

namespace fs = std::filesystem;

const char kCommand[] = "import";

std::string Help() {
  return std::string(
             R"(fastcal import: read a telemetry export through a column map, write the canonical dataset.

Usage:
  fastcal import --columns=MAP.yaml --data=EXPORT.csv --out=DATA.csv [--force]
                 [--sessions-at=TIME,...] [--skip-invalid-rows]

)") + kColumnsFlagHelp +
         R"(
  --data=FILE         the export (CSV or TSV text; an .xlsx is read by Python's
                      fastcal.read_dataset, or converted first by xlsx2csv)
  --out=FILE          the canonical dataset (docs/data-format.md): time_s (Unix seconds,
                      UTC, for absolute time stamps), x_m..z_m, the attitude, T1_kN..T6_kN
                      and the optional columns the map gives; written atomically (nothing
                      is left on failure); an existing file is kept unless --force
  --force             replace an existing --out
)" + kSessionsAtFlagHelp +
         R"(
  --skip-invalid-rows leave out rows with a bad value (each listed on stderr) instead of
                      failing

The output opens with its provenance as '#' comments: the export and its SHA-256, the
column map and its SHA-256 and text, the command line, fastcal's version and the time.
Every value is converted once (units to m, deg, kN; time stamps to seconds), checked as
the readers check the canonical file, and written with the fewest digits that read back
to the same number: calibrating the import gives what calibrating the export through
the map gives.

Streams: the summary (samples, time range) on stdout; skipped rows on stderr.
Exit codes: 0 written, 2 bad input (the map, the export, the flags).

Example (the bundled FAST-style export):
  fastcal import --columns=calibration_data/fast_export.columns.yaml \
    --data=calibration_data/fast_export.csv --out=out/fast_survey.csv
)";
}

std::string Provenance(int argc, char** argv, const ColumnMap& map) {
  std::string data_digest, map_digest, ignored;
  FileSha256(FLAGS_data, &data_digest, &ignored);
  FileSha256(FLAGS_columns, &map_digest, &ignored);
  std::ostringstream s;
  s << "imported by fastcal " << FASTCAL_VERSION << " on " << UtcNow() << "\n"
    << CommandLine(argc, argv, {"force"}) << "\n"
    << "export " << FLAGS_data << " (sha256 " << data_digest << ")\n"
    << "column map " << FLAGS_columns << " (sha256 " << map_digest << "):\n";
  std::istringstream lines(map.text);
  std::string line;
  while (std::getline(lines, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    s << "  | " << line << "\n";
  }
  s << "time_s: "
    << (map.time.format == TimeFormat::kSeconds
            ? "as the export gives it (seconds)"
            : "Unix seconds (UTC) of the export's " +
                  TimeFormatName(map.time.format, map.time.pattern) + " time stamps");
  return s.str();
}

int Fail(const std::string& message, const std::string& temporary = "") {
  if (!temporary.empty()) {
    std::error_code ec;
    fs::remove(temporary, ec);
  }
  PrintError(kCommand, message);
  return kExitUsage;
}

}  // namespace

int RunImport(int argc, char** argv) {
  int exit_code = 0;
  const std::string help = Help();
  if (!StartCommand(argc, argv, kCommand, help.c_str(),
                    {"columns", "data", "out", "force", "sessions-at", "skip-invalid-rows"},
                    &exit_code)) {
    return exit_code;
  }
  if (FLAGS_columns.empty() || FLAGS_data.empty() || FLAGS_out.empty() || FLAGS_out == "-") {
    return Fail(
        "--columns=MAP.yaml, --data=EXPORT and --out=FILE.csv are required (see "
        "fastcal import --help)");
  }
  std::string error;
  std::shared_ptr<const ColumnMap> map;
  if (!CheckCanWrite("out", FLAGS_out, FLAGS_force, &error) || !ColumnsFromFlag(&map, &error)) {
    return Fail(error);
  }
  std::error_code ec;
  if (fs::exists(FLAGS_out, ec) && fs::exists(FLAGS_data, ec) &&
      fs::equivalent(FLAGS_out, FLAGS_data, ec)) {
    return Fail("--out names the export itself: give another file");
  }
  DatasetReadOptions read;
  read.columns = map;
  read.joint_columns = JointColumnsOf(*map);  // the moving parts' joints, carried through
  read.skip_invalid_rows = FLAGS_skip_invalid_rows;
  read.threads = 2;
  DatasetChunkReader reader;
  if (!reader.Open(FLAGS_data, read, &error)) return Fail(error);

  constexpr size_t kChunk = 8192;
  Dataset chunk;
  bool done = false;
  if (!reader.Next(kChunk, &chunk, &done, &error)) return Fail(error);
  // The tensions' unit, on the first chunk (a slip is in every row): here, where the map's
  // units are known, not in calibrate, which can only refuse the imported file (issue 57).
  chunk.path = FLAGS_data;
  if (!CheckTensionScaleOfAnyCabin(chunk, &error)) return Fail(error);
  std::vector<double> cuts;
  if (!SessionCutsFromFlag(chunk, &cuts, &error)) return Fail(error);
  const bool cut = !cuts.empty();
  if (cut && !chunk.session_labels.empty()) {
    return Fail("--sessions-at: the export has a session column already (mapped by " +
                FLAGS_columns + "): cutting at times is for one survey");
  }
  Dataset layout = chunk;
  layout.samples.clear();
  if (cut) {
    layout.session_labels.clear();
    for (size_t k = 0; k <= cuts.size(); ++k) {
      layout.session_labels.push_back(SessionCutLabel(static_cast<int>(k)));
    }
  }
  // The library's temporary name beside --out: unlinked by the SIGINT/SIGTERM handler, and
  // removed by the next run once this process is gone (a SIGKILL's leftover); locked, so
  // that a reused pid cannot make a live run's temporary look stale (issue 37).
  const std::string temporary = internal::TemporaryNameFor(FLAGS_out);
  DatasetWriter writer;
  if (!writer.Open(temporary, layout, Provenance(argc, argv, *map), &error)) {
    return Fail(error, temporary);
  }
  internal::TemporaryLock lock;
  lock.Lock(temporary);
  long long samples = 0;
  std::vector<long long> per_session(cuts.size() + 1, 0);
  double first = std::numeric_limits<double>::infinity(), last = -first;
  std::vector<std::string> skipped;
  while (true) {
    if (!cut && !chunk.session_labels.empty()) writer.UpdateSessionLabels(chunk.session_labels);
    for (Sample& s : chunk.samples) {
      if (cut) {
        s.session = SessionOfTime(cuts, s.time_s);
        ++per_session[s.session];
      }
      first = std::min(first, s.time_s);
      last = std::max(last, s.time_s);
      if (!writer.Write(s, &error)) return Fail(error, temporary);
      ++samples;
    }
    for (const std::string& why : chunk.skipped) std::cerr << "  skipped " << why << "\n";
    skipped.insert(skipped.end(), chunk.skipped.begin(), chunk.skipped.end());
    if (done) break;
    if (!reader.Next(kChunk, &chunk, &done, &error)) return Fail(error, temporary);
  }
  for (size_t k = 0; cut && k < per_session.size(); ++k) {
    if (per_session[k] > 0) continue;
    return Fail("--sessions-at: session " + SessionCutLabel(static_cast<int>(k)) +
                    " has no sample: cut within the survey",
                temporary);
  }
  if (!writer.Close(&error)) return Fail(error, temporary);
  // Without --force, a file that appeared at --out while this ran (another import) is kept
  // and this run fails, rather than both saying "wrote" and one result lost.
  if (FLAGS_force) {
    fs::rename(temporary, FLAGS_out, ec);
    if (ec) return Fail(FLAGS_out + ": cannot write: " + ec.message(), temporary);
  } else if (int err = 0; !internal::RenameNoReplace(temporary, FLAGS_out, &err)) {
    return Fail(FLAGS_out + (err == EEXIST ? ": written by another run meanwhile; kept (--force "
                                             "replaces it)"
                                           : ": cannot write: " + std::string(std::strerror(err))),
                temporary);
  }

  const TimeDisplay display = TimeDisplayFor(first, chunk.time_offset_s);
  std::cout << "fastcal import: " << samples << (samples == 1 ? " sample" : " samples") << " from "
            << internal::Escape(FLAGS_data) << " through " << internal::Escape(FLAGS_columns)
            << (skipped.empty() ? "" : " (" + std::to_string(skipped.size()) + " rows skipped)")
            << "\n  " << TimeRangeText(first, last, display)
            << (display.absolute ? " (time_s: Unix seconds, UTC)" : "") << "\n";
  if (cut) {
    std::cout << "  sessions:";
    for (size_t k = 0; k < per_session.size(); ++k) {
      std::cout << " " << SessionCutLabel(static_cast<int>(k)) << " (" << per_session[k] << ")";
    }
    std::cout << "\n";
  }
  std::cout << "wrote " << FLAGS_out << "\n";
  return 0;
}

}  // namespace fastcal::cli
