// The Levenshtein edit distance (Wagner and Fischer 1974, J. ACM 21: one row of the
// table), for "did you mean" in flags, column maps and headers. Not part of the API.
#ifndef FASTCAL_INTERNAL_EDIT_DISTANCE_H_
#define FASTCAL_INTERNAL_EDIT_DISTANCE_H_

#include <cstddef>
#include <string_view>

namespace fastcal::internal {

// Insertions, deletions and substitutions that turn a into b, letters compared without
// case (--min-tension-KN is one slip from --min-tension-kN).
size_t EditDistance(std::string_view a, std::string_view b);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_EDIT_DISTANCE_H_
