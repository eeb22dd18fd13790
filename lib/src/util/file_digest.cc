// SHA-256 of a file with OpenSSL's EVP interface (declarations: file_digest.h).
#include "fastcal/file_digest.h"

#include <openssl/evp.h>

#include <algorithm>
#include <exception>
#include <limits>
#include <memory>
#include <new>

#include "fastcal/internal/atomic_file.h"

namespace fastcal {

namespace {

// The digest of the file's first `limit` bytes (all of them when limit < 0).
bool Sha256Of(const std::string& path, long long limit, std::string* hex, std::string* error) {
  std::string message;
  long long seen = 0;
  const std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> context(EVP_MD_CTX_new(),
                                                                        &EVP_MD_CTX_free);
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int size = 0;
  bool ok = false;
  try {
    bool updated = true;
    ok = context != nullptr && EVP_DigestInit_ex(context.get(), EVP_sha256(), nullptr) == 1 &&
         internal::ReadFileChunks(
             path,
             [&](const char* data, size_t n) {
               const long long room = limit < 0 ? static_cast<long long>(n) : limit - seen;
               const size_t take =
                   static_cast<size_t>(std::max(0LL, std::min(room, static_cast<long long>(n))));
               seen += static_cast<long long>(n);
               if (take > 0) {
                 updated = updated && EVP_DigestUpdate(context.get(), data, take) == 1;
               }
             },
             &message) &&
         updated && EVP_DigestFinal_ex(context.get(), digest, &size) == 1;
  } catch (const std::bad_alloc&) {
    throw;  // the machine's, not the file's: the caller says "out of memory" (exit 1)
  } catch (const std::exception& e) {
    message = path + ": " + e.what();
    ok = false;
  }
  if (ok && limit >= 0 && seen < limit) {
    message = path + ": " + std::to_string(seen) + " bytes where " + std::to_string(limit) +
              " were expected";
    ok = false;
  }
  if (!ok) {
    if (message.empty()) message = path + ": cannot compute its SHA-256 (OpenSSL failed)";
    if (error != nullptr) *error = message;
    return false;
  }
  static constexpr char kHexDigits[] = "0123456789abcdef";
  std::string text;
  for (unsigned int i = 0; i < size; ++i) {
    text += kHexDigits[digest[i] >> 4];
    text += kHexDigits[digest[i] & 0xf];
  }
  *hex = text;
  return true;
}

}  // namespace

bool FileSha256(const std::string& path, std::string* hex, std::string* error) {
  return Sha256Of(path, -1, hex, error);
}

bool FileSha256Prefix(const std::string& path, long long bytes, std::string* hex,
                      std::string* error) {
  if (bytes < 0) {
    if (error != nullptr) *error = path + ": a prefix of " + std::to_string(bytes) + " bytes";
    return false;
  }
  return Sha256Of(path, bytes, hex, error);
}

}  // namespace fastcal
