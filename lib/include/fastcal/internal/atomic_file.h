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

// Reads a whole regular file of at most `max_bytes` into *text, refusing before reading
// anything else: a device, pipe or directory ("<path>: not a regular file ..."; /dev/zero
// would be read until memory ran out) and a file larger than `max_bytes` ("<path>: 2.1 GB
// is more than the <what> limit of 1 GiB"). `what` names the kind of file ("dataset").
// A file that grows while it is read is refused the same way.
bool ReadRegularFile(const std::string& path, long long max_bytes, const std::string& what,
                     std::string* text, std::string* error);

// ReadRegularFile piece by piece, for a file read in chunks (DatasetChunkReader): Open
// makes its checks before reading; Read appends up to `max` further bytes to *text, sets
// *end at the end of the file, and refuses a file that grows past max_bytes; the same
// messages. The file is closed at the end, on failure and by the destructor.
class RegularFileReader {
 public:
  RegularFileReader() = default;
  RegularFileReader(const RegularFileReader&) = delete;
  RegularFileReader& operator=(const RegularFileReader&) = delete;
  ~RegularFileReader();
  bool Open(const std::string& path, long long max_bytes, const std::string& what,
            std::string* error);
  bool Read(size_t max, std::string* text, bool* end, std::string* error);
  // The file's size when opened (bytes).
  long long size() const { return size_; }

 private:
  bool Fail(const std::string& why, std::string* error);
  int fd_ = -1;
  std::string name_, too_large_;
  long long max_bytes_ = 0, read_bytes_ = 0, size_ = 0;
};

// Reads a whole file in chunks handed to `sink` in order, for files too large to hold (a
// digest); the same messages (error may not be null).
bool ReadFileChunks(const std::string& path, const std::function<void(const char*, size_t)>& sink,
                    std::string* error);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_ATOMIC_FILE_H_
