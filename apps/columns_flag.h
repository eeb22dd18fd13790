// --columns=MAP.yaml, read by every command that reads telemetry (calibrate, evaluate,
// import, solve --poses, simulate --poses), and --sessions-at (calibrate, import).
#ifndef FASTCAL_APPS_COLUMNS_FLAG_H_
#define FASTCAL_APPS_COLUMNS_FLAG_H_

#include <memory>
#include <string>
#include <vector>

#include "fastcal/column_map.h"
#include "fastcal/dataset.h"

namespace fastcal::cli {

// The column map of --columns (LoadColumnMap), null when the flag is not given; false
// with the map's message (file, line, key) otherwise.
bool ColumnsFromFlag(std::shared_ptr<const ColumnMap>* map, std::string* error);

// --columns's digest for the report's provenance ("" without the flag).
std::string ColumnsDigest();

// The times of --sessions-at: TIME[,TIME...] (each a number in the data's time_s, or an
// ISO 8601 date and time, in the data's zone when it names none), or a previous
// calibrate's summary.json (the changes its scan found). Empty without the flag.
bool SessionCutsFromFlag(const Dataset& layout, std::vector<double>* cuts_s, std::string* error);

// Help text of the two flags, for the commands' --help.
extern const char kColumnsFlagHelp[];
extern const char kSessionsAtFlagHelp[];

}  // namespace fastcal::cli

#endif  // FASTCAL_APPS_COLUMNS_FLAG_H_
