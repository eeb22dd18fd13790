// The season's store survives interruption, duplication and tampering (issue 37): one
// run at a time on a track; an update killed after appending samples leaves nothing
// counted twice; a fold copied from elsewhere is refused (and --refold rebuilds it), as is
// a store copied from elsewhere (by its digest) and a fold of another window; the
// same data given twice, two files of relative times on one time line, a window label
// reaching outside the track and a state nested without end are refused by name.
#include <cstdint>
#include <filesystem>
#include <map>
#include <regex>
#include <sstream>
#include <string>

#include "cli_fixture.h"

namespace fastcal::test {
namespace {

class CliTrackStoreTest : public CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    // Three days of an hour each from 20:00 UTC, one file per day.
    for (int d = 1; d <= 3; ++d) {
      const std::string day = "2024-05-0" + std::to_string(d);
      ASSERT_EQ(Fastcal("simulate --trajectory=random --samples=1800 --interval-s=2 --seed=" +
                        std::to_string(d) + " --start=" + day +
                        "T20:00:00Z --mass-centre=0.22,0.11,0.5 --out=" + Path(day + ".csv"))
                    .code,
                0);
    }
  }
  CommandResult Track(const std::string& files, const std::string& out,
                      const std::string& more = "") {
    return Fastcal("track --spec=" + Source() + "/calibration_data/spec_track.yaml --data=" +
                   files + " --out=" + Path(out) + " " + more);
  }
  std::string Day(int d) const { return Path("2024-05-0" + std::to_string(d) + ".csv"); }
};

TEST_F(CliTrackStoreTest, ASecondRunOnTheSameTrackIsRefused) {
  // The lock is held as a running track holds it: the second run exits 1 at once.
  const CommandResult r =
      Shell("flock " + Path(".t.lock") + " " + Bin() + " track --spec=" + Source() +
            "/calibration_data/spec_track.yaml --data=" + Day(1) + " --out=" + Path("t"));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("another fastcal track is running on it"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(Path("t")));
}

// The same track by another name: a symbolic link to DIR, even before DIR exists (two
// runs on `t` and `sym -> t` both exited 0 before, and one result was lost).
TEST_F(CliTrackStoreTest, ARunThroughASymbolicLinkIsRefusedToo) {
  ASSERT_EQ(Shell("cd " + Path("") + " && ln -s t sym").code, 0);
  const CommandResult r =
      Shell("flock " + Path(".t.lock") + " " + Bin() + " track --spec=" + Source() +
            "/calibration_data/spec_track.yaml --data=" + Day(1) + " --out=" + Path("sym"));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("another fastcal track is running on it"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(Path("t")));
  // Unlocked, the run builds the track where the link points.
  EXPECT_EQ(Track(Day(1), "sym").code, 0);
  EXPECT_TRUE(fs::exists(Path("t/track_state.json")));
}

// Issue 57, 4: the lock was keyed on DIR as written: a run on `--out=/p/t` and one from
// inside it on `--out=.` locked /p/.t.lock and ./..lock, and both wrote the track. The lock
// is now the resolved track's, however it is spelled ('.', a trailing '/', '..').
TEST_F(CliTrackStoreTest, ARunFromInsideTheTrackTakesTheSameLock) {
  ASSERT_EQ(Track(Day(1), "t").code, 0);
  const std::string track = Bin() + " track --spec=" + Source() +
                            "/calibration_data/spec_track.yaml --data=" + Day(1) + "," + Day(2);
  for (const char* out : {".", "./", "../t", "../t/."}) {
    const CommandResult r =
        Shell("cd " + Path("t") + " && flock " + Path(".t.lock") + " " + track + " --out=" + out);
    EXPECT_EQ(r.code, 1) << out << "\n" << r.output;
    EXPECT_NE(r.output.find("another fastcal track is running on it"), std::string::npos)
        << r.output;
  }
  EXPECT_EQ(Shell("cd " + Path("t") + " && " + track + " --out=.").code, 0);  // unlocked: updates
  EXPECT_FALSE(fs::exists(Path("t/..lock")));
}

