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

// Whether this build runs under AddressSanitizer (gcc defines __SANITIZE_ADDRESS__, clang
// has __has_feature).
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kUnderAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kUnderAddressSanitizer = true;
#else
inline constexpr bool kUnderAddressSanitizer = false;
#endif
#else
inline constexpr bool kUnderAddressSanitizer = false;
#endif

// The same for ThreadSanitizer, which reserves most of the address space too.
#if defined(__SANITIZE_THREAD__)
inline constexpr bool kUnderThreadSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
inline constexpr bool kUnderThreadSanitizer = true;
#else
inline constexpr bool kUnderThreadSanitizer = false;
#endif
#else
inline constexpr bool kUnderThreadSanitizer = false;
#endif

// Whether a sanitizer's reserved shadow memory rules out limits on the address space.
inline constexpr bool kUnderSanitizer = kUnderAddressSanitizer || kUnderThreadSanitizer;

// Limits this process: SIGALRM after kBoundedSeconds and, without a sanitizer, at most
// kBoundedAddressSpaceBytes of address space (beyond it allocation throws bad_alloc).
inline void LimitThisProcess() {
  if (!kUnderSanitizer) {
    const rlimit limit{kBoundedAddressSpaceBytes, kBoundedAddressSpaceBytes};
    setrlimit(RLIMIT_AS, &limit);
  }
  alarm(kBoundedSeconds);
}

}  // namespace fastcal::test

#endif  // FASTCAL_TESTS_BOUNDED_PROCESS_H_
