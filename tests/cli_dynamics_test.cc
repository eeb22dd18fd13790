// End-to-end tests of `fastcal dynamics` (apps/dynamics_command.cc): a move's record and
// summary JSON written together, --force; a winch table; bad input named by its flag,
// file and line with exit 2, a pose the statics cannot hold with exit 1, and no output
// left by a failed run.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "cli_fixture.h"
#include "fastcal/statics.h"

namespace fastcal::test {
namespace {

// A 5 m move in 20 s at 16 segments, held 20 s, at 5 Hz: 201 rows of 32 columns, the
// quasi-static columns beside the dynamic ones, the summary JSON with the departures.
TEST_F(CliTest, DynamicsMoveWritesRecordAndSummary) {
  CommandResult r = Fastcal("dynamics --help");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.output.find("--initial-offset"), std::string::npos);
  const std::string csv = Path("move.csv"), json = Path("move.json");
  const std::string args =
      "dynamics --position=0,0,140 --to=5,0,140 --move-s=20 --hold-s=20 --rate-hz=5 "
      "--segments=16 --output=" +
      csv + " --summary=" + json;
  r = Fastcal(args);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("dynamic - quasi-static: tensions peak"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("settle"), std::string::npos) << r.output;
  std::istringstream lines(ReadFile(csv));
  std::string line;
  std::getline(lines, line);
  const std::vector<std::string> header = CsvFields(line);
  ASSERT_EQ(header.size(), 32u) << line;
  EXPECT_EQ(header[7], "T1_kN");
  EXPECT_EQ(header[19], "T1_qs_kN");
  EXPECT_EQ(header[13], "x_qs_m");
  int rows = 0;
  std::vector<std::string> last;
  while (std::getline(lines, line)) {
    last = CsvFields(line);
    ASSERT_EQ(last.size(), 32u) << line;
    ++rows;
  }
  EXPECT_EQ(rows, 201);
  EXPECT_EQ(last[0], "40");
  EXPECT_NEAR(std::stod(last[1]), 5.0, 0.02);  // the cabin at the end pose
  const std::string summary = ReadFile(json);
  EXPECT_NE(summary.find("\"kind\": \"move\""), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"settle_s\""), std::string::npos);
  r = Fastcal(args);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("--force"), std::string::npos) << r.output;
  EXPECT_EQ(Fastcal(args + " --force --wind=4,30 --seed=3").code, 0);
  EXPECT_NE(ReadFile(json).find("\"mean_m_per_s\": 4"), std::string::npos);
}

// A winch table holding the start's lengths: nothing departs from quasi-static.
TEST_F(CliTest, DynamicsFollowsAWinchTable) {
  Pose pose;
  pose.position_m = Eigen::Vector3d(10.0, 5.0, 141.0);
  StaticsSolution s;
  ASSERT_EQ(SolveStatics(CableRobot::NominalFast(), pose, StaticsOptions(), &s),
            StaticsStatus::kOk);
  std::ostringstream table;
  table << "time_s,s0_1_m,s0_2_m,s0_3_m,s0_4_m,s0_5_m,s0_6_m\n";
  for (double t : {0.0, 5.0}) {
    table << t;
    for (const CableSolution& c : s.cables)
      table << "," << std::setprecision(17) << c.unstretched_length_m;
    table << "\n";
  }
  Write("plan.csv", table.str());
  const CommandResult r = Fastcal("dynamics --position=10,5,141 --lengths=" + Path("plan.csv") +
                                  " --hold-s=5 --segments=12 --output=" + Path("held.csv"));
  ASSERT_EQ(r.code, 0) << r.output;
  const size_t at = r.output.find("tensions peak ");
  ASSERT_NE(at, std::string::npos) << r.output;
  EXPECT_LT(std::stod(r.output.substr(at + 14)), 1e-6) << r.output;  // kN: rounding
}

