// The columns of the measurement dataset CSV (docs/data-format.md), shared by its reader
// (dataset.cc) and writer (dataset_write.cc): their identifiers in the order WriteDataset
// writes them, their names, and the plausibility check of one value as read.
#ifndef FASTCAL_DATA_DATASET_COLUMNS_H_
#define FASTCAL_DATA_DATASET_COLUMNS_H_

#include <exception>
#include <new>
#include <string>
#include <string_view>

#include "fastcal/cable_robot.h"
#include "fastcal/internal/dataset_column_names.h"
#include "fastcal/internal/quote.h"
#include "fastcal/plausibility.h"

namespace fastcal::internal::dataset_columns {

enum Column : int {
  kTime,
  kX,
  kY,
  kZ,
  kRoll,
  kPitch,
  kYaw,
  kQw,
  kQx,
  kQy,
  kQz,
  kPlannedRoll,
  kPlannedPitch,
  kPlannedYaw,
  kTension1,
  kUnstretched1 = kTension1 + kNumCables,
  kNumColumns = kUnstretched1 + kNumCables,
};

// Their names, in the order above (internal/dataset_column_names.h holds the list).
inline constexpr auto& kColumnNames = kDatasetColumnNames;
static_assert(sizeof(kDatasetColumnNames) / sizeof(kDatasetColumnNames[0]) == kNumColumns,
              "one name per column");

// The optional label column (docs/data-format.md, "Sessions").
inline constexpr auto& kSessionColumn = kSessionColumnName;

// Files hold tensions in kN, memory in N: the decimal exponent shifts by this much.
inline constexpr int kKilo = 3;

inline bool IsTension(int column) { return column >= kTension1 && column < kTension1 + kNumCables; }
inline bool IsUnstretched(int column) {
  return column >= kUnstretched1 && column < kUnstretched1 + kNumCables;
}
inline bool IsAngle(int column) {
  return (column >= kRoll && column <= kYaw) || (column >= kPlannedRoll && column <= kPlannedYaw);
}

// User text in messages is escaped and capped (a binary file's header, a 10 MB line);
// the names of our own columns are quoted the same way.
inline std::string Quoted(std::string_view s) { return Quote(s); }

// `body` (returning bool, its message in *message) with an exception it throws made the
// message "NAME: what()": a library error (yaml-cpp's, a bad conversion) is the file's.
// Out of memory is the machine's, not the file's: rethrown (the caller says "out of
// memory", exit 1). *error (may be null) gets the message on failure.
template <typename Body>
bool FileErrors(const std::string& name, std::string* error, const Body& body) {
  std::string message;
  bool ok = false;
  try {
    ok = body(&message);
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    message = name + ": " + e.what();
    ok = false;
  }
  if (!ok && error != nullptr) *error = message;
  return ok;
}

// Checks a value as read (kN for a tension) against the plausibility limits; false with
// *why otherwise.
bool CheckValue(int column, double value, const PlausibilityLimits& limits, std::string* why);

}  // namespace fastcal::internal::dataset_columns

#endif  // FASTCAL_DATA_DATASET_COLUMNS_H_
