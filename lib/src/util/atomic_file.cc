// Atomic file writes, their temporaries, and bounded reads (internal/atomic_file.h).
#include "fastcal/internal/atomic_file.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <limits>
#include <regex>
#include <system_error>
#include <vector>

#include "fastcal/internal/quote.h"

namespace fastcal::internal {

namespace {

// A temporary older than this whose pid runs but which nobody has locked belongs to a
// process that reused the pid (the writer locks its temporary right after creating it).
constexpr int kStaleAfterSeconds = 60;

std::string BaseName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// The pid of a temporary's name after its prefix: `rest` is "<pid>", or with `counted`
// also "<pid>.<n>" or "<pid>.tmp.<pid>.<n>" (the forms fastcal writes and wrote); 0 for
// anything else, which is never touched (a user's "data.csv.tmp.2024.backup").
pid_t PidOf(std::string_view rest, bool counted) {
  static const std::regex kExact(R"((\d{1,9}))");
  static const std::regex kCounted(R"((\d{1,9})(\.\d+|\.tmp\.\d+\.\d+)?)");
  std::match_results<std::string_view::const_iterator> m;
  if (!std::regex_match(rest.begin(), rest.end(), m, counted ? kCounted : kExact)) return 0;
  return static_cast<pid_t>(std::stol(m[1].str()));
}

// Whether the process that made temporary `path` (pid `pid`) is gone.
bool MakerIsGone(const std::string& path, pid_t pid, bool lockable) {
  if (pid == ::getpid()) return false;  // ours: another write of this very run
  if (::kill(pid, 0) != 0 && errno == ESRCH) return true;
  if (!lockable) return false;
  // The pid runs: a reused one (another container's, after a restart) if nobody holds
  // the temporary's lock and it has not changed for a while.
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0 || ::time(nullptr) - st.st_mtime < kStaleAfterSeconds) {
    return false;
  }
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
  if (fd < 0) return false;
  const bool free = ::flock(fd, LOCK_EX | LOCK_NB) == 0;
  ::close(fd);
  return free;
}

void RemoveTree(const std::string& path) {
  std::error_code ec;
  std::filesystem::remove_all(path, ec);
}

}  // namespace

namespace {

// The temporaries this process named (TemporaryNameFor), for RemoveTemporariesOnSignal:
// a ring of fixed slots (no allocation in a signal handler). A name stays after its file
// is renamed into place: unlinking it then finds nothing, and a temporary's name is never
// a result's. The oldest names give way first; they are long done.
constexpr int kTemporarySlots = 64;
constexpr size_t kTemporaryPathBytes = 4096;
struct TemporarySlot {
  std::atomic<bool> ready{false};
  char path[kTemporaryPathBytes];
};
TemporarySlot g_temporaries[kTemporarySlots];
std::atomic<unsigned> g_next_temporary{0};

void RegisterTemporary(const std::string& path) {
  if (path.size() >= kTemporaryPathBytes) return;
  TemporarySlot& slot = g_temporaries[g_next_temporary.fetch_add(1) % kTemporarySlots];
  slot.ready.store(false);
  std::memcpy(slot.path, path.c_str(), path.size() + 1);
  slot.ready.store(true);
}

}  // namespace

std::string TemporaryNameFor(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  const std::string name =
      path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter.fetch_add(1));
  RegisterTemporary(name);
  return name;
}

