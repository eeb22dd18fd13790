// Tests of the vibration record reader (vibration_record.h): a dataset's rows into the
// record's channels and mean pose, times that step evenly, a step that does not named at
// its own line (issue 57: a clock jump at line 2004 was blamed on line 3).
#include "fastcal/vibration_record.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

namespace fastcal {
namespace {

constexpr char kHeader[] =
    "time_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,T1_kN,T2_kN,T3_kN,T4_kN,T5_kN,T6_kN\n";

// `rows` rows every `step_s`, the row numbered `jump_row` (0-based) and later `jump_s`
// later; the cabin at (k mm, 0, 140) m.
std::string Record(int rows, double step_s, int jump_row = -1, double jump_s = 0.0) {
  std::ostringstream csv;
  csv.precision(17);
  csv << kHeader;
  for (int k = 0; k < rows; ++k) {
    const double t = k * step_s + (jump_row >= 0 && k >= jump_row ? jump_s : 0.0);
    csv << t << "," << 1e-3 * k << ",0,140,0,0,0.5,160,161,162,163,164,165\n";
  }
  return csv.str();
}

TEST(VibrationRecordTest, ReadsTheChannelsAndTheMeanPose) {
  VibrationRecordFile file;
  std::string error;
  ASSERT_TRUE(ParseVibrationRecord(Record(101, 0.1), "r.csv", DatasetReadOptions(), &file, &error))
      << error;
  EXPECT_EQ(file.path, "r.csv");
  ASSERT_EQ(file.record.channels.rows(), 12);
  ASSERT_EQ(file.record.channels.cols(), 101);
  EXPECT_NEAR(file.record.sample_interval_s, 0.1, 1e-15);
  EXPECT_DOUBLE_EQ(file.record.channels(0, 100), 0.1);
  EXPECT_NEAR(file.record.channels(5, 7), 0.5, 1e-12);  // yaw, deg
  EXPECT_DOUBLE_EQ(file.record.channels(8, 3), 162.0);  // T3, kN
  EXPECT_NEAR(file.mean_pose.position_m.x(), 0.05, 1e-12);
  EXPECT_NEAR(RpyDegFromRotation(file.mean_pose.rotation).z(), 0.5, 1e-12);
}

TEST(VibrationRecordTest, AStepThatIsNotTheRecordsIsNamedAtItsLine) {
  VibrationRecordFile file;
  std::string error;
  // Row 2002 is line 2004 (the header is line 1); its step is the jump's.
  EXPECT_FALSE(ParseVibrationRecord(Record(4001, 0.1, 2002, 3600.0), "r.csv", DatasetReadOptions(),
                                    &file, &error));
  EXPECT_EQ(error.rfind("r.csv:2004: time_s steps by 3600.1 s where the record steps by 0.1 s", 0),
            0u)
      << error;
  // The first step odd: blamed on line 3, where it is.
  EXPECT_FALSE(ParseVibrationRecord(Record(100, 0.1, 1, 0.05), "r.csv", DatasetReadOptions(), &file,
                                    &error));
  EXPECT_EQ(error.rfind("r.csv:3: time_s steps by 0.15 s", 0), 0u) << error;
  EXPECT_FALSE(ParseVibrationRecord(Record(100, 0.1, 50, -1.0), "r.csv", DatasetReadOptions(),
                                    &file, &error));
  EXPECT_NE(error.find("r.csv:52: time_s 4 s does not increase (line 51: 4.9 s)"),
            std::string::npos)
      << error;
  EXPECT_FALSE(ParseVibrationRecord(Record(1, 0.1), "r.csv", DatasetReadOptions(), &file, &error));
  EXPECT_NE(error.find("a record needs many samples, it has 1"), std::string::npos) << error;
}

// Issue 59: a survey day (poses tens of metres apart) is not a vibration about one pose;
// refused at the line furthest from the mean, with the spread and the bound. A cabin that
// stays within kMaxPoseSpreadM of its mean is read.
TEST(VibrationRecordTest, ARecordThatIsNotAboutOnePoseIsRefused) {
  VibrationRecordFile file;
  std::string error;
  std::string csv = kHeader;
  for (int k = 0; k < 100; ++k) {
    csv += std::to_string(0.1 * k) + "," + (k == 60 ? "30" : "0") +
           ",0,140,0,0,0,160,161,162,163,164,165\n";
  }
  EXPECT_FALSE(ParseVibrationRecord(csv, "day.csv", DatasetReadOptions(), &file, &error));
  EXPECT_EQ(error.rfind("day.csv:62: the cabin is 29.7 m from the record's mean position (0.3, "
                        "0, 140) m, beyond the 2 m a vibration about one pose may spread",
                        0),
            0u)
      << error;
  // 0 to 3.9 m along x: 1.95 m from the mean at most, within the bound.
  EXPECT_TRUE(ParseVibrationRecord(Record(3901, 0.1), "r.csv", DatasetReadOptions(), &file, &error))
      << error;
}

}  // namespace
}  // namespace fastcal
