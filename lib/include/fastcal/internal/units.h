// Unit factors shared by the library, the command line and the Python bindings: SI inside,
// the units people read (kN) in files and text.
#ifndef FASTCAL_INTERNAL_UNITS_H_
#define FASTCAL_INTERNAL_UNITS_H_

namespace fastcal::internal {

// Newtons per kilonewton: tensions are N inside, kN in files, tables and plots.
inline constexpr double kNPerKn = 1e3;

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_UNITS_H_
