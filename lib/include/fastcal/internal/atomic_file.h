// Whole-file reads, and writes that readers never see half-written: a new temporary file beside
// the target (O_EXCL, unique name), write, fsync, rename over the target; on any failure
// the temporary file is removed and the target is untouched.
#ifndef FASTCAL_INTERNAL_ATOMIC_FILE_H_
#define FASTCAL_INTERNAL_ATOMIC_FILE_H_

#include <cstddef>
#include <functional>
#include <string>

namespace fastcal::internal {

// On failure returns false with "<path>: <what>: <strerror>" in *error (may be null).
bool WriteFileAtomically(const std::string& path, const std::string& content, std::string* error);

// Reads a whole file; "<path>: cannot open" / "<path>: cannot read" on failure (a
// directory cannot be opened).
bool ReadTextFile(const std::string& path, std::string* text, std::string* error);

// Reads a whole file in chunks handed to `sink` in order, for files too large to hold (a
// digest); the same messages (error may not be null).
bool ReadFileChunks(const std::string& path, const std::function<void(const char*, size_t)>& sink,
                    std::string* error);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_ATOMIC_FILE_H_
