// The reader of a track's track_state.json (docs/calibration.md, "Tracking: files"), for
// the fuzz target of the track state (tests/fuzz): what an update reads before it trusts
// a store or a fold. Not part of the API.
#ifndef FASTCAL_INTERNAL_TRACK_STATE_H_
#define FASTCAL_INTERNAL_TRACK_STATE_H_

#include <string>

namespace fastcal::internal {

// Parses `text` as a track state with every check an update makes before it touches a
// file (format, nesting, numbers, window labels that stay inside DIR, file indices in
// range). True with *windows the number of windows it records; false with *error.
bool ParseTrackStateText(const std::string& text, int* windows, std::string* error);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_TRACK_STATE_H_
