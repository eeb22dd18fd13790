// The canonical dataset's column names (docs/data-format.md), in the order WriteDataset
// writes them, and the session label's. Held here, below the model, so that the model's
// moving parts can refuse a joint column named as one of them (issue 57: a joint with
// `column: x_m` made simulate write x_m twice, and every reader then refused the file);
// the dataset's reader and writer (lib/src/data/dataset_columns.h) use the same list.
#ifndef FASTCAL_INTERNAL_DATASET_COLUMN_NAMES_H_
#define FASTCAL_INTERNAL_DATASET_COLUMN_NAMES_H_

#include <string_view>

namespace fastcal::internal {

// clang-format off
inline constexpr const char* kDatasetColumnNames[] = {
    "time_s", "x_m", "y_m", "z_m",
    "roll_deg", "pitch_deg", "yaw_deg",
    "qw", "qx", "qy", "qz",
    "planned_roll_deg", "planned_pitch_deg", "planned_yaw_deg",
    "T1_kN", "T2_kN", "T3_kN", "T4_kN", "T5_kN", "T6_kN",
    "s0_1_m", "s0_2_m", "s0_3_m", "s0_4_m", "s0_5_m", "s0_6_m"};
// clang-format on

// The optional label column (docs/data-format.md, "Sessions").
inline constexpr char kSessionColumnName[] = "session";

// Whether `name` is a column of the canonical dataset (or its session label): no other
// column, a joint's included, may take it.
inline bool IsDatasetColumnName(std::string_view name) {
  if (name == kSessionColumnName) return true;
  for (const char* column : kDatasetColumnNames) {
    if (name == column) return true;
  }
  return false;
}

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_DATASET_COLUMN_NAMES_H_
