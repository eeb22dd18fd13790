// fastcal evaluate: model-minus-measured tension statistics per cable, streamed
// (evaluation_stream.h), with the report (calibrate_common.h for what it shares with
// calibrate).
#include <gflags/gflags.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "calibrate_common.h"
#include "cli_util.h"
#include "columns_flag.h"
#include "commands.h"
#include "common_flags.h"
#include "fastcal/cable_robot.h"
#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"
#include "fastcal/evaluation_screen.h"
#include "fastcal/evaluation_stream.h"
#include "fastcal/internal/quote.h"
#include "fastcal/internal/units.h"
#include "fastcal/report.h"
#include "fastcal/statics.h"
#include "fastcal/trajectory.h"

namespace fastcal::cli {
namespace {

const char kEvaluateHelp[] = R"(fastcal evaluate: model-minus-measured tension statistics per cable.

Usage:
  fastcal evaluate --data=DATA.csv [--model=MODEL.yaml] [--out=DIR] [--method=exact]

  --model=FILE   model to evaluate (e.g. DIR/model_calibrated.yaml from calibrate);
                 default the nominal FAST model
  --data=FILE    telemetry export (docs/data-format.md); several, comma-separated, are
                 read together (one session each)
  --columns=MAP.yaml  read --data as exported, through a column map (docs/data-format.md,
                 "Column maps")
  --method=M     statics method: exact (default), aas-refined, aas
  --out=DIR      also write report.html, report.md, summary.json and residuals.csv
  --force        let --out be a previous evaluate's results, replaced when complete
  --residuals-every=K   residuals.csv keeps one sample in K (1: all, the default; 0: none)
  --skip-invalid-rows   skip rows that are malformed or whose pose the model cannot solve
                 (with --method, at each attitude) instead of failing; each is listed
                 with its line on stderr and, with --out, in the report and summary.json

Prints RMS, mean and max |model - measured| per cable in kN and percent, with the measured
attitude and, when the data has it, the planned attitude. Gross errors are screened as calibrate
screens them (against the measured attitude's predictions, with the default noise model
of 3 % of the reading and a threshold that grows with the number of readings), named by
line and cable, and each row of the RMS table is repeated without them. The model's sensor gain and
bias (if any) are applied: predicted reading = gain * tension + bias.

The data is read in chunks, so memory does not grow with it (about 20 MB at 10^6 samples);
each sample is kept meanwhile in an unnamed temporary file in $TMPDIR, else /tmp (about 200
bytes a sample); a full disk there is exit 1, naming the directory.
)";

const std::vector<std::string> kEvaluateOutputs = {"report.html", "report.md", "summary.json",
                                                   "residuals.csv"};

// evaluate's gross errors: how many, the threshold and why, the first few by line and cable.
std::string EvaluationGrossErrorLines(const EvaluationScreen& screen) {
  std::ostringstream s;
  const long long count = screen.count;
  s << "gross errors (against \"" << screen.variant << "\"): " << count
    << (count == 1 ? " reading" : " readings")
    << (count > 0 ? ", left out of the rows \"... - gross errors\"" : "") << "\n"
    << ThresholdLine("  ", screen.threshold);
  const bool summary_written = !FLAGS_out.empty();
  s << ReadingLines(screen.gross_errors, "  ", summary_written);
  if (count > static_cast<long long>(screen.gross_errors.size())) {
    s << "  (" << screen.gross_errors.size() << " of the " << count << " named "
      << SummaryPlace(summary_written) << ": the first in file order)\n";
  }
  return s.str();
}

// evaluate's console: the RMS table, then per variant the RMS (%), mean and largest
// error (kN) per cable, then the gross errors.
std::string EvaluationConsole(const Dataset& data, long long samples, StaticsMethod method,
                              const std::vector<VariantEvaluation>& variants,
                              const EvaluationScreen& screen, const PaperCircleMatcher& positions) {
  std::ostringstream s;
  s << "fastcal evaluate: " << samples << " samples";
  s << SkippedNote(data);
  s << ", model " << internal::Escape(ModelName(FLAGS_model)) << ", method "
    << StaticsMethodName(method) << "\n\n"
    << RmsTable(variants) << PaperTable6Lines(positions, !SimulatedProvenance().empty());
  for (const VariantEvaluation& v : variants) {
    s << "\n" << CableHeader(v.name + ":");
    s << CableRow("  RMS (%)", v.fit.rms_percent, 1.0);
    s << CableRow("  mean (kN)", v.fit.mean_n, 1.0 / kNPerKn);
    s << CableRow("  max |error| (kN)", v.fit.max_abs_n, 1.0 / kNPerKn);
  }
  s << "\n" << EvaluationGrossErrorLines(screen);
  if (!FLAGS_out.empty())
    s << "\nwrote " << FLAGS_out << "/{report.html, report.md, summary.json"
      << (FLAGS_residuals_every > 0 ? ", residuals.csv" : "") << "}\n";
  return s.str();
}

// evaluate: the data read, predicted and screened a chunk at a time (evaluation_stream.h),
// so that memory does not grow with the number of samples.
int RunEvaluateStreamed(int argc, char** argv, const CableRobot& model,
                        const std::vector<std::string>& paths, StaticsMethod method) {
  const char* command = "evaluate";
  std::string error;
  EvaluationStreamOptions options;
  options.method = method;
  options.read.skip_invalid_rows = FLAGS_skip_invalid_rows;
  options.read.threads = kReadThreads;
  SetJointColumns(model.moving_parts, &options.read);
  if (!ColumnsFromFlag(&options.read.columns, &error)) {
    PrintError(command, error);
    return kExitUsage;
  }
  StreamedEvaluation evaluation;
  const EvaluationStreamStatus status = evaluation.Run(model, paths, options, &error);
  if (status == EvaluationStreamStatus::kInvalidInput ||
      status == EvaluationStreamStatus::kSystemError) {
    PrintError(command, error);
    // A full disk is a failure of the machine, not bad input.
    return status == EvaluationStreamStatus::kSystemError ? kExitFailure : kExitUsage;
  }
  if (const std::string blame = BlameText(evaluation.diagnosis(), "the model"); !blame.empty()) {
    PrintError(command, blame);
    return kExitFailure;
  }
  if (status == EvaluationStreamStatus::kUnsolvable) {
    PrintError(command, error + SkipHint());
    return kExitFailure;
  }
  const Dataset& data = evaluation.layout();
  if (!ReportSkipped(command, data, evaluation.samples(), &error)) {
    PrintError(command, error);
    return kExitFailure;
  }
  if (!FLAGS_out.empty()) {
    ReportInputs report = ReportProvenance(argc, argv, /*with_spec=*/false, nullptr);
    report.initial_model = &model;
    report.data = &data;
    report.variants = evaluation.variants();
    report.evaluation_method = StaticsMethodName(method);
    report.evaluation_screen = &evaluation.screen();
    const ReportSampleStream samples = ReportSamplesOf(evaluation);
    report.sample_stream = &samples;
    const auto residuals = [&evaluation](const std::string& dir, std::string* why) {
      return FLAGS_residuals_every <= 0 ||
             WriteStreamedResiduals(dir, evaluation, FLAGS_residuals_every, why);
    };
    // The output was checked before the work: a failure now is the machine's (a full
    // disk), not the input's.
    if (!WriteOutDirectory(command, {}, report, kEvaluateOutputs, residuals)) return kExitFailure;
  }
  PaperCircleMatcher positions;
  if (!evaluation.ForEach([&positions](const EvaluatedSample& s) { positions.Add(s.position_m); },
                          &error)) {
    PrintError(command, error);
    return kExitFailure;
  }
  std::cout << EvaluationConsole(data, evaluation.samples(), method, evaluation.variants(),
                                 evaluation.screen(), positions);
  return 0;
}

}  // namespace

int RunEvaluate(int argc, char** argv) {
  const char* command = "evaluate";
  int exit_code = 0;
  if (!StartCommand(argc, argv, command, kEvaluateHelp,
                    {"model", "data", "out", "method", "skip-invalid-rows", "force",
                     "residuals-every", "columns"},
                    &exit_code)) {
    return exit_code;
  }
  std::string error;
  StaticsMethod method = StaticsMethod::kExact;
  if (FlagGiven("method") && !ParseStaticsMethod(FLAGS_method, &method)) {
    PrintError(command,
               "--method must be aas, aas-refined or exact, got " + internal::Quote(FLAGS_method));
    return kExitUsage;
  }
  CableRobot model;
  std::vector<std::string> paths;
  if (!CheckResidualsEvery(&error) ||
      (!FLAGS_out.empty() && !CheckOutFlag(kEvaluateOutputs, &error)) ||
      !LoadModelAndDataPaths(&model, &paths, &error)) {
    PrintError(command, error);
    return kExitUsage;
  }
  return RunEvaluateStreamed(argc, argv, model, paths, method);
}

}  // namespace fastcal::cli
