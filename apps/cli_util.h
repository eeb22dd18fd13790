// Helpers shared by the fastcal subcommands: flag checking, value parsing, atomic output.
#ifndef FASTCAL_APPS_CLI_UTIL_H_
#define FASTCAL_APPS_CLI_UTIL_H_

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <functional>
#include <future>
#include <set>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/units.h"

namespace fastcal::cli {

using internal::kNPerKn;

// The console is one screen: at most kConsoleWidth columns (calibrate's and design's
// summaries).
constexpr size_t kConsoleWidth = 100;

// `text` wrapped at kConsoleWidth, each line after the first indented by `indent`; cut
// after `max_lines` lines with " ... (FULL_TEXT_IN)", where the whole text is.
std::string Wrapped(const std::string& text, const std::string& first_indent,
                    const std::string& indent, size_t max_lines,
                    const std::string& full_text_in = "report.md");

// Exit codes: 0 success, 1 a computation failed (infeasible pose, solver), 2 bad usage or
// bad input (flags, files).
inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 2;

// Checks every "--name[=value]" in argv[first..] against `allowed` (names with dashes as
// the user types them), rewrites dashes in the names to the underscores gflags uses, and
// returns the rewritten argument vector (argv[0] first). A deprecated name
// (DeprecatedFlagName) whose new name is allowed is taken as the new one, with a note in
// *notes (may be null). On an unknown flag (named with the closest allowed ones: "did
// you mean"), a flag given twice (--noforce and --force, or an old and a new name, count
// as one flag) or a positional argument, returns false with the message in *error.
bool CheckAndNormaliseFlags(int argc, char** argv, int first, const std::string& command,
                            const std::set<std::string>& allowed,
                            std::vector<std::string>* normalised, std::string* error,
                            std::vector<std::string>* notes = nullptr);

// The current name of a flag renamed so that its unit is spelt as the data spell it
// (`_kN`, `_percent`: --min-tension-kn is now --min-tension-kN, --tension-noise-pct
// --tension-noise-percent); "" for any other name. Names with dashes.
std::string DeprecatedFlagName(const std::string& old_name);

// The allowed names (a command's flags, or the commands) closest to a misspelt `name`
// (edit distance, ignoring case, within about a third of its length; or the names it is
// the start of; a flag's former spelling counts as the flag), at most three, best first:
// what "did you mean" offers.
std::vector<std::string> ClosestNames(const std::string& name,
                                      const std::set<std::string>& allowed);

// True when argv has -h, --help or -help.
bool WantsHelp(int argc, char** argv, int first);

// Parses already-checked flags (see CheckAndNormaliseFlags) with gflags.
void ParseFlags(const std::vector<std::string>& args);

// The start of every subcommand `fastcal <command> ...` (argv[1] is the command): prints
// `help` to stdout when asked (-h, --help), else checks the flags against `allowed`
// (names with dashes) and parses them into the FLAGS_ variables. Returns true when the
// command should go on; otherwise *exit_code is 0 (help printed) or kExitUsage (the error
// already printed on stderr).
bool StartCommand(int argc, char** argv, const std::string& command, const char* help,
                  const std::set<std::string>& allowed, int* exit_code);

// True when flag `name` (with dashes, as the user types it) was given on the command line.
bool FlagGiven(const std::string& name);

// A flag that only some modes of a command use, e.g. --radius (--trajectory=arc).
struct FlagScope {
  std::string flag;        // name with dashes, as the user types it
  bool applies = false;    // to the mode of this command line
  std::string belongs_to;  // where it applies, e.g. "--trajectory=arc"
};

// Refuses a flag given on the command line that does not apply to the chosen mode (its
// words, e.g. "--trajectory=grid"): false with "--radius applies to --trajectory=arc, not
// to --trajectory=grid" in *error. Flags are never a silent default.
bool CheckFlagsApply(const std::vector<FlagScope>& scopes, const std::string& mode,
                     std::string* error);

// "nominal FAST" for an empty --model, else the path: the model named in summaries.
std::string ModelName(const std::string& model_path);

// The model of flag `flag` (e.g. "model"): the nominal FAST model when `path` is empty,
// else LoadCableRobot(path) with the library's words for the file replaced by the flag.
bool LoadModelFlag(const std::string& flag, const std::string& path, CableRobot* robot,
                   std::string* error);

// `message` (from the library, which names its option fields) with each field name in
// `field_to_flag` replaced by the flag that sets it, e.g. {"radius_m", "--radius"}. A name
// is replaced only where it stands as a whole name (not inside a longer one such as
// "sphere.radius_m").
std::string WithFlagNames(const std::string& message,
                          const std::vector<std::pair<std::string, std::string>>& field_to_flag);

// Checks, before any work, that output flag `flag` (e.g. "output") can write `path`:
// refuses to replace an existing file unless `force` (naming the file and --force), a
// directory even with `force`, a path whose directory does not exist, and a directory
// where no file can be made (read-only, /proc: a probe file is made and removed), each
// message starting "--<flag>=<path>: " and naming the directory. "" and "-" (stdout) pass.
// First removes the temporaries killed runs left beside `path` (their process gone:
// internal::RemoveStaleTemporaries).
bool CheckCanWrite(const std::string& flag, const std::string& path, bool force,
                   std::string* error);

// An output directory (calibrate/evaluate --out) must be new or empty, and creatable: its
// nearest existing ancestor must take a new directory (a probe is made and removed).
// With `replaceable` (--force), a directory holding only regular files of those names (a
// previous run's results) is accepted too. False with a message starting
// "--<flag>=<dir>: " and naming the directory otherwise. First removes what killed runs
// left beside it, and puts back a previous result a killed --force run had moved aside.
bool CheckOutputDirectory(const std::string& flag, const std::string& dir, std::string* error,
                          const std::vector<std::string>* replaceable = nullptr);

// Where an output path really is: absolute, without a trailing '/', '.' or '..', and
// through symbolic links, so that `--out=dir/`, `--out=.` and a link to an empty directory
// put the results in that directory (a temporary sibling renamed over it), and so that two
// flags naming one file can be told.
std::filesystem::path ResolveOutputPath(const std::string& dir);

// Parses one number of a comma-separated flag value by the rules of every fastcal file
// (internal::ParseFiniteDecimal: decimal, '.' whatever the locale, finite; no hexadecimal);
// spaces and tabs around it are ignored. False with the reason in *why otherwise.
bool ParseNumberItem(const std::string& item, double* value, std::string* why);

// Parses "x,y,z" (three finite numbers) for flag `name`.
bool ParseVector3(const std::string& name, const std::string& text, Eigen::Vector3d* v,
                  std::string* error);
bool ParseVector4(const std::string& name, const std::string& text, Eigen::Vector4d* v,
                  std::string* error);
// Six finite numbers, one per cable (--lengths, --tensions-kN).
bool ParseSix(const std::string& name, const std::string& text, std::array<double, 6>* v,
              std::string* error);

// A cabin position (--position, --from, --to): ParseVector3, then the plausibility limits
// a dataset's positions obey (plausibility.h): "--position=0,0,-50: z = -50 m is below the
// reflector (...)".
bool ParsePosition(const std::string& name, const std::string& text, Eigen::Vector3d* position_m,
                   std::string* error);
// Roll, pitch, yaw in degrees (--rpy), each within the plausible angle.
bool ParseRpyDeg(const std::string& name, const std::string& text, Eigen::Vector3d* rpy_deg,
                 std::string* error);

// A comma-separated list of finite numbers for flag `flag` (ParseNumberItem each; an empty
// item, as after a trailing comma, is an error naming the flag).
bool ParseNumberList(const std::string& flag, const std::string& text, std::vector<double>* values,
                     std::string* error);

// --joints=v1,...: the model's moving parts at these joint values (its joint order, the
// columns' units: deg, m), folded into *robot's mass centre (moving_parts.h eq. (1)); the
// parts are then fixed. Empty: every joint at 0 (the model's mass_centre_m). A count other
// than the model's joints, a value out of a joint's range, or --joints for a model without
// moving parts is an error naming the joints. With the parts fixed the model's measured
// frame (which names a part) is dropped too: convert the data's poses with the model as
// loaded, at *joints_out (may be null; left as it is for an empty --joints).
bool MassCentreAtJointsFlag(const std::string& text, CableRobot* robot, std::string* error,
                            JointValues* joints_out = nullptr);

// Writes `content` to `path` through a temporary file and a rename, so that a failure
// leaves no partial file; path "" or "-" writes to stdout (each write checked: "cannot
// write to standard output: No space left on device ..."). Without `replace` (--force),
// a file another process made at `path` meanwhile is not replaced (internal::RenameNoReplace).
bool WriteOutput(const std::string& path, const std::string& content, std::string* error,
                 bool replace = true);

// A result written as it is made (solve: memory independent of the number of poses):
// into a locked temporary beside the file, renamed into place by Finish; or, for stdout
// (path "" or "-"), held in memory up to kHeldBytes and beyond that in an unnamed
// temporary file in $TMPDIR (else /tmp), all copied to stdout by Finish. A run that fails
// before Finish leaves nothing, neither a file nor a partial table on stdout. Errors name
// the user's file, or standard output, or the temporary directory.
class ResultStream {
 public:
  static constexpr size_t kHeldBytes = size_t{64} << 20;