// Issue 57, 10: refused runs left lock files outside --out (`--out=/` made /..lock,
// `--out=season.csv` .season.csv.lock). What cannot be a track is refused before any
// lock, and the lock file goes with the run that held it, refused or not.
TEST_F(CliTrackStoreTest, NoRunLeavesALockFileBehind) {
  const bool root_had_one = fs::exists("/..lock");
  CommandResult r = Track(Day(1), "2024-05-01.csv");  // the data file itself as --out
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("2024-05-01.csv: not a directory"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(Path(".2024-05-01.csv.lock")));
  r = Fastcal("track --spec=" + Source() + "/calibration_data/spec_track.yaml --data=" + Day(1) +
              " --out=/");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("/: the root directory cannot hold a track"), std::string::npos)
      << r.output;
  if (!root_had_one && fs::exists("/..lock")) {
    fs::remove("/..lock");
    ADD_FAILURE() << "a refused run made /..lock";
  }
  Write("bad.csv", "time_s,x_m\n1,2\n");
  r = Track(Day(1) + "," + Path("bad.csv"), "t");  // refused after the lock was taken
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_FALSE(fs::exists(Path(".t.lock")));
  EXPECT_EQ(Track(Day(1), "t").code, 0);
  EXPECT_FALSE(fs::exists(Path(".t.lock")));
}

// Issue 57, 6: a day sent again with its times shifted (a re-export in Beijing time, +8 h)
// passed the SHA-256 and repeated-row checks, which include the time, and was folded
// twice; shifted by 9 days it made a false event at p = 3e-84. The readings without their
// times tell it, in one run and in an update.
TEST_F(CliTrackStoreTest, ADayReSentWithShiftedTimesIsRefused) {
  const auto shifted = [&](const std::string& name, double shift_s) {
    std::istringstream in(ReadFile(Day(1)));
    std::ostringstream out;
    out.precision(17);
    for (std::string line; std::getline(in, line);) {
      if (line.empty() || line[0] == '#' || line.rfind("time_s", 0) == 0) {
        out << line << "\n";
        continue;
      }
      const size_t comma = line.find(',');
      out << std::stod(line.substr(0, comma)) + shift_s << line.substr(comma) << "\n";
    }
    Write(name, out.str());
    return Path(name);
  };
  CommandResult r = Track(Day(1) + "," + shifted("beijing.csv", 8 * 3600.0), "a");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("beijing.csv: the same readings as"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("its times shifted by +8 h"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(Path("a")));
  ASSERT_EQ(Track(Day(1) + "," + Day(2), "b").code, 0);
  r = Track(Day(1) + "," + Day(2) + "," + shifted("later.csv", 9 * 86400.0), "b");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("later.csv: the same readings as"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("already in the track, its times shifted by +216 h (+9 d)"),
            std::string::npos)
      << r.output;
}

TEST_F(CliTrackStoreTest, AnInterruptedUpdateCountsNothingTwice) {
  ASSERT_EQ(Track(Day(1) + "," + Day(2), "t").code, 0);
  ASSERT_EQ(Track(Day(1) + "," + Day(2), "clean").code, 0);
  ASSERT_EQ(Track(Day(1) + "," + Day(2) + "," + Day(3), "clean").code, 0);  // its update
  // An update killed after appending day 2's samples again and day 3's to a new store,
  // before the state was saved: what the stores hold then.
  ASSERT_EQ(Shell("cd " + Path("t/windows") + " && cp 2024-05-02.samples 2024-05-03.samples" +
                  " && cp 2024-05-02.samples again && cat again >> 2024-05-02.samples && rm again")
                .code,
            0);
  const CommandResult r = Track(Day(1) + "," + Day(2) + "," + Day(3), "t");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("interrupted run"), std::string::npos) << r.output;
  // The repaired track is the one an uninterrupted update gives, to the digit (samples
  // appended twice would change every window's numbers and counts).
  const std::string kept = ReadFile(Path("t/track.csv"));
  const std::string clean = ReadFile(Path("clean/track.csv"));
  EXPECT_EQ(kept.substr(kept.find('\n')), clean.substr(clean.find('\n')));
}

