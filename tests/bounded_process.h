// For tests of inputs that once made a reader hang and grow without bound (yaml-cpp 0.7's
// LoadAll on a stray comma): run the reader inside a gtest death test's child process
// after LimitThisProcess, so that without the fix the test fails within seconds with
// SIGALRM (or bad_alloc) instead of hanging the suite and eating the machine's memory.
#ifndef FASTCAL_TESTS_BOUNDED_PROCESS_H_
#define FASTCAL_TESTS_BOUNDED_PROCESS_H_

#include <sys/resource.h>
#include <unistd.h>

namespace fastcal::test {

// Seconds a bounded child may run; generous, the readers take milliseconds.
inline constexpr unsigned kBoundedSeconds = 20;
// Address space of a bounded child without a sanitizer (a sanitizer reserves terabytes of
// shadow memory, so there only the time limit applies).
inline constexpr rlim_t kBoundedAddressSpaceBytes = rlim_t{4} << 30;

inline void LimitThisProcess() {
#if !defined(__SANITIZE_ADDRESS__) && !defined(__has_feature)
#define FASTCAL_LIMIT_ADDRESS_SPACE 1
#elif defined(__has_feature)
#if !__has_feature(address_sanitizer) && !defined(__SANITIZE_ADDRESS__)
#define FASTCAL_LIMIT_ADDRESS_SPACE 1
#endif
#endif
#ifdef FASTCAL_LIMIT_ADDRESS_SPACE
  const rlimit limit{kBoundedAddressSpaceBytes, kBoundedAddressSpaceBytes};
  setrlimit(RLIMIT_AS, &limit);
#endif
  alarm(kBoundedSeconds);
}

}  // namespace fastcal::test

#endif  // FASTCAL_TESTS_BOUNDED_PROCESS_H_
