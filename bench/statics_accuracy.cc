// Accuracy of each statics method against exact at the workspace's edge, by the largest
// s0/k of a pose's cables (the table "At the workspace's edge, by s0/k" of docs/model.md):
// the largest tension error |T/T_exact - 1| and the error over the method's own estimate,
// over the poses of issue 9's sweep (RandomPosesAroundFocalLaw: 45 deg off axis, +-5 m,
// extra rotations of 2 to 5 deg per axis, seed 20260101) that have an equilibrium within
// the model's range. The reflector is left out of the model: it would refuse a few of
// them, and the accuracy of the methods does not depend on it.
// Run: build/bench/statics_accuracy [poses, default 10000]
#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "fastcal/statics.h"
#include "fastcal/trajectory.h"

namespace fastcal {
namespace {

constexpr std::array<double, 9> kEdges = {0.0, 1.0, 1.01, 1.02, 1.05, 1.1, 1.2, 1.3, 1.5};
constexpr int kBins = static_cast<int>(kEdges.size()) - 1;

struct Bin {
  int poses = 0, ok = 0;
  double max_error = 0.0;
  double min_ratio = HUGE_VAL, max_ratio = 0.0;  // error / estimate
};

struct Variant {
  const char* name;
  StaticsOptions options;
};

int Run(int count) {
  std::vector<Pose> poses;
  std::string error;
  if (!RandomPosesAroundFocalLaw(EdgeSweepSpec(count, 20260101), &poses, &error)) {
    std::fprintf(stderr, "statics_accuracy: %s\n", error.c_str());
    return 1;
  }
  CableRobot robot = CableRobot::NominalFast();
  robot.reflector.reset();
  std::vector<Variant> variants(4);
  variants[0] = {"aas, no limit", StaticsOptions()};
  variants[0].options.method = StaticsMethod::kAas;
  variants[0].options.aas_max_relative_error = HUGE_VAL;
  variants[1] = {"aas (default: 1% limit)", StaticsOptions()};
  variants[1].options.method = StaticsMethod::kAas;
  variants[2] = {"aas-refined, one step (ok where it converges)", StaticsOptions()};
  variants[2].options.method = StaticsMethod::kAasRefined;
  variants[2].options.refined_relative_tolerance = HUGE_VAL;
  variants[2].options.max_refinement_steps = 1;
  variants[3] = {"aas-refined (default: 1e-6)", StaticsOptions()};
  variants[3].options.method = StaticsMethod::kAasRefined;
  std::vector<std::array<Bin, kBins>> bins(variants.size());
  for (const Pose& pose : poses) {
    StaticsSolution exact;
    if (SolveStatics(robot, pose, StaticsOptions(), &exact) != StaticsStatus::kOk) continue;
    double ratio = 0.0;
    for (const CableSolution& c : exact.cables) {
      ratio = std::max(ratio, c.unstretched_length_m / c.chord_length_m);
    }
    const int b =
        std::min<int>(kBins - 1, std::upper_bound(kEdges.begin() + 1, kEdges.end() - 1, ratio) -
                                     kEdges.begin() - 1);
    for (size_t v = 0; v < variants.size(); ++v) {
      Bin& bin = bins[v][b];
      ++bin.poses;
      StaticsSolution s;
      if (SolveStatics(robot, pose, variants[v].options, &s) != StaticsStatus::kOk) continue;
      ++bin.ok;
      double e = 0.0;
      for (int i = 0; i < kNumCables; ++i) {
        e = std::max(e,
                     std::abs(s.cables[i].lower_tension_n / exact.cables[i].lower_tension_n - 1));
      }
      bin.max_error = std::max(bin.max_error, e);
      if (e > 1e-11 && s.error_estimate > 0.0) {  // above the reference's rounding
        bin.min_ratio = std::min(bin.min_ratio, e / s.error_estimate);
        bin.max_ratio = std::max(bin.max_ratio, e / s.error_estimate);
      }
    }
  }
  for (size_t v = 0; v < variants.size(); ++v) {
    std::printf("%s\n  s0/k        poses     ok  max error  error/estimate\n", variants[v].name);
    for (int b = 0; b < kBins; ++b) {
      const Bin& bin = bins[v][b];
      if (bin.poses == 0) continue;
      std::printf("  %.2f-%.2f  %6d %6d  %9.2g  ", kEdges[b], kEdges[b + 1], bin.poses, bin.ok,
                  bin.max_error);
      if (bin.max_ratio > 0.0) {
        std::printf("%.2f..%.3g\n", bin.min_ratio, bin.max_ratio);
      } else {
        std::printf("-\n");
      }
    }
  }
  return 0;
}

}  // namespace
}  // namespace fastcal

int main(int argc, char** argv) { return fastcal::Run(argc > 1 ? std::atoi(argv[1]) : 10000); }