TEST_F(CliTrackStoreTest, AFoldFromElsewhereIsRefusedAndRefoldRebuildsIt) {
  ASSERT_EQ(Track(Day(1) + "," + Day(2), "t").code, 0);
  ASSERT_EQ(Shell("cd " + Path("t/folds") + " && cp 2024-05-01.g1.fold 2024-05-02.g1.fold").code,
            0);
  CommandResult r = Track(Day(1) + "," + Day(2) + "," + Day(3), "t");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("2024-05-02.g1.fold: not the fold this track wrote"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("--refold"), std::string::npos) << r.output;
  r = Track(Day(1) + "," + Day(2) + "," + Day(3), "t", "--refold");
  EXPECT_EQ(r.code, 0) << r.output;
}

TEST_F(CliTrackStoreTest, AStoreFromElsewhereIsRefusedEvenOnRefold) {
  ASSERT_EQ(Track(Day(1) + "," + Day(2), "t").code, 0);
  // Same length (1800 samples a day): only the digest tells the two days apart.
  ASSERT_EQ(Shell("cd " + Path("t/windows") + " && cp 2024-05-01.samples 2024-05-02.samples").code,
            0);
  const CommandResult r = Track(Day(1) + "," + Day(2), "t", "--refold");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("2024-05-02.samples: not the samples this track stored"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("--force"), std::string::npos) << r.output;
  // As it says: --force builds the track afresh from the data, the day's own numbers.
  ASSERT_EQ(Track(Day(1) + "," + Day(2), "clean").code, 0);
  ASSERT_EQ(Track(Day(1) + "," + Day(2), "t", "--force").code, 0);
  const std::string rebuilt = ReadFile(Path("t/track.csv"));
  const std::string clean = ReadFile(Path("clean/track.csv"));
  EXPECT_EQ(rebuilt.substr(rebuilt.find('\n')), clean.substr(clean.find('\n')));
}

// A fold that cannot be read is cleared by --force as by --refold (issue 37: --force kept
// refusing it).
TEST_F(CliTrackStoreTest, ACorruptFoldIsClearedByForce) {
  ASSERT_EQ(Track(Day(1) + "," + Day(2), "t").code, 0);
  Write("t/folds/2024-05-02.g1.fold", "not a fold");
  EXPECT_EQ(Track(Day(1) + "," + Day(2), "t").code, 2);
  const CommandResult r = Track(Day(1) + "," + Day(2), "t", "--force");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(ReadFile(Path("t/folds/2024-05-02.g1.fold")), "not a fold");  // the day folded afresh
  EXPECT_EQ(Track(Day(1) + "," + Day(2), "t").code, 0);                   // and read back
}

TEST_F(CliTrackStoreTest, AFoldOfAnotherWindowIsRefusedEvenWithItsDigestForged) {
  ASSERT_EQ(Track(Day(1) + "," + Day(2), "t").code, 0);
  const std::string one = Path("t/folds/2024-05-01.g1.fold");
  const std::string two = Path("t/folds/2024-05-02.g1.fold");
  const std::string sha_one = Shell("sha256sum " + one).output.substr(0, 64);
  const std::string sha_two = Shell("sha256sum " + two).output.substr(0, 64);
  ASSERT_EQ(Shell("cp " + one + " " + two).code, 0);
  const std::string state = ReadFile(Path("t/track_state.json"));
  ASSERT_NE(state.find(sha_two), std::string::npos);
  Write("t/track_state.json", std::regex_replace(state, std::regex(sha_two), sha_one));
  const CommandResult r = Track(Day(1) + "," + Day(2) + "," + Day(3), "t");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("the fold of window '2024-05-01'"), std::string::npos) << r.output;
}