// Bad input: exit 2 naming the flag (or the file, line and column), a pose the statics
// cannot hold: exit 1; never an output file.
TEST_F(CliTest, DynamicsRefusesBadInput) {
  Write("bad.csv",
        "time_s,s0_1_m,s0_2_m,s0_3_m,s0_4_m,s0_5_m,s0_6_m\n0,300,300,300,300,300,300\n"
        "1,300,x,300,300,300,300\n");
  const std::string out = " --output=" + Path("never.csv");
  for (const ExpectedRun& c : std::vector<ExpectedRun>{
           {"dynamics --position=0,0,140 --segments=-3" + out, 2, "--segments"},
           {"dynamics --position=0,0,140 --wind=nan,0" + out, 2, "--wind"},
           {"dynamics --position=0,0,140 --wind=4" + out, 2, "SPEED,DIRECTION_DEG"},
           {"dynamics --position=0,0,140 --hold-s=-1" + out, 2, "--hold-s"},
           {"dynamics --position=0,0,140 --rate-hz=0" + out, 2, "--rate-hz"},
           {"dynamics --position=0,0,140 --move-s=10" + out, 2, "--move-s applies to --to"},
           {"dynamics --position=0,0,140 --to=1,0,140 --initial-offset=0.1,0,0" + out, 2,
            "give one of"},
           {"dynamics --position=0,0,140 --initial-offset=0.1,0" + out, 2, "--initial-offset"},
           {"dynamics --position=0,0,140 --gust-spectrum=karman" + out, 2, "--gust-spectrum"},
           {"dynamics --position=0,0,140 --lengths=" + Path("bad.csv") + out, 2,
            "bad.csv:3: column 's0_2_m'"},
           {"dynamics --position=0,0,140 --lengths=" + Path("none.csv") + out, 2, "none.csv"},
           {"dynamics --position=0,0,290" + out, 1, "--position=0,0,290: the statics cannot hold"},
           {"dynamics --position=0,0,140 --to=0,0,290" + out, 1, "--to=0,0,290"},
       }) {
    RunBoundedAndExpect(c);
  }
  EXPECT_FALSE(std::filesystem::exists(Path("never.csv")));
}

// simulate --dynamics: a survey flown in time, written as a dataset calibrate reads; its
// flags refused without it, and what it excludes refused with it.
TEST_F(CliTest, SimulateFliesASurveyInTime) {
  const std::string out = Path("flown.csv");
  const CommandResult r = Fastcal(
      "simulate --dynamics --trajectory=line --from=0,0,140 --to=6,0,140 --nodes=3 "
      "--segments=12 --wait-s=5 --min-move-s=15 --wind=3,0 --seed=2 --out=" +
      out);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("flown in time (--dynamics): 40 s"), std::string::npos) << r.output;
  std::istringstream lines(ReadFile(out));
  std::string line;
  std::vector<std::string> rows;
  while (std::getline(lines, line)) {
    if (!line.empty() && line[0] != '#') rows.push_back(line);
  }
  ASSERT_EQ(rows.size(), 4u);  // the header and three samples
  EXPECT_EQ(CsvFields(rows[0])[0], "time_s");
  EXPECT_EQ(CsvFields(rows[2])[0], "20");
  EXPECT_EQ(CsvFields(rows[3])[0], "40");
  RunBoundedAndExpect(
      {"simulate --trajectory=random --samples=3 --wait-s=5 --out=" + Path("never.csv"), 2,
       "--wait-s applies to --dynamics only"});
  RunBoundedAndExpect(
      {"simulate --dynamics --trajectory=random --samples=3 "
       "--mass-centre-drift-m=0.01 --out=" +
           Path("never.csv"),
       2, "--dynamics"});
  EXPECT_FALSE(std::filesystem::exists(Path("never.csv")));
}

// simulate --dynamics --waits=design.json: each move followed by its design's wait (issue
// 55: the flight took one --wait-s for every move), the count checked against the moves.
TEST_F(CliTest, SimulateFliesTheDesignsWaits) {
  Write("design.json",
        "{\"stops\": [{\"settle\": {\"wait_s\": 0}}, {\"settle\": {\"wait_s\": 3}},"
        " {\"settle\": {\"wait_s\": 12}}]}\n");
  const std::string out = Path("flown.csv");
  const std::string base =
      "simulate --dynamics --trajectory=line --from=0,0,140 --to=6,0,140 --nodes=3 "
      "--segments=12 --min-move-s=15 --seed=2 ";
  const CommandResult r = Fastcal(base + "--waits=" + Path("design.json") + " --out=" + out);
  ASSERT_EQ(r.code, 0) << r.output;
  std::istringstream lines(ReadFile(out));
  std::string line;
  std::vector<std::string> rows;
  while (std::getline(lines, line)) {
    if (!line.empty() && line[0] != '#') rows.push_back(line);
  }
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(CsvFields(rows[2])[0], "18");  // a 15 s move, then 3 s
  EXPECT_EQ(CsvFields(rows[3])[0], "45");  // and 15 s, then 12 s
  Write("short.json", "{\"stops\": [{\"settle\": {\"wait_s\": 0}}]}\n");
  RunBoundedAndExpect({base + "--waits=" + Path("short.json") + " --out=" + Path("never.csv"), 2,
                       "0 waits (one per move), but the poses make 2 moves"});
  Write("bad.json", "{\"stops\": [{}, {\"settle\": {\"wait_s\": \"soon\"}}, {}]}\n");
  RunBoundedAndExpect({base + "--waits=" + Path("bad.json") + " --out=" + Path("never.csv"), 2,
                       "stops[1].settle.wait_s is missing"});
  RunBoundedAndExpect(
      {base + "--waits=" + Path("design.json") + " --wait-s=5 --out=" + Path("never.csv"), 2,
       "not both"});
  EXPECT_FALSE(std::filesystem::exists(Path("never.csv")));
}

}  // namespace
}  // namespace fastcal::test
