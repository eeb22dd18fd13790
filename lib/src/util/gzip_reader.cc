// Gzip files read as they are (RegularFileReader, internal/atomic_file.h): telemetry is
// kept as .csv.gz for months, and every reader takes it. RFC 1952 members decompressed
// with zlib's inflate (windowBits 15 + 16: gzip only, header and CRC-32 checked), one after
// the other when several are concatenated (RFC 1952 section 2.2; gunzip reads them so).
// Streamed: 64 KiB of compressed input and the caller's chunk of output at a time, so a
// gzipped dataset costs the memory of the plain one.
#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>
#include <string>

#include "fastcal/internal/atomic_file.h"

namespace fastcal::internal {

struct RegularFileReader::Gzip {
  z_stream stream{};
  unsigned char input[1 << 16];
  bool input_end = false;   // the file has no more bytes
  bool member_end = false;  // the last inflate ended a member (a valid place to stop)
};

void RegularFileReader::GzipDeleter::operator()(Gzip* g) const {
  inflateEnd(&g->stream);
  delete g;
}

bool RegularFileReader::StartGzipIfCompressed(std::string* error) {
  unsigned char magic[2] = {0, 0};
  ssize_t n;
  do {
    n = ::pread(fd_, magic, sizeof(magic), 0);
  } while (n < 0 && errno == EINTR);
  if (n < 0) return Fail(std::string("cannot read: ") + std::strerror(errno), error);
  if (n < 2 || magic[0] != 0x1f || magic[1] != 0x8b) return true;
  std::unique_ptr<Gzip, GzipDeleter> g(new Gzip);
  if (inflateInit2(&g->stream, 15 + 16) != Z_OK) {
    delete g.release();  // inflateEnd needs a stream that inflateInit2 set up
    return Fail("cannot start gzip decompression (zlib: out of memory)", error);
  }
  gzip_ = std::move(g);
  return true;
}

bool RegularFileReader::ReadGzip(size_t max, std::string* text, bool* end, std::string* error) {
  Gzip& g = *gzip_;
  *end = false;
  unsigned char output[1 << 16];
  size_t got = 0;
  while (got < max) {
    if (g.stream.avail_in == 0 && !g.input_end) {
      ssize_t n;
      do {
        n = ::read(fd_, g.input, sizeof(g.input));
      } while (n < 0 && errno == EINTR);
      if (n < 0) return Fail(std::string("cannot read: ") + std::strerror(errno), error);
      g.input_end = n == 0;
      g.stream.next_in = g.input;
      g.stream.avail_in = static_cast<uInt>(n);
    }
    if (g.stream.avail_in == 0 && g.input_end) {
      if (!g.member_end) {
        return Fail("truncated gzip file (it ends inside its compressed data, after " +
                        std::to_string(read_bytes_) + " decompressed bytes)",
                    error);
      }
      ::close(fd_);
      fd_ = -1;
      gzip_.reset();
      *end = true;
      return true;
    }
    if (g.member_end) {  // another member follows: start it afresh
      inflateReset(&g.stream);
      g.member_end = false;
    }
    g.stream.next_out = output;
    g.stream.avail_out = static_cast<uInt>(std::min(sizeof(output), max - got));
    const int z = inflate(&g.stream, Z_NO_FLUSH);
    if (z != Z_OK && z != Z_STREAM_END && !(z == Z_BUF_ERROR && g.stream.avail_in == 0)) {
      const char* why = g.stream.msg != nullptr ? g.stream.msg : zError(z);
      return Fail(std::string("not a valid gzip file (zlib: ") + why + ", after " +
                      std::to_string(read_bytes_) + " decompressed bytes)",
                  error);
    }
    g.member_end = z == Z_STREAM_END;
    const size_t n = static_cast<size_t>(g.stream.next_out - output);
    if (read_bytes_ + static_cast<long long>(n) > max_bytes_) {
      return Fail("decompressed, it is " + too_large_, error);
    }
    read_bytes_ += static_cast<long long>(n);
    got += n;
    text->append(reinterpret_cast<const char*>(output), n);
  }
  return true;
}

}  // namespace fastcal::internal