namespace {

// Staging directories (RegisterTemporaryDirectory), the same way.
constexpr int kDirectorySlots = 8;
TemporarySlot g_directories[kDirectorySlots];
std::atomic<unsigned> g_next_directory{0};

// Empties the directory open as `fd` with system calls only (getdents64, openat,
// unlinkat: no allocation, no lock), its subdirectories too down to kSignalDepth levels (a
// new track's staging directory holds windows/ and folds/: issue 37). A few passes, since
// removing entries while listing may skip some. Closes fd.
constexpr int kSignalDepth = 3;
void EmptyDirectoryOnSignal(int fd, int depth) {
  static char buffers[kSignalDepth][8192];  // one per level: a level's listing survives
  char* buffer = buffers[depth];
  for (int pass = 0; pass < 4; ++pass) {
    bool removed = false;
    long n = 0;
    ::lseek(fd, 0, SEEK_SET);
    while ((n = ::syscall(SYS_getdents64, fd, buffer, sizeof(buffers[0]))) > 0) {
      for (long at = 0; at < n;) {
        // struct linux_dirent64: ino (8), off (8), reclen (2), type (1), name.
        unsigned short reclen = 0;
        std::memcpy(&reclen, buffer + at + 16, sizeof(reclen));
        const char* name = buffer + at + 19;
        at += reclen;
        const bool dots = name[0] == '.' && (name[1] == 0 || (name[1] == '.' && name[2] == 0));
        if (dots) continue;
        if (::unlinkat(fd, name, 0) == 0) {
          removed = true;
          continue;
        }
        if (depth + 1 < kSignalDepth) {
          const int sub = ::openat(fd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
          if (sub >= 0) EmptyDirectoryOnSignal(sub, depth + 1);
        }
        if (::unlinkat(fd, name, AT_REMOVEDIR) == 0) removed = true;
      }
    }
    if (!removed) break;
  }
  ::close(fd);
}

void RemoveDirectoryOnSignal(const char* dir) {
  const int fd = ::open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;  // published or removed meanwhile
  EmptyDirectoryOnSignal(fd, 0);
  ::rmdir(dir);
}

}  // namespace

void RegisterTemporaryDirectory(const std::string& dir) {
  if (dir.size() >= kTemporaryPathBytes) return;
  TemporarySlot& slot = g_directories[g_next_directory.fetch_add(1) % kDirectorySlots];
  slot.ready.store(false);
  std::memcpy(slot.path, dir.c_str(), dir.size() + 1);
  slot.ready.store(true);
}

void RemoveTemporariesOnSignal() {
  for (TemporarySlot& slot : g_temporaries) {
    if (slot.ready.load()) ::unlink(slot.path);  // async-signal-safe
  }
  for (TemporarySlot& slot : g_directories) {
    if (slot.ready.load()) RemoveDirectoryOnSignal(slot.path);
  }
}

int RemoveStaleTemporaries(const std::string& path) {
  const std::string name = BaseName(path);
  if (name.empty() || name == "." || name == "..") return 0;
  const std::string dir = ParentDirectory(path);
  const std::string file_prefix = name + ".tmp.";
  const std::string dir_prefix = "." + name + ".tmp.";
  const std::string old_prefix = "." + name + ".old.";
  int removed = 0;
  DIR* listing = ::opendir(dir.c_str());
  if (listing == nullptr) return 0;
  std::vector<std::string> entries;
  while (const dirent* entry = ::readdir(listing)) entries.emplace_back(entry->d_name);
  ::closedir(listing);
  for (const std::string& entry : entries) {
    const std::string full = dir == "." ? entry : dir + "/" + entry;
    for (const std::string* prefix : {&file_prefix, &dir_prefix}) {
      if (entry.rfind(*prefix, 0) != 0) continue;
      const pid_t pid =
          PidOf(std::string_view(entry).substr(prefix->size()), prefix == &file_prefix);
      if (pid > 0 && MakerIsGone(full, pid, /*lockable=*/true)) {
        RemoveTree(full);
        ++removed;
      }
    }
    if (entry.rfind(old_prefix, 0) == 0) {
      // A previous result moved aside by a --force run killed before its new one was in
      // place: put it back if nothing took its place, else it was replaced.
      const pid_t pid = PidOf(std::string_view(entry).substr(old_prefix.size()), false);
      if (pid <= 0 || !MakerIsGone(full, pid, /*lockable=*/false)) continue;
      int err = 0;
      if (!RenameNoReplace(full, path, &err)) RemoveTree(full);
      ++removed;
    }
  }
  return removed;
}

bool RenameNoReplace(const std::string& from, const std::string& to, int* err) {
  if (::renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE) == 0) return true;
  *err = errno;
  if (*err != EINVAL && *err != ENOSYS) return false;
  struct stat st {};
  if (::lstat(from.c_str(), &st) != 0) {
    *err = errno;
    return false;
  }
  if (S_ISDIR(st.st_mode)) {
    // rename(2) of a directory refuses a non-empty target: results there are kept.
    if (::rename(from.c_str(), to.c_str()) == 0) return true;
    *err = errno == ENOTEMPTY ? EEXIST : errno;
    return false;
  }
  if (::link(from.c_str(), to.c_str()) != 0) {
    *err = errno;
    return false;
  }
  ::unlink(from.c_str());
  return true;
}

bool RenameExchange(const std::string& a, const std::string& b, int* err) {
  if (::renameat2(AT_FDCWD, a.c_str(), AT_FDCWD, b.c_str(), RENAME_EXCHANGE) == 0) return true;
  *err = errno;
  return false;
}

bool SyncDirectory(const std::string& dir, int* err) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) {
    *err = errno;
    return false;
  }
  // EINVAL: a file system that cannot sync a directory (nothing to make durable there).
  const bool ok = ::fsync(fd) == 0 || errno == EINVAL;
  if (!ok) *err = errno;
  ::close(fd);
  return ok;
}

