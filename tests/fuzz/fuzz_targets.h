// The file readers of fastcal as fuzz targets (tests/fuzz/README.md): each takes any
// bytes, goes through the public API as a user's file would, and where there is a writer
// checks the round trip read, write, read: equal. A broken invariant aborts, which
// libFuzzer and the test suite both report; a rejected input is simply not interesting.
// The same functions serve libFuzzer (fuzz_entry.cc, built with -DFASTCAL_BUILD_FUZZERS=ON
// and clang) and the regression test of the normal suite (fuzz_regression_test.cc), which
// replays the seed corpora and every input that ever hung or crashed.
#ifndef FASTCAL_TESTS_FUZZ_FUZZ_TARGETS_H_
#define FASTCAL_TESTS_FUZZ_FUZZ_TARGETS_H_

#include <cstddef>
#include <cstdint>
#include <string>

namespace fastcal::fuzz {

// Measurement dataset CSV: ParseDataset, then WriteDataset and ReadDataset: equal samples.
void DatasetCsv(const uint8_t* data, size_t size);
// Pose CSV (solve --poses): ParsePosesCsv; every pose it returns finite and plausible.
void PoseCsv(const uint8_t* data, size_t size);
// Model YAML: ParseCableRobotYaml, CableRobotToYaml, parse again: the same YAML text.
void ModelYaml(const uint8_t* data, size_t size);
// Calibration spec YAML: ParseCalibrationSpecYaml, CalibrationSpecToYaml, parse again:
// the same YAML text.
void SpecYaml(const uint8_t* data, size_t size);
// A track's stored fold (track_fold.h) and its state (internal/track_state.h): refused
// with a message, or read and, for a fold, written back to the same bytes.
void WindowFoldBytes(const uint8_t* data, size_t size);
void TrackStateJson(const uint8_t* data, size_t size);

// A vibration record (`fastcal modes --data`, vibration_record.h): ParseVibrationRecord,
// then CheckRecordSampling and, for a short record it accepts, IdentifyModesEra; every
// accepted record finite, evenly sampled and within kMaxRecordSamples, every identified
// mode in the band.
void VibrationRecordCsv(const uint8_t* data, size_t size);

// Prints `what` and aborts: a broken invariant of the target.
[[noreturn]] void Violation(const std::string& what);

}  // namespace fastcal::fuzz

#endif  // FASTCAL_TESTS_FUZZ_FUZZ_TARGETS_H_
