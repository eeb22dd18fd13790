// Ctrl-C and SIGTERM stop a command cleanly (issue 37): exit 128 + the signal (130, 143),
// and nothing half-written left where the result goes, nor a temporary beside it.
#include <string>

#include "cli_fixture.h"

namespace fastcal::test {
namespace {

class CliSignalsTest : public CliTest {
 protected:
  // Starts `args` (a run of minutes), signals it after `delay_s` and returns its exit code.
  int Interrupted(const std::string& args, const char* signal, double delay_s) {
    const CommandResult r = Shell("cd " + Path("") + " && (timeout 120 " + Bin() + " " + args +
                                  " & pid=$!; sleep " + std::to_string(delay_s) + "; kill -" +
                                  signal + " $pid; wait $pid; echo \"exit=$?\")");
    const size_t at = r.output.rfind("exit=");
    EXPECT_NE(at, std::string::npos) << r.output;
    EXPECT_NE(r.output.find("interrupted"), std::string::npos) << r.output;
    return at == std::string::npos ? -1 : std::stoi(r.output.substr(at + 5));
  }
  bool DirectoryEmpty() const { return fs::is_empty(dir_); }
};

TEST_F(CliSignalsTest, SigintAndSigtermLeaveNothingHalfWritten) {
  constexpr double kDelayS = 0.7;  // the runs below take minutes
  EXPECT_EQ(Interrupted("simulate --trajectory=random --samples=10000000 --out=s.csv", "INT",
                        kDelayS),
            130);
  EXPECT_TRUE(DirectoryEmpty());
  EXPECT_EQ(Interrupted("solve --trajectory=random --samples=10000000 --output=p.csv", "TERM",
                        kDelayS),
            143);
  EXPECT_TRUE(DirectoryEmpty());
}

}  // namespace
}  // namespace fastcal::test
