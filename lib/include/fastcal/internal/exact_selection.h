// Exact order statistics of value streams too long to hold (evaluation_stream.h: the
// medians of a million-sample evaluation's residuals), by passes over the values.
//
// For each target (stream s, rank k) the values still in play form a range, nested
// bins of successive histograms. A pass either counts the values in the range and keeps
// them while at most kMaxKept are there (then nth_element gives the k-th: exact), or bins
// the range into kBins equal bins over its [min, max] and narrows it to the bin holding
// rank k - (values below the range). Each narrowing divides the range by kBins, so a
// million doubles take 3 to 4 passes; equal values end it at once (min == max).
#ifndef FASTCAL_INTERNAL_EXACT_SELECTION_H_
#define FASTCAL_INTERNAL_EXACT_SELECTION_H_

#include <cstddef>
#include <utility>
#include <vector>

namespace fastcal::internal {

// The k-th smallest values (0-based rank) of several streams of values, exactly, in
// memory independent of their length: the caller feeds every value of every stream in
// each pass (Begin, Add..., End) until done(). A pass either counts and, when at most
// kMaxKept values are left in the target's range, keeps them (then sorts: done), or
// bins the range into kBins bins and narrows it to the bin holding the rank.
class ExactSelection {
 public:
  static constexpr int kBins = 4096;
  static constexpr size_t kMaxKept = 65536;
  // targets[t] = {stream, rank}; a rank outside [0, count of the stream) gives NaN.
  explicit ExactSelection(std::vector<std::pair<int, long long>> targets);
  bool done() const;
  void Begin();
  void Add(int stream, double value);
  void End();
  double Result(size_t target) const { return targets_[target].result; }

 private:
  struct Level {
    double min = 0.0, width = 0.0;
    int bin = 0;
  };
  struct Target {
    int stream = 0;
    long long rank = 0;
    bool done = false;
    double result = 0.0;
    std::vector<Level> levels;  // the range: the values in bin `bin` of every level
    long long below = 0;        // values below the range
    bool binning = false;       // this pass bins (else counts and keeps)
    long long count = 0;
    double min = 0.0, max = 0.0;
    std::vector<double> kept;
    std::vector<long long> bins;
  };
  static int BinOf(const Level& level, double value);
  static bool InRange(const Target& t, double value);
  std::vector<Target> targets_;
  std::vector<std::vector<size_t>> by_stream_;  // targets of each stream
};

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_EXACT_SELECTION_H_