bool PublishDirectory(const std::string& tmp, const std::string& target,
                      const std::function<bool(std::string*)>& may_replace, std::string* why) {
  namespace fs = std::filesystem;
  std::error_code ec;
  // rmdir refuses a target that another run has filled meanwhile.
  if (fs::is_directory(target, ec) && fs::is_empty(target, ec)) ::rmdir(target.c_str());
  int err = 0;
  if (RenameNoReplace(tmp, target, &err)) return true;
  if (err != EEXIST) {
    *why = std::string("cannot move the results into place: ") + std::strerror(err);
    return false;
  }
  if (!may_replace) {
    *why =
        "another run wrote its results there meanwhile (kept as they are); these results "
        "were not written: choose a new --out, or --force to replace";
    return false;
  }
  if (!may_replace(why)) return false;
  if (RenameExchange(tmp, target, &err)) {
    fs::remove_all(tmp, ec);  // now the previous results
    return true;
  }
  if (err != EINVAL && err != ENOSYS) {
    *why = std::string("cannot replace the previous results: ") + std::strerror(err);
    return false;
  }
  const fs::path to(target);
  const fs::path previous =
      to.parent_path() / ("." + to.filename().string() + ".old." + std::to_string(::getpid()));
  fs::remove_all(previous, ec);
  fs::rename(to, previous, ec);
  if (ec) {
    *why = "cannot move the previous results aside: " + ec.message();
    return false;
  }
  if (!RenameNoReplace(tmp, target, &err)) {
    fs::rename(previous, to, ec);
    *why = std::string("cannot move the results into place: ") + std::strerror(err);
    return false;
  }
  fs::remove_all(previous, ec);
  return true;
}

std::string ParentDirectory(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

std::FILE* OpenUnnamedFile(const std::string& dir, int* err) {
  int fd = ::open(dir.c_str(), O_TMPFILE | O_RDWR | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0 && (errno == EOPNOTSUPP || errno == EISDIR || errno == EINVAL)) {
    std::string name = dir + "/.fastcal-XXXXXX";
    fd = ::mkstemp(name.data());
    if (fd >= 0) ::unlink(name.c_str());
  }
  if (fd < 0) {
    *err = errno;
    return nullptr;
  }
  std::FILE* file = ::fdopen(fd, "w+b");
  if (file == nullptr) {
    *err = errno;
    ::close(fd);
  }
  return file;
}

void TemporaryLock::Lock(const std::string& path) {
  Release();
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd_ >= 0) ::flock(fd_, LOCK_EX | LOCK_NB);
}

void TemporaryLock::Release() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

bool AtomicFileWriter::Fail(const char* what, int err, std::string* error) {
  if (error != nullptr) *error = path_ + ": " + what + ": " + std::strerror(err);
  Abort();
  return false;
}

bool AtomicFileWriter::Open(const std::string& path, std::string* error) {
  Abort();
  path_ = path;
  RemoveStaleTemporaries(path);
  temp_path_ = TemporaryNameFor(path);
  fd_ = ::open(temp_path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd_ < 0) {
    const int err = errno;
    temp_path_.clear();
    return Fail("cannot write", err, error);
  }
  ::flock(fd_, LOCK_EX | LOCK_NB);  // in use: RemoveStaleTemporaries leaves it
  return true;
}

bool AtomicFileWriter::Flush(std::string* error) {
  size_t written = 0;
  while (written < buffer_.size()) {
    const ssize_t n = ::write(fd_, buffer_.data() + written, buffer_.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return Fail("cannot write", errno, error);
    written += static_cast<size_t>(n);
  }
  buffer_.clear();
  return true;
}

bool AtomicFileWriter::Write(std::string_view data, std::string* error) {
  if (fd_ < 0) return Fail("cannot write", EBADF, error);
  constexpr size_t kFlushBytes = 1 << 20;
  buffer_.append(data);
  return buffer_.size() < kFlushBytes || Flush(error);
}

bool AtomicFileWriter::Sync(std::string* error) {
  if (fd_ < 0) return Fail("cannot write", EBADF, error);
  if (!Flush(error)) return false;
  if (::fsync(fd_) != 0) return Fail("cannot write", errno, error);
  return true;
}

bool AtomicFileWriter::Commit(bool replace, std::string* error) {
  if (!Sync(error)) return false;
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) return Fail("cannot write", errno, error);
  int err = 0;
  if (replace ? ::rename(temp_path_.c_str(), path_.c_str()) != 0
              : !RenameNoReplace(temp_path_, path_, &err)) {
    if (replace) err = errno;
    return Fail(err == EEXIST ? "exists (made by another process meanwhile); not replaced"
                              : "cannot replace",
                err, error);
  }
  temp_path_.clear();
  if (!SyncDirectory(ParentDirectory(path_), &err)) return Fail("cannot write", err, error);
  return true;
}

