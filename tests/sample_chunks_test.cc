// The chunked passes over samples (internal/sample_chunks.h) when the system refuses
// threads or the work throws (issue 29, item 3): the work still completes with the same
// bits on fewer threads, and an exception reaches the caller instead of std::terminate.
#include "fastcal/internal/sample_chunks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <new>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace fastcal::internal {
namespace {

// Items and chunk size: several chunks per thread, so that the order of merging matters.
constexpr int kItems = 10000;
constexpr int kChunk = 97;
constexpr int kThreads = 4;

// A ThreadStarter that starts `allowed` threads, then refuses as the system does under a
// process limit (std::thread throws std::system_error with EAGAIN).
ThreadStarter RefuseAfter(int allowed, std::atomic<int>* started) {
  return [allowed, started](std::function<void()> body) {
    if (started->load() >= allowed) {
      throw std::system_error(EAGAIN, std::generic_category(), "Resource temporarily unavailable");
    }
    ++*started;
    return std::thread(std::move(body));
  };
}

// Terms whose floating-point sum depends on the order of addition.
double Term(int i) { return std::sin(0.37 * i) * std::pow(10.0, (i % 17) - 8); }

double SumOnThreads(int threads, const ThreadStarter& start) {
  double total = 0.0;
  const int failed = ReduceChunks<double>(
      kItems, threads, [] { return 0.0; },
      [](int begin, int end, double* local) {
        for (int i = begin; i < end; ++i) *local += Term(i);
        return -1;
      },
      [&total](double local) { total += local; }, kChunk, start);
  EXPECT_EQ(failed, -1);
  return total;
}

TEST(SampleChunksTest, RefusedThreadsFallBackToTheThreadsThatStarted) {
  for (int allowed = 0; allowed < kThreads; ++allowed) {
    std::atomic<int> started{0};
    const int ran = OnThreads(
        kThreads, [&](int) {}, RefuseAfter(allowed, &started));
    EXPECT_EQ(ran, allowed + 1) << "the calling thread plus the started ones";
  }
}

TEST(SampleChunksTest, EveryItemIsDoneWhenThreadsAreRefused) {
  for (int allowed = 0; allowed < kThreads; ++allowed) {
    std::atomic<int> started{0};
    std::vector<int> done(kItems, 0);
    const int failed = ForEachChunk(
        kItems, kThreads,
        [&done](int begin, int end) {
          for (int i = begin; i < end; ++i) ++done[i];
          return -1;
        },
        kChunk, RefuseAfter(allowed, &started));
    EXPECT_EQ(failed, -1);
    EXPECT_EQ(std::count(done.begin(), done.end(), 1), kItems) << allowed << " threads allowed";
  }
}

TEST(SampleChunksTest, SumsKeepTheirBitsWhenThreadsAreRefused) {
  const double one_thread = SumOnThreads(1, nullptr);
  for (int allowed = 0; allowed < kThreads; ++allowed) {
    std::atomic<int> started{0};
    EXPECT_EQ(SumOnThreads(kThreads, RefuseAfter(allowed, &started)), one_thread)
        << allowed << " threads allowed";
  }
}

TEST(SampleChunksTest, AnExceptionInTheWorkReachesTheCaller) {
  // Thrown by the chunk of item 5000, whichever thread takes it; the others must neither
  // hang waiting for its merge nor end the process.
  const auto throwing = [](int begin, int end) {
    if (begin <= 5000 && 5000 < end) throw std::bad_alloc();
    return -1;
  };
  EXPECT_THROW(ForEachChunk(kItems, kThreads, throwing, kChunk), std::bad_alloc);
  EXPECT_THROW(ReduceChunks<double>(
                   kItems, kThreads, [] { return 0.0; },
                   [&throwing](int begin, int end, double*) { return throwing(begin, end); },
                   [](double) {}, kChunk),
               std::bad_alloc);
  EXPECT_THROW(ReduceChunks<double>(
                   kItems, kThreads, [] { return 0.0; }, [](int, int, double*) { return -1; },
                   [](double) { throw std::runtime_error("merge"); }, kChunk),
               std::runtime_error);
}

}  // namespace
}  // namespace fastcal::internal
