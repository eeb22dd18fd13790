// Atomic file writes (internal/atomic_file.h).
#include "fastcal/internal/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "fastcal/internal/quote.h"

namespace fastcal::internal {

// Writes `content` to a new temporary file beside `path`, then renames it over `path`.
bool WriteFileAtomically(const std::string& path, const std::string& content, std::string* error) {
  std::string ignored;
  if (error == nullptr) error = &ignored;
  static std::atomic<unsigned> counter{0};
  const std::string temp_path =
      path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter.fetch_add(1));
  const int fd = ::open(temp_path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) {
    *error = path + ": cannot write: " + std::strerror(errno);
    return false;
  }
  const auto fail = [&](const char* what, int err) {
    *error = path + ": " + what + ": " + std::strerror(err);
    ::unlink(temp_path.c_str());
    return false;
  };
  size_t written = 0;
  while (written < content.size()) {
    const ssize_t n = ::write(fd, content.data() + written, content.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      return fail("cannot write", err);
    }
    written += static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    return fail("cannot write", err);
  }
  if (::close(fd) != 0) return fail("cannot write", errno);
  if (std::rename(temp_path.c_str(), path.c_str()) != 0) return fail("cannot replace", errno);
  return true;
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
  if (S_ISDIR(st.st_mode)) return Fail("is a directory, not a " + what + " file", error);
  if (!S_ISREG(st.st_mode)) {
    return Fail(
        "not a regular file (a device, pipe or socket): a " + what + " file must be a regular file",
        error);
  }
  too_large_ = "larger than the limit for a " + what + " file, " + ByteCount(max_bytes) +
               " (docs/data-format.md, \"Limits\")";
  size_ = static_cast<long long>(st.st_size);
  if (st.st_size > max_bytes) {
    return Fail(std::to_string(static_cast<long long>(st.st_size)) + " bytes is " + too_large_,
                error);
  }
  return true;
}

bool RegularFileReader::Read(size_t max, std::string* text, bool* end, std::string* error) {
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
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    *error = path + ": cannot open: " + std::strerror(errno);
    return false;
  }
  char buffer[1 << 16];
  while (true) {
    const size_t n = std::fread(buffer, 1, sizeof(buffer), file);
    if (n > 0) sink(buffer, n);
    if (n < sizeof(buffer)) break;
  }
  const bool failed = std::ferror(file) != 0;
  const int read_errno = errno;
  std::fclose(file);
  if (failed) {
    *error = path + ": cannot read: " + std::strerror(read_errno);
    return false;
  }
  return true;
}

}  // namespace fastcal::internal
