// The error recorder of a function that answers false on failure: sets *error (when there
// is one) and answers false, so that a check reads `if (bad) return Fail(error, "why");`.
#ifndef FASTCAL_INTERNAL_FAIL_H_
#define FASTCAL_INTERNAL_FAIL_H_

#include <string>

namespace fastcal::internal {

inline bool Fail(std::string* error, const std::string& message) {
  if (error != nullptr) *error = message;
  return false;
}

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_FAIL_H_