  ResultStream() = default;
  ResultStream(const ResultStream&) = delete;
  ResultStream& operator=(const ResultStream&) = delete;
  ~ResultStream();

  bool Open(const std::string& path, std::string* error);
  bool Write(std::string_view text, std::string* error);
  // `replace`: over an existing file (--force); see WriteOutput.
  bool Finish(bool replace, std::string* error);

 private:
  bool Spill(std::string* error);

  bool to_stdout_ = true;
  internal::AtomicFileWriter file_;
  std::string held_;
  std::FILE* spill_ = nullptr;
  std::string spill_directory_;
};

// A record (--output=FILE, or stdout when empty or "-") and a companion file (--NAME=FILE:
// a summary, a page; never stdout): refused before any work when --force applies to
// neither, the companion is "-", both name one file, or either cannot be written.
bool CheckRecordOutputs(const std::string& name, const std::string& path, std::string* error);
// Writes the record and the companion (empty path: none) together, the record to stdout
// without --output (WriteOutputsTogether).
bool WriteRecordOutputs(const std::string& record, const std::string& path,
                        const std::string& content, std::string* error);

// Writes every (path, content) to a temporary file beside it, and renames them into place
// only once all were written: a failure to write (disk full, no permission) leaves none
// of the paths changed. On failure removes its temporary files and returns false with the
// user's path named in *error. (A rename that fails after others succeeded, another
// process taking the name meanwhile, leaves those in place.) `replace` as WriteOutput's.
bool WriteOutputsTogether(const std::vector<std::pair<std::string, std::string>>& files,
                          bool replace, std::string* error);

// Writes the given (name, content) files and then `extra` (may be empty; it writes into
// the directory it is given) into a fresh temporary sibling of `dir`, then renames it to
// `dir` (calibrate, evaluate, design --out); on any failure removes the temporary
// directory and names --out=<dir> in *error. `dir` must pass CheckOutputDirectory, with
// `replaceable` (may be null) the files a previous run may have left there (--force):
// that run's directory is then moved aside and removed once the new one is in place.
bool WriteDirectoryAtomically(const std::string& dir,
                              const std::vector<std::pair<std::string, std::string>>& files,
                              const std::function<bool(const std::string&, std::string*)>& extra,
                              const std::vector<std::string>* replaceable, std::string* error);
// std::async(std::launch::async, fn) or, when the system refuses a thread (a process
// limit, `ulimit -v`: issue 29), the same work deferred to the caller's get().
template <typename Fn>
auto AsyncOrDeferred(Fn fn) -> std::future<decltype(fn())> {
  try {
    return std::async(std::launch::async, fn);
  } catch (const std::system_error&) {
    return std::async(std::launch::deferred, fn);
  }
}

// Standard output is a result file like any other (issue 29). InstallCheckedStdout, at
// the start of main, gives std::cout a buffer that writes to file descriptor 1 with
// write(2), checks each write and keeps the first error (a full disk, /dev/full, a closed
// pipe when SIGPIPE is ignored); StdoutError() is its errno, 0 while all went well.
// Everything the commands print on stdout goes through std::cout.
void InstallCheckedStdout();
int StdoutError();

// Flushes std::cout and closes standard output, checking both. On a failure prints
// "fastcal <command>: cannot write to standard output: <why> ..." and returns kExitFailure
// (the machine failed, not the input) unless `exit_code` already says the run failed;
// otherwise returns `exit_code`. Called once, at the end of main.
int FinishStandardOutput(const std::string& command, int exit_code);

// "fastcal <command>: <message>" on stderr.
void PrintError(const std::string& command, const std::string& message);

std::string FormatDouble(double value, int significant_digits = 10);

// "fastcal <arguments>" as typed, for the headers of written files; the flags named in
// `omit` (without dashes, e.g. "force") left out, with their "no" forms.
std::string CommandLine(int argc, char** argv, const std::vector<std::string>& omit = {});

// The current date and time, UTC, ISO 8601 ("2026-11-22T15:04:05Z"): when a run was made.
std::string UtcNow();

}  // namespace fastcal::cli

#endif  // FASTCAL_APPS_CLI_UTIL_H_
