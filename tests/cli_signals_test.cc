// Ctrl-C and SIGTERM stop a command cleanly (issue 37): exit 128 + the signal (130, 143),
// and nothing half-written left where the result goes, nor a temporary beside it.
#include <string>

#include "cli_fixture.h"

namespace fastcal::test {
namespace {

class CliSignalsTest : public CliTest {
 protected:
  // Starts `args` (a run of minutes), waits until the process catches SIGINT and SIGTERM
  // (bits 2 and 15 of SigCgt in /proc/PID/status: on a loaded CI machine the program may
  // not have reached main() after a fixed delay, and the default action then kills it
  // without a word), signals it `delay_s` later and returns its exit code. A watchdog
  // kills a run the signal did not stop, its output away from the pipe read here.
  int Interrupted(const std::string& args, const char* signal, double delay_s) {
    const CommandResult r =
        Shell("cd " + Path("") + " && (" + Bin() + " " + args +
              " & pid=$!; (sleep 120; kill -9 $pid) >/dev/null 2>&1 & w=$!; "
              "for i in $(seq 600); do m=$(sed -n 's/^SigCgt:[[:space:]]*//p' /proc/$pid/status "
              "2>/dev/null); [ -n \"$m\" ] && [ $((0x$m & 0x4002)) -eq 16386 ] && break; "
              "sleep 0.05; done; sleep " +
              std::to_string(delay_s) + "; kill -" + signal +
              " $pid; wait $pid; c=$?; kill $w 2>/dev/null; echo \"exit=$c\")");
    const size_t at = r.output.rfind("exit=");
    EXPECT_NE(at, std::string::npos) << r.output;
    EXPECT_NE(r.output.find("interrupted"), std::string::npos) << r.output;
    return at == std::string::npos ? -1 : std::stoi(r.output.substr(at + 5));
  }
  bool DirectoryEmpty() const { return fs::is_empty(dir_); }
};

TEST_F(CliSignalsTest, SigintAndSigtermLeaveNothingHalfWritten) {
  constexpr double kDelayS = 0.7;  // the runs below take minutes
  EXPECT_EQ(
      Interrupted("simulate --trajectory=random --samples=10000000 --out=s.csv", "INT", kDelayS),
      130);
  EXPECT_TRUE(DirectoryEmpty());
  EXPECT_EQ(
      Interrupted("solve --trajectory=random --samples=10000000 --output=p.csv", "TERM", kDelayS),
      143);
  EXPECT_TRUE(DirectoryEmpty());
}

// A new track stopped while it writes its window stores (issue 37: the staging directory
// DIR.partial-PID and its windows/*.samples stayed, beside a message that nothing was
// left): nothing of it remains but the lock file beside DIR.
TEST_F(CliSignalsTest, AStoppedNewTrackLeavesNoStagingDirectory) {
  ASSERT_EQ(Fastcal("simulate --trajectory=random --samples=200000 --interval-s=1 --seed=2 "
                    "--start=2024-05-01T00:00:00Z --out=" +
                    Path("days.csv"))
                .code,
            0);
  for (const char* signal : {"INT", "TERM"}) {
    const int code = Interrupted(
        "track --spec=" + Source() + "/calibration_data/spec_track.yaml --data=days.csv --out=t",
        signal, 1.0);
    EXPECT_EQ(code, signal[0] == 'I' ? 130 : 143);
    for (const fs::directory_entry& e : fs::directory_iterator(dir_)) {
      const std::string name = e.path().filename().string();
      EXPECT_TRUE(name == "days.csv" || name == "days.truth.yaml" || name == ".t.lock")
          << name << " left after SIG" << signal;
    }
  }
}

}  // namespace
}  // namespace fastcal::test
