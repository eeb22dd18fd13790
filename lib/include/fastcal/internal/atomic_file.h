// Whole-file reads, and writes that readers never see half-written: a new temporary file beside
// the target (O_EXCL, unique name), write, fsync, rename over the target, fsync of the
// directory (so that the new name survives a crash); on any failure the temporary file is
// removed and the target is untouched.
//
// Temporaries (issue 29): a file's is "<path>.tmp.<pid>[.<n>]" and an output directory's
// ".<name>.tmp.<pid>" (".<name>.old.<pid>" while --force swaps without RENAME_EXCHANGE);
// the process writing one holds an flock(2) on it. A run killed midway leaves them
// behind; RemoveStaleTemporaries, called before each write, removes those whose process
// is gone.
#ifndef FASTCAL_INTERNAL_ATOMIC_FILE_H_
#define FASTCAL_INTERNAL_ATOMIC_FILE_H_

#include <cstddef>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

namespace fastcal::internal {

// On failure returns false with "<path>: <what>: <strerror>" in *error (may be null).
// `replace` false: fails ("<path>: exists ...") rather than replace a file that exists at
// the moment of the rename (RenameNoReplace), even one another process made meanwhile.
bool WriteFileAtomically(const std::string& path, const std::string& content, std::string* error,
                         bool replace = true);

// A new unique temporary name beside `path` ("<path>.tmp.<pid>.<n>").
std::string TemporaryNameFor(const std::string& path);

// A staging directory this process writes a result into before publishing it (renamed to
// its place): RemoveTemporariesOnSignal removes it with what it holds.
void RegisterTemporaryDirectory(const std::string& dir);

// Unlinks every temporary this process named with TemporaryNameFor that still exists, and
// empties and removes every registered staging directory that still exists (its files and
// subdirectories, three levels deep): async-signal-safe (system calls only: no allocation, no
// lock), for a SIGINT/SIGTERM handler, so that an interrupted command leaves no half-written file
// (issue 37). What a SIGKILL leaves, the next run removes once its process is gone.
void RemoveTemporariesOnSignal();

// Removes what killed runs left beside `path` (the names above), only when the process
// that made them is gone: its pid no longer runs, or the pid was reused (it runs, but
// nobody holds the temporary's lock and it is over a minute old). A moved-aside previous
// result (".<name>.old.<pid>", the --force fallback) is renamed back to `path` when `path`
// is missing, else removed. Best effort; returns how many it removed or restored.
int RemoveStaleTemporaries(const std::string& path);

// rename(from, to) that fails with EEXIST (in *err) instead of replacing an existing `to`:
// renameat2 RENAME_NOREPLACE, or where the file system lacks it, link + unlink for a file
// and rename for a directory (which refuses a non-empty target, and replaces an empty one).
bool RenameNoReplace(const std::string& from, const std::string& to, int* err);

// Swaps `a` and `b` atomically (renameat2 RENAME_EXCHANGE): no moment without either.
// False with *err = EINVAL or ENOSYS where the file system or kernel lacks it.
bool RenameExchange(const std::string& a, const std::string& b, int* err);

// Puts the complete directory `tmp` (synced by the caller) in place as `target`: false with
// *why on failure, `tmp` then still there. An empty `target` (a new --out made beforehand)
// is removed first. A `target` that holds something is replaced only with `may_replace`,
// asked at that moment (another run may have filled it meanwhile; false with *why: kept):
// swapped in one step (RENAME_EXCHANGE) or, where the file system lacks that, moved aside
// first, ".<name>.old.<pid>", which RemoveStaleTemporaries puts back after a crash between
// the two renames. The previous contents are then removed. Sync the parent after it.
bool PublishDirectory(const std::string& tmp, const std::string& target,
                      const std::function<bool(std::string*)>& may_replace, std::string* why);

// fsync of directory `dir`, after a rename into it (false, with *err, on failure).
bool SyncDirectory(const std::string& dir, int* err);
// The directory holding `path` ("." for a bare name).
std::string ParentDirectory(const std::string& path);

// A new file in directory `dir` that has no name (O_TMPFILE, or mkstemp and unlink where
// the file system lacks it), open for reading and writing, gone when closed; nullptr with
// *err on failure (a missing directory: ENOENT).
std::FILE* OpenUnnamedFile(const std::string& dir, int* err);

// Takes an exclusive flock(2) on `path` (a file or directory) for the lifetime of the
// object, the mark of a temporary in use (RemoveStaleTemporaries leaves it alone).
class TemporaryLock {
 public:
  TemporaryLock() = default;
  TemporaryLock(const TemporaryLock&) = delete;
  TemporaryLock& operator=(const TemporaryLock&) = delete;
  ~TemporaryLock() { Release(); }
  // Locks `path` (best effort: a file system without locks leaves it unlocked).
  void Lock(const std::string& path);
  void Release();

