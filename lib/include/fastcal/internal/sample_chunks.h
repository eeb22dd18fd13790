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
//
// Faults (issue 29): the library runs inside control software, so a thread the system
// refuses (std::system_error from std::thread: a process limit, `ulimit -v`) is not an
// abort: the work goes on with the threads that did start, at worst the calling thread
// alone, and gives the same bits. An exception thrown by `work` (std::bad_alloc) stops
// the pass and is rethrown on the calling thread once every thread has joined.
#ifndef FASTCAL_INTERNAL_SAMPLE_CHUNKS_H_
#define FASTCAL_INTERNAL_SAMPLE_CHUNKS_H_

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace fastcal::internal {

// Samples per chunk: large enough that handing out a chunk costs nothing, small enough
// that two threads stay balanced on 10^4 samples.
inline constexpr int kSampleChunk = 1024;

// Starts a thread running `body`, or throws std::system_error as std::thread's constructor
// does when the system refuses one. Empty: std::thread itself; tests pass one that refuses.
using ThreadStarter = std::function<std::thread(std::function<void()> body)>;

// The first exception of several threads, kept to be rethrown by the calling thread.
class FirstException {
 public:
  void Keep(std::exception_ptr e) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!first_) first_ = std::move(e);
  }
  void RethrowIfAny() const {
    if (first_) std::rethrow_exception(first_);
  }

 private:
  std::mutex mutex_;
  std::exception_ptr first_;
};

// Runs fn(thread) on up to `threads` threads, the calling thread being thread 0, and
// returns how many ran: those the system started (thread ids 0 .. returned - 1), at least
// the calling thread. An exception thrown by fn on any thread is rethrown here after
// every thread has joined.
template <typename Fn>
int OnThreads(int threads, const Fn& fn, const ThreadStarter& start = nullptr) {
  FirstException thrown;
  const auto guarded = [&fn, &thrown](int w) {
    try {
      fn(w);
    } catch (...) {
      thrown.Keep(std::current_exception());
    }
  };
  std::vector<std::thread> workers;
  try {
    workers.reserve(static_cast<size_t>(std::max(threads - 1, 0)));
    for (int w = 1; w < threads; ++w) {
      std::function<void()> body = [&guarded, w] { guarded(w); };
      workers.push_back(start ? start(std::move(body)) : std::thread(std::move(body)));
    }
  } catch (const std::system_error&) {
    // Refused: the threads started so far share the work.
  } catch (const std::bad_alloc&) {
  }
  guarded(0);
  for (std::thread& t : workers) t.join();
  thrown.RethrowIfAny();
  return 1 + static_cast<int>(workers.size());
}

// `threads`, at most the threads the machine runs at once: for Ceres, which gains nothing
// beyond them and logs a warning.
inline int MachineThreads(int threads) {
  const unsigned cores = std::thread::hardware_concurrency();
  return cores == 0 ? threads : std::clamp(threads, 1, static_cast<int>(cores));
}

inline int ChunkThreads(int count, int chunk, int threads) {
  const int chunks = (count + chunk - 1) / chunk;
  return std::clamp(threads, 1, std::max(1, chunks));
}

// work(begin, end) -> first failing index or -1, for each chunk. Returns the smallest
// failing index, or -1.
// `start`: how threads are started (OnThreads). An exception from `work` stops the other
// threads at their next chunk and is rethrown.
template <typename Work>
int ForEachChunk(int count, int threads, const Work& work, int chunk = kSampleChunk,
                 const ThreadStarter& start = nullptr) {
  std::atomic<int> next{0};
  std::atomic<int> failed{count};  // smallest failing index so far (count: none)
  OnThreads(
      ChunkThreads(count, chunk, threads),
      [&](int) {
        for (;;) {
          const int begin = next.fetch_add(chunk);
          if (begin >= count || begin > failed.load()) return;
          int f = -1;
          try {
            f = work(begin, std::min(count, begin + chunk));
          } catch (...) {
            failed.store(-1);  // every later chunk is past it: the others stop
            throw;
          }
          if (f < 0) continue;
          int seen = failed.load();
          while (f < seen && !failed.compare_exchange_weak(seen, f)) {
          }
        }
      },
      start);
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
// After a failure, ordered, finish and merge are skipped (the total is discarded). A thread
// whose stage throws abandons the pass: the threads waiting for their turn are released,
// and the exception is rethrown (issue 29).
template <typename Local, typename Make, typename Work, typename Ordered, typename Finish,
          typename Merge>
int ReduceChunksInOrder(int count, int threads, const Make& make, const Work& work,
                        const Ordered& ordered, const Finish& finish, const Merge& merge,
                        int chunk = kSampleChunk, const ThreadStarter& start = nullptr) {
  std::atomic<int> next{0};
  std::atomic<int> failed{count};
  std::mutex mutex;
  std::condition_variable turn;
  int ordered_chunks = 0;  // chunks through `ordered` (or passed over), in order
  int merged = 0;          // chunks merged (or passed over), in order
  bool abandoned = false;  // an exception: no chunk takes its turn any more
  const auto record = [&](int f) {
    if (f < 0) return;
    int seen = failed.load();
    while (f < seen && !failed.compare_exchange_weak(seen, f)) {
    }
  };
  // Waits for chunk `index`'s turn on `counter`, runs `step` unless something failed;
  // false when the pass was abandoned meanwhile.
  const auto in_turn = [&](int* counter, int index, const auto& step) {
    std::unique_lock<std::mutex> lock(mutex);
    turn.wait(lock, [&] { return *counter == index || abandoned; });
    if (abandoned) return false;
    if (failed.load() == count) step();
    ++*counter;
    lock.unlock();
    turn.notify_all();
    return true;
  };
  const auto abandon = [&] {
    {
      std::lock_guard<std::mutex> lock(mutex);
      abandoned = true;
    }
    turn.notify_all();
  };
  OnThreads(
      ChunkThreads(count, chunk, threads),
      [&](int) {
        try {
          Local local = make();
          for (;;) {
            const int begin = next.fetch_add(chunk);
            if (begin >= count) return;
            const int end = std::min(count, begin + chunk);
            const int index = begin / chunk;
            // Past a failure the chunk is not needed: the total is discarded.
            record(begin > failed.load() ? -1 : work(begin, end, &local));
            if (!in_turn(&ordered_chunks, index, [&] { ordered(begin, end, &local); })) return;
            if (failed.load() == count) record(finish(begin, end, &local));
            if (!in_turn(&merged, index, [&] { merge(local); })) return;
            local = make();
          }
        } catch (...) {
          abandon();
          throw;
        }
      },
      start);
  return failed.load() < count ? failed.load() : -1;
}

// ReduceChunksInOrder without the ordered stage: work(begin, end, &local) adds a chunk
// into the thread's `local`; merge(local) adds it into the total, in chunk order.
template <typename Local, typename Make, typename Work, typename Merge>
int ReduceChunks(int count, int threads, const Make& make, const Work& work, const Merge& merge,
                 int chunk = kSampleChunk, const ThreadStarter& start = nullptr) {
  const auto none = [](int, int, Local*) {};
  const auto no_finish = [](int, int, Local*) { return -1; };
  return ReduceChunksInOrder<Local>(count, threads, make, work, none, no_finish, merge, chunk,
                                    start);
}

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_SAMPLE_CHUNKS_H_