void AtomicFileWriter::Abort() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  if (!temp_path_.empty()) ::unlink(temp_path_.c_str());
  temp_path_.clear();
  buffer_.clear();
}

bool WriteFileAtomically(const std::string& path, const std::string& content, std::string* error,
                         bool replace) {
  AtomicFileWriter writer;
  return writer.Open(path, error) && writer.Write(content, error) && writer.Commit(replace, error);
}

namespace {

// "1 GiB", "16 MiB", "100 bytes": a limit as docs/data-format.md states it.
std::string ByteCount(long long bytes) {
  const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB"};
  int unit = 0;
  long long whole = bytes;
  while (unit < 4 && whole >= 1024 && whole % 1024 == 0) {
    whole /= 1024;
    ++unit;
  }
  return std::to_string(whole) + " " + units[unit];
}

}  // namespace

RegularFileReader::~RegularFileReader() {
  if (fd_ >= 0) ::close(fd_);
}

bool RegularFileReader::Fail(const std::string& why, std::string* error) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  gzip_.reset();
  *error = name_ + ": " + why;
  return false;
}

bool RegularFileReader::Open(const std::string& path, long long max_bytes, const std::string& what,
                             std::string* error) {
  name_ = Escape(path);
  max_bytes_ = max_bytes;
  read_bytes_ = 0;
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd_ < 0) {
    *error = name_ + ": cannot open: " + std::strerror(errno);
    return false;
  }
  struct stat st {};
  if (::fstat(fd_, &st) != 0)
    return Fail(std::string("cannot read: ") + std::strerror(errno), error);
  const std::string a = !what.empty() && std::strchr("aeiou", what[0]) != nullptr ? "an " : "a ";
  if (S_ISDIR(st.st_mode)) return Fail("is a directory, not " + a + what + " file", error);
  if (!S_ISREG(st.st_mode)) {
    return Fail("not a regular file (a device, pipe or socket): " + a + what +
                    " file must be a regular file",
                error);
  }
  too_large_ = "larger than the limit for a " + what + " file, " + ByteCount(max_bytes) +
               " (docs/data-format.md, \"Limits\")";
  size_ = static_cast<long long>(st.st_size);
  if (st.st_size > max_bytes) {
    return Fail(std::to_string(static_cast<long long>(st.st_size)) + " bytes is " + too_large_,
                error);
  }
  return StartGzipIfCompressed(error);
}

bool RegularFileReader::Read(size_t max, std::string* text, bool* end, std::string* error) {
  if (gzip_ != nullptr) return ReadGzip(max, text, end, error);
  *end = fd_ < 0;
  char buffer[1 << 16];
  for (size_t got = 0; fd_ >= 0 && got < max;) {
    const ssize_t n = ::read(fd_, buffer, std::min(sizeof(buffer), max - got));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return Fail(std::string("cannot read: ") + std::strerror(errno), error);
    if (n == 0) {
      ::close(fd_);
      fd_ = -1;
      *end = true;
      break;
    }
    if (read_bytes_ + n > max_bytes_) return Fail("grew while being read: " + too_large_, error);
    read_bytes_ += n;
    got += static_cast<size_t>(n);
    text->append(buffer, static_cast<size_t>(n));
  }
  return true;
}

bool ReadRegularFile(const std::string& path, long long max_bytes, const std::string& what,
                     std::string* text, std::string* error) {
  RegularFileReader reader;
  if (!reader.Open(path, max_bytes, what, error)) return false;
  std::string contents;
  // One allocation of the file's size: growing by doubling would peak at twice it (a
  // 250 MB dataset of 10^6 samples read whole by calibrate).
  contents.reserve(static_cast<size_t>(reader.size()));
  for (bool end = false; !end;) {
    if (!reader.Read(static_cast<size_t>(1) << 20, &contents, &end, error)) return false;
  }
  *text = std::move(contents);
  return true;
}

bool ReadFileChunks(const std::string& path, const std::function<void(const char*, size_t)>& sink,
                    std::string* error) {
  // The reader's checks first: a device (/dev/zero) would never end (issue 29: calibrate
  // --data=/dev/zero hashed it on a thread of its own, and never exited).
  RegularFileReader reader;
  if (!reader.Open(path, std::numeric_limits<long long>::max(), "input", error)) return false;
  std::string chunk;
  for (bool end = false; !end;) {
    chunk.clear();
    if (!reader.Read(static_cast<size_t>(1) << 16, &chunk, &end, error)) return false;
    if (!chunk.empty()) sink(chunk.data(), chunk.size());
  }
  return true;
}

}  // namespace fastcal::internal
