// Atomic file writes (internal/atomic_file.h).
#include "fastcal/internal/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

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

bool ReadTextFile(const std::string& path, std::string* text, std::string* error) {
  std::string ignored;
  if (error == nullptr) error = &ignored;
  try {
    std::error_code ec;
    std::ifstream in(path, std::ios::binary);
    if (!in || std::filesystem::is_directory(path, ec)) {
      *error = path + ": cannot open";
      return false;
    }
    std::ostringstream contents;
    contents << in.rdbuf();
    if (in.bad()) {
      *error = path + ": cannot read";
      return false;
    }
    *text = contents.str();
  } catch (const std::exception& e) {
    *error = path + ": cannot read: " + e.what();
    return false;
  }
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
