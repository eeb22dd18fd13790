// Exact order statistics by passes (internal/exact_selection.h).
#include "fastcal/internal/exact_selection.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fastcal::internal {

ExactSelection::ExactSelection(std::vector<std::pair<int, long long>> targets) {
  for (const auto& [stream, rank] : targets) {
    Target t;
    t.stream = stream;
    t.rank = rank;
    if (by_stream_.size() <= static_cast<size_t>(stream)) by_stream_.resize(stream + 1);
    by_stream_[stream].push_back(targets_.size());
    targets_.push_back(std::move(t));
  }
}

bool ExactSelection::done() const {
  return std::all_of(targets_.begin(), targets_.end(), [](const Target& t) { return t.done; });
}

int ExactSelection::BinOf(const Level& level, double value) {
  const double b = std::floor((value - level.min) / level.width);
  return static_cast<int>(std::clamp(b, 0.0, static_cast<double>(kBins - 1)));
}

bool ExactSelection::InRange(const Target& t, double value) {
  // While binning, the last level is the one being binned: its bin is not chosen yet.
  const size_t levels = t.levels.size() - (t.binning ? 1 : 0);
  for (size_t l = 0; l < levels; ++l) {
    const Level& level = t.levels[l];
    if (value < level.min || BinOf(level, value) != level.bin) return false;
  }
  return true;
}

void ExactSelection::Begin() {
  for (Target& t : targets_) {
    t.count = 0;
    t.min = std::numeric_limits<double>::infinity();
    t.max = -t.min;
    t.kept.clear();
    if (t.binning) t.bins.assign(kBins, 0);
  }
}

void ExactSelection::Add(int stream, double value) {
  if (stream < 0 || static_cast<size_t>(stream) >= by_stream_.size()) return;
  for (size_t k : by_stream_[stream]) {
    Target& t = targets_[k];
    if (t.done || !InRange(t, value)) continue;
    if (t.binning) {
      ++t.bins[BinOf(t.levels.back(), value)];
      continue;
    }
    ++t.count;
    t.min = std::min(t.min, value);
    t.max = std::max(t.max, value);
    if (t.kept.size() < kMaxKept) t.kept.push_back(value);
  }
}

void ExactSelection::End() {
  for (Target& t : targets_) {
    if (t.done) continue;
    const long long rank = t.rank - t.below;
    if (t.binning) {
      // Narrow the range to the bin that holds the rank.
      long long before = 0;
      int b = 0;
      while (b < kBins - 1 && before + t.bins[b] <= rank) before += t.bins[b++];
      t.below += before;
      t.levels.back().bin = b;
      t.binning = false;
      t.bins.clear();
      continue;
    }
    if (rank < 0 || rank >= t.count) {  // no such rank (or an empty stream)
      t.result = std::numeric_limits<double>::quiet_NaN();
      t.done = true;
    } else if (t.count <= static_cast<long long>(kMaxKept)) {
      std::nth_element(t.kept.begin(), t.kept.begin() + rank, t.kept.end());
      t.result = t.kept[rank];
      t.done = true;
    } else if (t.min == t.max) {
      t.result = t.min;
      t.done = true;
    } else {
      // (max - min) / kBins underflows only for a subnormal range: then two bins.
      const double width = (t.max - t.min) / kBins;
      t.levels.push_back({t.min, width > 0.0 ? width : t.max - t.min, 0});
      t.binning = true;
    }
    t.kept.clear();
    t.kept.shrink_to_fit();
  }
}

}  // namespace fastcal::internal