// One tension column in another unit (its kN read as N: 1000x small) is named before
// anything is folded, as calibrate names it (track said "cannot solve this pose").
TEST_F(CliTrackStoreTest, ATensionColumnInAnotherUnitIsNamed) {
  ASSERT_EQ(Shell("awk -F, 'BEGIN {OFS = \",\"} /^#/ {print; next} !h {for (i = 1; i <= NF; "
                  "++i) if ($i == \"T3_kN\") c = i; h = 1; print; next} {$c = $c / 1000; "
                  "print}' " +
                  Day(1) + " > " + Path("slipped.csv"))
                .code,
            0);
  const CommandResult r = Track(Path("slipped.csv"), "t");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("cable 3's tensions"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("read 1000x small? (T3 in kN where the column map says N)"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(Path("t")));
}

// A file holding its rows twice (two exports concatenated): refused naming the repeated
// line, where every sample was folded twice with exit 0.
TEST_F(CliTrackStoreTest, AFileHoldingItsRowsTwiceIsRefused) {
  ASSERT_EQ(Shell("(cat " + Day(1) + "; grep -v '^#' " + Day(1) + " | sed -n '2,$p') > " +
                  Path("twice.csv"))
                .code,
            0);
  const CommandResult r = Track(Path("twice.csv") + "," + Day(2), "t");
  EXPECT_NE(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("twice.csv:1805 repeats line 5 (the same time, pose and tensions)"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(Path("t")));
  // The copy written with 9 significant digits (a second re-check: folded twice, exit 0).
  ASSERT_EQ(Shell("(cat " + Day(1) + "; grep -v '^#' " + Day(1) +
                  " | sed -n '2,$p' | awk -F, 'BEGIN {OFS = \",\"} {for (i = 2; i <= NF; ++i) "
                  "$i = sprintf(\"%.9g\", $i); print}') > " +
                  Path("rounded.csv"))
                .code,
            0);
  const CommandResult rounded = Track(Path("rounded.csv") + "," + Day(2), "t");
  EXPECT_NE(rounded.code, 0) << rounded.output;
  EXPECT_NE(rounded.output.find("rounded.csv:1805 repeats line 5"), std::string::npos)
      << rounded.output;
}

TEST_F(CliTrackStoreTest, TheSameDataTwiceIsRefusedByContent) {
  ASSERT_EQ(Shell("cp " + Day(1) + " " + Path("copy.csv") + " && gzip -k " + Day(2)).code, 0);
  CommandResult r = Track(Day(1) + "," + Path("copy.csv"), "a");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("copy.csv: the same data as"), std::string::npos) << r.output;
  ASSERT_EQ(Track(Day(1) + "," + Day(2), "b").code, 0);
  // The copy is found once it is read (its digest computed beside the read): the samples
  // it appended are cut back with the refusal.
  std::map<std::string, std::uintmax_t> stores;
  for (const auto& e : fs::directory_iterator(Path("b/windows"))) {
    stores[e.path().filename().string()] = fs::file_size(e.path());
  }
  r = Track(Day(1) + "," + Day(2) + "," + Day(2) + ".gz", "b");  // the day re-sent gzipped
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("already in the track"), std::string::npos) << r.output;
  std::map<std::string, std::uintmax_t> after;
  for (const auto& e : fs::directory_iterator(Path("b/windows"))) {
    after[e.path().filename().string()] = fs::file_size(e.path());
  }
  EXPECT_EQ(after, stores);
  // Two copies of a file of relative times: the copy is named, not the time line the two
  // would share.
  ASSERT_EQ(Fastcal("simulate --trajectory=random --samples=300 --interval-s=2 --seed=4 --out=" +
                    Path("rel.csv"))
                .code,
            0);
  ASSERT_EQ(Shell("cp " + Path("rel.csv") + " " + Path("rel_copy.csv")).code, 0);
  r = Track(Path("rel.csv") + "," + Path("rel_copy.csv"), "r");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("rel_copy.csv: the same data as"), std::string::npos) << r.output;
}

