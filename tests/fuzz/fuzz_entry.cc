// libFuzzer's entry point for one target of fuzz_targets.h, chosen at compile time by
// FASTCAL_FUZZ_TARGET (tests/fuzz/CMakeLists.txt builds this file once per target).
#include <cstddef>
#include <cstdint>

#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fastcal::fuzz::FASTCAL_FUZZ_TARGET(data, size);
  return 0;
}
