// A track's per-window sample files (internal/window_store.h).
#include "fastcal/internal/window_store.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numeric>

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

bool ReadStoredWindow(const std::string& path, Dataset* data, std::vector<int>* file_of,
                      std::string* error) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return Fail(path, std::strerror(errno), error);
  std::vector<StoredSample> records;
  StoredSample buffer[4096];
  size_t got = 0;
  while ((got = std::fread(buffer, 1, sizeof(buffer), file)) > 0) {
    if (got % sizeof(StoredSample) != 0) {
      std::fclose(file);
      return Fail(path, "not a whole number of 160-byte sample records (truncated?)", error);
    }
    records.insert(records.end(), buffer, buffer + got / sizeof(StoredSample));
  }
  const bool failed = std::ferror(file) != 0;
  std::fclose(file);
  if (failed) return Fail(path, "cannot read the samples", error);
  std::vector<size_t> order(records.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return records[a].time_s < records[b].time_s; });
  data->samples.assign(records.size(), Sample());
  file_of->assign(records.size(), 0);
  for (size_t k = 0; k < order.size(); ++k) {
    const StoredSample& r = records[order[k]];
    if (!IsFinite(r))
      return Fail(path, "record " + std::to_string(order[k]) + " is not finite", error);
    Sample& s = data->samples[k];
    s.time_s = r.time_s;
    s.line = r.line;
    s.pose.position_m = Eigen::Vector3d(r.position_m[0], r.position_m[1], r.position_m[2]);
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) s.pose.rotation(row, col) = r.rotation[3 * row + col];
    }
    for (int i = 0; i < kNumCables; ++i) s.tension_n[i] = r.tension_n[i];
    (*file_of)[k] = r.file;
  }
  data->path = path;
  return true;
}

}  // namespace fastcal::internal
