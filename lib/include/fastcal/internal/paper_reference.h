// Published reference values of the paper (docs/model.md, "Measured data"), shown beside
// the tool's own numbers where the data are the paper's case: its Table 6, the RMS of
// model minus measured lower-end tension per cable on the measured circle (radius 71.11 m
// about (0, 0, 156.73) m, PaperCircleArc), real FAST telemetry, AAS statics.
#ifndef FASTCAL_INTERNAL_PAPER_REFERENCE_H_
#define FASTCAL_INTERNAL_PAPER_REFERENCE_H_

#include <array>

#include "fastcal/cable_robot.h"

namespace fastcal::internal {

struct PaperRmsRow {
  const char* label;           // the paper's row
  const char* corresponds_to;  // the variant of a fastcal report it compares with
  std::array<double, kNumCables> rms_kn;
};

inline constexpr std::array<PaperRmsRow, 3> kPaperTable6 = {{
    {"AAS", "initial model, planned attitude", {22.554, 17.517, 20.078, 18.687, 17.167, 18.190}},
    {"AAS with actual attitudes",
     "initial model, measured attitude",
     {23.942, 14.226, 19.531, 14.210, 17.534, 16.058}},
    {"AAS with actual attitudes and corrected coordinates",
     "calibrated model, measured attitude",
     {20.060, 12.683, 16.422, 10.018, 16.457, 12.053}},
}};

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_PAPER_REFERENCE_H_
