// A track's per-window sample files (internal/window_store.h).
#include "fastcal/internal/window_store.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

namespace fastcal::internal {
namespace {

bool Fail(const std::string& path, const std::string& what, std::string* error) {
  *error = path + ": " + what;
  return false;
}

bool IsFinite(const StoredSample& s) {
  bool ok = std::isfinite(s.time_s);
  for (double v : s.position_m) ok = ok && std::isfinite(v);
  for (double v : s.rotation) ok = ok && std::isfinite(v);
  for (double v : s.tension_n) ok = ok && std::isfinite(v);
  return ok;
}

// Reads up to `bytes` at `offset`, fewer only at the end of the file (pread may return
// part of a request). -1 on an error.
long long ReadAt(int fd, void* into, long long bytes, long long offset) {
  long long done = 0;
  while (done < bytes) {
    const ssize_t got = ::pread(fd, static_cast<char*>(into) + done, bytes - done, offset + done);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) return -1;
    if (got == 0) break;
    done += got;
  }
  return done;
}

}  // namespace

StoredSample ToStored(const Sample& sample, int file, bool planned) {
  StoredSample s{};
  s.time_s = sample.time_s;
  s.line = sample.line;
  s.file = file;
  const Eigen::Matrix3d& r = planned ? sample.planned_rotation : sample.pose.rotation;
  for (int k = 0; k < 3; ++k) s.position_m[k] = sample.pose.position_m[k];
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) s.rotation[3 * row + col] = r(row, col);
  }
  for (int i = 0; i < kNumCables; ++i) s.tension_n[i] = sample.tension_n[i];
  return s;
}

bool AppendStoredSamples(const std::string& path, const std::vector<StoredSample>& samples,
                         std::string* error) {
  std::FILE* file = std::fopen(path.c_str(), "ab");
  if (file == nullptr) return Fail(path, std::strerror(errno), error);
  const size_t written = std::fwrite(samples.data(), sizeof(StoredSample), samples.size(), file);
  const bool closed = std::fclose(file) == 0;
  if (written != samples.size() || !closed) return Fail(path, "cannot write the samples", error);
  return true;
}

StoredWindowReader::~StoredWindowReader() {
  if (fd_ >= 0) ::close(fd_);
}

bool StoredWindowReader::Open(const std::string& path, std::string* error) {
  path_ = path;
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) return Fail(path, std::strerror(errno), error);
  // One pass: every record checked, and whether the times ever go back.
  std::vector<StoredSample> buffer(4096);
  bool in_order = true;
  double last_s = -std::numeric_limits<double>::infinity();
  size_ = 0;
  for (;;) {
    const long long got = ReadAt(fd_, buffer.data(), buffer.size() * sizeof(StoredSample),
                                 size_ * sizeof(StoredSample));
    if (got < 0) return Fail(path, std::strerror(errno), error);
    if (got == 0) break;
    if (got % static_cast<long long>(sizeof(StoredSample)) != 0) {
      return Fail(path, "not a whole number of 160-byte sample records (truncated?)", error);
    }
    for (long long k = 0; k < got / static_cast<long long>(sizeof(StoredSample)); ++k) {
      if (!IsFinite(buffer[k])) {
        return Fail(path, "record " + std::to_string(size_ + k) + " is not finite", error);
      }
      in_order = in_order && buffer[k].time_s >= last_s;
      last_s = buffer[k].time_s;
    }
    size_ += got / static_cast<long long>(sizeof(StoredSample));
  }
  if (in_order) return true;
  sorted_.resize(size_);
  const long long bytes = size_ * static_cast<long long>(sizeof(StoredSample));
  if (ReadAt(fd_, sorted_.data(), bytes, 0) != bytes) {
    return Fail(path, "cannot read the samples", error);
  }
  std::stable_sort(
      sorted_.begin(), sorted_.end(),
      [](const StoredSample& a, const StoredSample& b) { return a.time_s < b.time_s; });
  return true;
}

bool StoredWindowReader::Read(long long first, int count, std::vector<Sample>* samples,
                              std::vector<int>* file_of, std::string* error) const {
  if (first < 0 || count < 0 || first + count > size_) {
    return Fail(path_,
                "records " + std::to_string(first) + " to " + std::to_string(first + count) +
                    " of " + std::to_string(size_),
                error);
  }
  std::vector<StoredSample> own;
  const StoredSample* records = sorted_.data() + first;
  if (sorted_.empty()) {
    own.resize(count);
    const long long bytes = count * static_cast<long long>(sizeof(StoredSample));
    if (ReadAt(fd_, own.data(), bytes, first * static_cast<long long>(sizeof(StoredSample))) !=
        bytes) {
      return Fail(path_, "cannot read the samples", error);
    }
    records = own.data();
  }
  samples->assign(count, Sample());
  file_of->assign(count, 0);
  for (int k = 0; k < count; ++k) {
    const StoredSample& r = records[k];
    Sample& s = (*samples)[k];
    s.time_s = r.time_s;
    s.line = r.line;
    s.pose.position_m = Eigen::Vector3d(r.position_m[0], r.position_m[1], r.position_m[2]);
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) s.pose.rotation(row, col) = r.rotation[3 * row + col];
    }
    for (int i = 0; i < kNumCables; ++i) s.tension_n[i] = r.tension_n[i];
    (*file_of)[k] = r.file;
  }
  return true;
}

bool ReadStoredWindow(const std::string& path, Dataset* data, std::vector<int>* file_of,
                      std::string* error) {
  StoredWindowReader reader;
  if (!reader.Open(path, error)) return false;
  if (!reader.Read(0, static_cast<int>(reader.size()), &data->samples, file_of, error)) {
    return false;
  }
  data->path = path;
  return true;
}

}  // namespace fastcal::internal
