// Passes over many samples on several threads with results that do not depend on the
// number of threads (issue 20: 1 and 2 threads must print the same digits).
//
// [0, count) is cut into chunks of a fixed size, whatever the number of threads; threads
// take chunks in increasing order. ForEachChunk is for work whose results are per item
// (written to disjoint slots). ReduceChunks is for sums: each chunk is computed into a
// thread's own accumulator, which is then merged into the total strictly in chunk order,
// so the floating-point sums are the same on one thread or many.
//
// Failures: `work` returns the index of the first item it could not do, or -1. The result
// is the smallest failing index over all chunks (every chunk before it is still done, so
// the answer is deterministic too); chunks after a failure may be skipped.
#ifndef FASTCAL_INTERNAL_SAMPLE_CHUNKS_H_
#define FASTCAL_INTERNAL_SAMPLE_CHUNKS_H_

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

namespace fastcal::internal {

// Samples per chunk: large enough that handing out a chunk costs nothing, small enough
// that two threads stay balanced on 10^4 samples.
inline constexpr int kSampleChunk = 1024;

// Runs fn(thread) on `threads` threads (the calling thread is thread 0).
template <typename Fn>
void OnThreads(int threads, const Fn& fn) {
  std::vector<std::thread> workers;
  for (int w = 1; w < threads; ++w) workers.emplace_back([&fn, w] { fn(w); });
  fn(0);
  for (std::thread& t : workers) t.join();
}

inline int ChunkThreads(int count, int chunk, int threads) {
  const int chunks = (count + chunk - 1) / chunk;
  return std::clamp(threads, 1, std::max(1, chunks));
}

// work(begin, end) -> first failing index or -1, for each chunk. Returns the smallest
// failing index, or -1.
template <typename Work>
int ForEachChunk(int count, int threads, const Work& work, int chunk = kSampleChunk) {
  std::atomic<int> next{0};
  std::atomic<int> failed{count};  // smallest failing index so far (count: none)
  OnThreads(ChunkThreads(count, chunk, threads), [&](int) {
    for (;;) {
      const int begin = next.fetch_add(chunk);
      if (begin >= count || begin > failed.load()) return;
      const int f = work(begin, std::min(count, begin + chunk));
      if (f < 0) continue;
      int seen = failed.load();
      while (f < seen && !failed.compare_exchange_weak(seen, f)) {
      }
    }
  });
  return failed.load() < count ? failed.load() : -1;
}

// Like ForEachChunk, with sums and a stage that must see the chunks in order:
//   work(begin, end, &local)     in parallel: the chunk's costly part, into the thread's
//                                `local` (made by make()); the first failing index or -1
//   ordered(begin, end, &local)  strictly in chunk order, one chunk at a time: a recursion
//                                in time order over what work computed (the slow-error
//                                filter, slow_error_filter.h)
//   finish(begin, end, &local)   in parallel again (e.g. fold what ordered produced)
//   merge(local)                 in chunk order under a lock; then `local` is made afresh.
// After a failure, ordered, finish and merge are skipped (the total is discarded).
template <typename Local, typename Make, typename Work, typename Ordered, typename Finish,
          typename Merge>
int ReduceChunksInOrder(int count, int threads, const Make& make, const Work& work,
                        const Ordered& ordered, const Finish& finish, const Merge& merge,
                        int chunk = kSampleChunk) {
  std::atomic<int> next{0};
  std::atomic<int> failed{count};
  std::mutex mutex;
  std::condition_variable turn;
  int ordered_chunks = 0;  // chunks through `ordered` (or passed over), in order
  int merged = 0;          // chunks merged (or passed over), in order
  const auto record = [&](int f) {
    if (f < 0) return;
    int seen = failed.load();
    while (f < seen && !failed.compare_exchange_weak(seen, f)) {
    }
  };
  // Waits for chunk `index`'s turn on `counter`, runs `step` unless something failed.
  const auto in_turn = [&](int* counter, int index, const auto& step) {
    std::unique_lock<std::mutex> lock(mutex);
    turn.wait(lock, [&] { return *counter == index; });
    if (failed.load() == count) step();
    ++*counter;
    lock.unlock();
    turn.notify_all();
  };
  OnThreads(ChunkThreads(count, chunk, threads), [&](int) {
    Local local = make();
    for (;;) {
      const int begin = next.fetch_add(chunk);
      if (begin >= count) return;
      const int end = std::min(count, begin + chunk);
      const int index = begin / chunk;
      // Past a failure the chunk is not needed: the total is discarded.
      record(begin > failed.load() ? -1 : work(begin, end, &local));
      in_turn(&ordered_chunks, index, [&] { ordered(begin, end, &local); });
      if (failed.load() == count) record(finish(begin, end, &local));
      in_turn(&merged, index, [&] { merge(local); });
      local = make();
    }
  });
  return failed.load() < count ? failed.load() : -1;
}

// ReduceChunksInOrder without the ordered stage: work(begin, end, &local) adds a chunk
// into the thread's `local`; merge(local) adds it into the total, in chunk order.
template <typename Local, typename Make, typename Work, typename Merge>
int ReduceChunks(int count, int threads, const Make& make, const Work& work, const Merge& merge,
                 int chunk = kSampleChunk) {
  const auto none = [](int, int, Local*) {};
  const auto no_finish = [](int, int, Local*) { return -1; };
  return ReduceChunksInOrder<Local>(count, threads, make, work, none, no_finish, merge, chunk);
}

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_SAMPLE_CHUNKS_H_
