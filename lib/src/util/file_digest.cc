// SHA-256 of a file with OpenSSL's EVP interface (declarations: file_digest.h).
#include "fastcal/file_digest.h"

#include <openssl/evp.h>

#include <exception>
#include <memory>

#include "fastcal/internal/atomic_file.h"

namespace fastcal {

bool FileSha256(const std::string& path, std::string* hex, std::string* error) {
  std::string message;
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
               updated = updated && EVP_DigestUpdate(context.get(), data, n) == 1;
             },
             &message) &&
         updated && EVP_DigestFinal_ex(context.get(), digest, &size) == 1;
  } catch (const std::exception& e) {
    message = path + ": " + e.what();
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

}  // namespace fastcal