TEST_F(CliTrackStoreTest, FilesOverlappingInTimeAreRefusedUnlessKept) {
  // The same hour simulated again with another seed (another name, other numbers): its
  // instants are day 1's; folded both, day 1 would count twice (issue 37).
  ASSERT_EQ(Fastcal("simulate --trajectory=random --samples=1800 --interval-s=2 --seed=9 "
                    "--start=2024-05-01T20:00:00Z --out=" +
                    Path("again.csv"))
                .code,
            0);
  CommandResult r = Track(Day(1) + "," + Path("again.csv"), "a");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("again.csv (2024-05-01T20:00:00Z to 2024-05-01T20:59:58Z) overlaps"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("--keep-overlapping"), std::string::npos) << r.output;
  r = Track(Day(1) + "," + Path("again.csv"), "b", "--keep-overlapping");
  EXPECT_EQ(r.code, 0) << r.output;
  // Days that follow each other do not overlap.
  EXPECT_EQ(Track(Day(1) + "," + Day(2), "c").code, 0);
}

TEST_F(CliTrackStoreTest, RelativeTimesOfTwoFilesNeedAWindowEach) {
  for (int k = 1; k <= 2; ++k) {
    ASSERT_EQ(Fastcal("simulate --trajectory=random --samples=300 --seed=" + std::to_string(k) +
                      " --out=" + Path("rel" + std::to_string(k) + ".csv"))
                  .code,
              0);
  }
  const std::string both = Path("rel1.csv") + "," + Path("rel2.csv");
  CommandResult r = Track(both, "a", "--window=1h");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("give --window=file"), std::string::npos) << r.output;
  r = Track(both, "b", "--window=file");
  EXPECT_EQ(r.code, 0) << r.output;
  // Nor in an update: the second relative file added to a track of the first (a review
  // found them joined in window t0, exit 0), with --keep-overlapping too.
  ASSERT_EQ(Track(Path("rel1.csv"), "c", "--window=1h").code, 0);
  r = Track(both, "c", "--window=1h --keep-overlapping");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("give --window=file"), std::string::npos) << r.output;
}

TEST_F(CliTrackStoreTest, ASymbolicLinkInsideATrackIsRefused) {
  // A store linked to a file outside the track was truncated there (a review, issue 37).
  ASSERT_EQ(Track(Day(1), "t").code, 0);
  const std::string store = Path("t/windows/2024-05-01.samples");
  ASSERT_TRUE(fs::exists(store));
  fs::rename(store, Path("outside.samples"));
  const auto size = fs::file_size(Path("outside.samples"));
  fs::create_symlink(Path("outside.samples"), store);
  const CommandResult r = Track(Day(1) + "," + Day(2), "t");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("a symbolic link inside a track is refused"), std::string::npos)
      << r.output;
  EXPECT_EQ(fs::file_size(Path("outside.samples")), size);
}

