// The SHA-256 digest of a file, for provenance: summary.json, the report and the
// calibrated model's header name each input file with it, so anyone can check which
// bytes a result came from with a standard tool (`sha256sum FILE` prints the same 64
// hex digits). Computed by OpenSSL's libcrypto (FIPS 180-4), not by hand.
#ifndef FASTCAL_FILE_DIGEST_H_
#define FASTCAL_FILE_DIGEST_H_

#include <string>

namespace fastcal {

// SHA-256 of the file's bytes as 64 lowercase hex digits. The empty file gives
// "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855". On failure returns
// false and names the file and the reason in *error (may be null); *hex is then untouched.
bool FileSha256(const std::string& path, std::string* hex, std::string* error);

// SHA-256 of the file's first `bytes` bytes (>= 0): a file appended to since, checked
// against what it held (a track's sample store, issue 37). False, naming the file, when it
// is shorter than that.
bool FileSha256Prefix(const std::string& path, long long bytes, std::string* hex,
                      std::string* error);

}  // namespace fastcal

#endif  // FASTCAL_FILE_DIGEST_H_
