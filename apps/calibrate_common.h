// What `fastcal calibrate` and `fastcal evaluate` share (issue 54: each command in its own
// file): their inputs (the model and the data's paths), the console's per-cable tables and
// gross-error lines, residuals.csv's rows, the skipped rows, and the output directory with
// the report (written by the report layer, put in place as every command's results are).
#ifndef FASTCAL_APPS_CALIBRATE_COMMON_H_
#define FASTCAL_APPS_CALIBRATE_COMMON_H_

#include <array>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"
#include "fastcal/evaluation_screen.h"
#include "fastcal/internal/paper_reference.h"
#include "fastcal/report.h"
#include "fastcal/residuals_csv.h"
#include "fastcal/trajectory.h"
#include "fastcal/unsolvable_rows.h"

namespace fastcal::cli {

// Threads that read a dataset (calibrate, evaluate).
inline constexpr int kReadThreads = 2;

bool CheckResidualsEvery(std::string* error);
bool CheckOutFlag(const std::vector<std::string>& outputs, std::string* error);
std::string CableHeader(const std::string& title, const char* prefix = "T");
std::string CableRow(const std::string& label, const std::array<double, kNumCables>& values,
                     double scale);
std::string RmsTable(const std::vector<VariantEvaluation>& variants);
std::string PaperTable6Lines(const PaperCircleMatcher& positions, bool simulated);
std::vector<std::string> DataPaths();
// The digests of --data's files, joined by ',' like the names.
std::string DataDigest();
std::string SimulatedProvenance();
bool LoadModelAndDataPaths(CableRobot* robot, std::vector<std::string>* paths, std::string* error);
bool ReportSkipped(const char* command, const Dataset& data, long long samples, std::string* error);
bool ReportSkipped(const char* command, const Dataset& data, std::string* error);
std::string SkippedNote(const Dataset& data);
std::string SkipHint();
std::string BlameText(const UnsolvableRows& d, const std::string& model_name);
std::string ThresholdLine(const std::string& indent, const GrossErrorThreshold& t);
std::string SummaryPlace(bool summary_written, const std::string& key = "");
std::string ReadingLines(const std::vector<ReadingResidual>& list, const std::string& indent,
                         bool summary_written = true);
bool WriteOutDirectory(const char* command,
                       const std::vector<std::pair<std::string, std::string>>& files,
                       const ReportInputs& report, const std::vector<std::string>& outputs,
                       const std::function<bool(const std::string&, std::string*)>& more = nullptr,
                       bool more_beside_report = false);
std::string OtherDataset(const std::string& data_path);
ReportInputs ReportProvenance(int argc, char** argv, bool with_spec,
                              const std::string* data_digest);

}  // namespace fastcal::cli

#endif  // FASTCAL_APPS_CALIBRATE_COMMON_H_