TEST_F(CliTrackStoreTest, ADamagedStateIsRefusedByName) {
  ASSERT_EQ(Track(Day(1) + "," + Day(2), "t").code, 0);
  const std::string state = ReadFile(Path("t/track_state.json"));
  Write("t/track_state.json", std::regex_replace(state, std::regex("\"label\": \"2024-05-02\""),
                                                 "\"label\": \"../../escape\""));
  CommandResult r = Track(Day(1) + "," + Day(2) + "," + Day(3), "t");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("is not one this program writes"), std::string::npos) << r.output;
  // A negative count (a day dropped silently before) is refused by name.
  Write("t/track_state.json",
        std::regex_replace(state, std::regex("\"samples\": ([0-9]+)"), "\"samples\": -5",
                           std::regex_constants::format_first_only));
  r = Track(Day(1) + "," + Day(2), "t");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("not a count"), std::string::npos) << r.output;
  // Window times that are no window's (1e400 was written to track.csv as inf).
  Write("t/track_state.json",
        std::regex_replace(state, std::regex("\"start_s\": [-0-9.e+]+"), "\"start_s\": 1e400",
                           std::regex_constants::format_first_only));
  r = Track(Day(1) + "," + Day(2), "t");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("times are not a window's"), std::string::npos) << r.output;
  // The windows emptied by hand: an update dropped every earlier day, exit 0.
  const size_t windows = state.find("\"windows\": [");
  const size_t shared = state.find("\"shared\": [");
  ASSERT_NE(windows, std::string::npos);
  ASSERT_NE(shared, std::string::npos);
  Write("t/track_state.json",
        state.substr(0, windows) + "\"windows\": [],\n  " + state.substr(shared));
  r = Track(Day(1) + "," + Day(2) + "," + Day(3), "t");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("samples are in no window: a damaged state"), std::string::npos)
      << r.output;
  // Edits that crashed the next run or gave another day's numbers under a date, exit 0:
  // a shared value twice (SIGSEGV or abort), a shared value of no column (abort: invalid
  // pointer), a window's key (a later day's samples merged into it), a count.
  const auto refused_after = [&](const std::string& edited, const std::string& why) {
    Write("t/track_state.json", edited);
    const CommandResult after = Track(Day(1) + "," + Day(2) + "," + Day(3), "t");
    EXPECT_EQ(after.code, 2) << why << "\n" << after.output;
    EXPECT_NE(after.output.find(why), std::string::npos) << after.output;
  };
  refused_after(
      std::regex_replace(state, std::regex("(\"shared\": \\[\\s*)(\\{[^}]*\\})"), "$1$2, $2"),
      "two shared values of linear_density_kg_per_m[1] from one time");
  refused_after(
      std::regex_replace(state, std::regex("\"linear_density_kg_per_m\\[1\\]\""), "\"bogus[9]\""),
      "a shared value of 'bogus[9]', not a column");
  refused_after(std::regex_replace(state, std::regex("\"key\": ([0-9]+)"), "\"key\": 19850",
                                   std::regex_constants::format_first_only),
                "is not the window of key 19850");
  // Its end moved a day on, key and label kept (one day's data shown under two dates).
  refused_after(
      std::regex_replace(state, std::regex("\"end_s\": [-0-9.e+]+"), "\"end_s\": 1714780800",
                         std::regex_constants::format_first_only),
      "is not the window of key");
  refused_after(std::regex_replace(state, std::regex("\"samples\": 1800"), "\"samples\": 900",
                                   std::regex_constants::format_first_only),
                "its windows hold");
  refused_after(
      std::regex_replace(state, std::regex("\"sigma_percent\": [^,\n]+"), "\"sigma_percent\": 50",
                         std::regex_constants::format_first_only),
      "whitened by another slow error than track_state.json records");
  // Millions of empty lists: each a yaml-cpp node (16 MiB of them took 2.7 GB); refused by
  // their count before they are parsed, under a memory limit.
  std::string lists = "{\"format\": [";
  while (lists.size() < (8u << 20)) lists += "[],";
  Write("t/track_state.json", lists + "[]]}");
  r = Shell(std::string(kUnderSanitizer ? "" : "ulimit -v 1500000; ") + "timeout 60 " + Bin() +
            " track --spec=" + Source() + "/calibration_data/spec_track.yaml --data=" + Day(1) +
            " --out=" + Path("t"));
  EXPECT_EQ(r.code, 2) << r.output.substr(0, 2000);
  EXPECT_NE(r.output.find("entries, more than any track's state holds"), std::string::npos)
      << r.output.substr(0, 2000);
  Write("t/track_state.json", std::string(100000, '['));  // under the entries bound
  r = RunBoundedAndExpect({"track --spec=" + Source() +
                               "/calibration_data/spec_track.yaml --data=" + Day(1) +
                               " --out=" + Path("t"),
                           2, "nesting deeper than"});
}

}  // namespace
}  // namespace fastcal::test