 private:
  int fd_ = -1;
};

// A file written piece by piece into a locked temporary beside `path`, which Commit
// renames into place: a failure or a destruction without Commit leaves no file (and the
// target untouched). Writes are buffered and each checked: a full disk fails the write
// at once, naming `path` (not the temporary).
class AtomicFileWriter {
 public:
  AtomicFileWriter() = default;
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;
  ~AtomicFileWriter() { Abort(); }

  bool Open(const std::string& path, std::string* error);
  bool Write(std::string_view data, std::string* error);
  // Flushes and fsyncs the temporary: a full disk shows here, before any rename (several
  // files published together sync them all first).
  bool Sync(std::string* error);
  // Flushes, fsyncs and closes, renames into place (over an existing file only with
  // `replace`) and fsyncs the directory.
  bool Commit(bool replace, std::string* error);
  // Removes the temporary (nothing when not open).
  void Abort();

 private:
  bool Flush(std::string* error);
  bool Fail(const char* what, int err, std::string* error);

  std::string path_, temp_path_, buffer_;
  int fd_ = -1;
};

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
//
// A gzip file (known by its first two bytes, 1f 8b, whatever its name) is decompressed as
// it is read (zlib, streamed: memory as for the plain file): Read gives its content, and
// max_bytes bounds the decompressed bytes too ("decompresses to more than ..."), so that a
// small file that inflates without end is refused. Concatenated gzip members are read one
// after the other (as gunzip does); a truncated or corrupt stream is an error naming the
// file and the decompressed byte it reached.
class RegularFileReader {
 public:
  RegularFileReader() = default;
  RegularFileReader(const RegularFileReader&) = delete;
  RegularFileReader& operator=(const RegularFileReader&) = delete;
  ~RegularFileReader();
  bool Open(const std::string& path, long long max_bytes, const std::string& what,
            std::string* error);
  bool Read(size_t max, std::string* text, bool* end, std::string* error);
  // The file's size when opened (bytes; compressed for a gzip file).
  long long size() const { return size_; }
  // Whether the file is gzip-compressed (decompressed by Read).
  bool gzip() const { return gzip_ != nullptr; }

 private:
  struct Gzip;  // zlib's state, kept out of this header
  struct GzipDeleter {
    void operator()(Gzip* g) const;
  };
  bool Fail(const std::string& why, std::string* error);
  // Open's last step: a gzip file's first bytes start the decompression (gzip_reader.cc).
  bool StartGzipIfCompressed(std::string* error);
  bool ReadGzip(size_t max, std::string* text, bool* end, std::string* error);
  int fd_ = -1;
  std::string name_, too_large_;
  long long max_bytes_ = 0, read_bytes_ = 0, size_ = 0;
  std::unique_ptr<Gzip, GzipDeleter> gzip_;
};

// Reads a whole regular file, of any size, in chunks handed to `sink` in order, for files
// too large to hold (a digest); a device, pipe or directory is refused before reading,
// with RegularFileReader's messages (error may not be null).
bool ReadFileChunks(const std::string& path, const std::function<void(const char*, size_t)>& sink,
                    std::string* error);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_ATOMIC_FILE_H_
