// A track's per-window sample files (internal/window_store.h).
#include "fastcal/internal/window_store.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>

namespace fastcal::internal {
namespace {

bool Fail(const std::string& path, const std::string& what, std::string* error) {
  *error = path + ": " + what;
  return false;
}

// The records of `bytes` (whole records of `record` bytes each) into *out.
void Unpack(const std::vector<char>& bytes, long long count, long long record, StoredSample* out) {
  for (long long k = 0; k < count; ++k) {
    out[k] = StoredSample{};
    std::memcpy(&out[k], bytes.data() + k * record, static_cast<size_t>(record));
  }
}

// Every value of a record is a double but its line and file (two int32 at offset 8): a
// record's doubles are its 8-byte words but the second.
static_assert(offsetof(StoredSample, time_s) == 0 && offsetof(StoredSample, line) == 8 &&
                  offsetof(StoredSample, file) == 12 && offsetof(StoredSample, position_m) == 16,
              "the store's record layout: doubles but the word at offset 8");

// Whether the double at `at` is finite (its exponent not all ones), from its bits.
bool FiniteAt(const char* at) {
  constexpr std::uint64_t kExponent = 0x7ff0000000000000ULL;
  std::uint64_t bits;
  std::memcpy(&bits, at, sizeof(bits));
  return (bits & kExponent) != kExponent;
}

// Open's check of `count` records of `record` bytes read whole: the first that holds a
// value that is not finite (-1: none), and whether the times, from *last_s on, never go
// back (*last_s then the last time). On the raw bytes: the check read every record of
// every fold's window into a StoredSample first, a tenth of a subsample's fold.
long long CheckRecords(const char* bytes, long long count, long long record, double* last_s,
                       bool* in_order) {
  const long long words = record / 8;
  for (long long k = 0; k < count; ++k) {
    const char* r = bytes + k * record;
    bool finite = true;
    for (long long w = 0; w < words; ++w) finite &= w == 1 || FiniteAt(r + 8 * w);
    if (!finite) return k;
    double time_s;
    std::memcpy(&time_s, r, sizeof(time_s));
    *in_order = *in_order && time_s >= *last_s;
    *last_s = time_s;
  }
  return -1;
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
  for (int j = 0; j < kMaxJoints; ++j) s.joint[j] = sample.joint[j];
  return s;
}

bool AppendStoredSamples(const std::string& path, const std::vector<StoredSample>& samples,
                         int joints, std::string* error) {
  const long long record = RecordBytes(joints);
  std::vector<char> bytes(samples.size() * record);
  for (size_t k = 0; k < samples.size(); ++k) {
    std::memcpy(bytes.data() + k * record, &samples[k], static_cast<size_t>(record));
  }
  std::FILE* file = std::fopen(path.c_str(), "ab");
  if (file == nullptr) return Fail(path, std::strerror(errno), error);
  const size_t written =
      std::fwrite(bytes.data(), static_cast<size_t>(record), samples.size(), file);
  const bool closed = std::fclose(file) == 0;
  if (written != samples.size() || !closed) return Fail(path, "cannot write the samples", error);
  return true;
}

StoredWindowReader::~StoredWindowReader() {
  if (fd_ >= 0) ::close(fd_);
}

bool StoredWindowReader::Open(const std::string& path, int joints, std::string* error) {
  path_ = path;
  joints_ = joints;
  const long long record = RecordBytes(joints);
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) return Fail(path, std::strerror(errno), error);
  // One pass: every record checked, and whether the times ever go back.
  constexpr long long kChunkRecords = 4096;
  std::vector<char> bytes(kChunkRecords * record);
  bool in_order = true;
  double last_s = -std::numeric_limits<double>::infinity();
  size_ = 0;
  for (;;) {
    const long long got = ReadAt(fd_, bytes.data(), kChunkRecords * record, size_ * record);
    if (got < 0) return Fail(path, std::strerror(errno), error);
    if (got == 0) break;
    if (got % record != 0) {
      return Fail(path,
                  "not a whole number of " + std::to_string(record) +
                      "-byte sample records (truncated, or stored for a model with another "
                      "number of moving-part joints?)",
                  error);
    }
    const long long bad = CheckRecords(bytes.data(), got / record, record, &last_s, &in_order);
    if (bad >= 0) {
      return Fail(path, "record " + std::to_string(size_ + bad) + " is not finite", error);
    }
    size_ += got / record;
  }
  if (in_order) return true;
  sorted_.resize(size_);
  bytes.resize(size_ * record);
  if (ReadAt(fd_, bytes.data(), size_ * record, 0) != size_ * record) {
    return Fail(path, "cannot read the samples", error);
  }
  Unpack(bytes, size_, record, sorted_.data());
  std::stable_sort(
      sorted_.begin(), sorted_.end(),
      [](const StoredSample& a, const StoredSample& b) { return a.time_s < b.time_s; });
  return true;
}

bool StoredWindowReader::Read(long long first, int count, std::vector<Sample>* samples,
                              std::vector<int>* file_of, std::string* error) const {
  return ReadEvery(first, count, 1, samples, file_of, error);
}

bool StoredWindowReader::ReadEvery(long long first, int count, int step,
                                   std::vector<Sample>* samples, std::vector<int>* file_of,
                                   std::string* error) const {
  const long long span = count > 0 ? static_cast<long long>(count - 1) * step + 1 : 0;
  if (first < 0 || count < 0 || step < 1 || first + span > size_) {
    return Fail(path_,
                "records " + std::to_string(first) + " to " + std::to_string(first + span) +
                    " of " + std::to_string(size_),
                error);
  }
  // Unsorted, the range is read at once into a buffer kept by the thread: a new vector
  // for each range was zeroed before the read filled it, as many bytes again as the read
  // (a pass over 10^7 samples reads 1.6 GB; so does a subsample's round, its strides
  // spanning every window; issue 41).
  thread_local std::vector<char> buffer;
  const long long record = RecordBytes(joints_);
  // A fold's ranges span at most a few MB; a larger one (a whole window read at once) is
  // not kept after it.
  constexpr long long kKeptBufferBytes = 16LL << 20;
  struct Release {
    std::vector<char>& buffer;
    ~Release() {
      if (static_cast<long long>(buffer.size()) > kKeptBufferBytes)
        std::vector<char>().swap(buffer);
    }
  } release{buffer};
  if (sorted_.empty()) {
    if (static_cast<long long>(buffer.size()) < span * record) buffer.resize(span * record);
    if (ReadAt(fd_, buffer.data(), span * record, first * record) != span * record) {
      return Fail(path_, "cannot read the samples", error);
    }
  }
  const auto record_at = [&](int k) {
    if (!sorted_.empty()) return sorted_[first + static_cast<long long>(k) * step];
    StoredSample r{};
    std::memcpy(&r, buffer.data() + static_cast<long long>(k) * step * record,
                static_cast<size_t>(record));
    return r;
  };
  samples->assign(count, Sample());
  file_of->assign(count, 0);
  for (int k = 0; k < count; ++k) {
    const StoredSample r = record_at(k);
    Sample& s = (*samples)[k];
    s.time_s = r.time_s;
    s.line = r.line;
    s.pose.position_m = Eigen::Vector3d(r.position_m[0], r.position_m[1], r.position_m[2]);
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) s.pose.rotation(row, col) = r.rotation[3 * row + col];
    }
    for (int i = 0; i < kNumCables; ++i) s.tension_n[i] = r.tension_n[i];
    for (int j = 0; j < joints_; ++j) s.joint[j] = r.joint[j];
    (*file_of)[k] = r.file;
  }
  return true;
}

bool ReadStoredWindow(const std::string& path, int joints, Dataset* data, std::vector<int>* file_of,
                      std::string* error) {
  StoredWindowReader reader;
  if (!reader.Open(path, joints, error)) return false;
  if (!reader.Read(0, static_cast<int>(reader.size()), &data->samples, file_of, error)) {
    return false;
  }
  data->path = path;
  return true;
}

}  // namespace fastcal::internal
