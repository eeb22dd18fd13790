// The diagnosis of a model that cannot solve many rows of a dataset (unsolvable_rows.h).
#include "fastcal/unsolvable_rows.h"

#include <set>

#include "fastcal/model_plausibility.h"
#include "fastcal/plausibility.h"

namespace fastcal {

UnsolvableRows DiagnoseUnsolvableRows(const CableRobot& model, const std::string& model_name,
                                      const Dataset& data,
                                      const std::vector<AttitudeSource>& attitudes,
                                      const std::vector<StaticsMethod>& methods) {
  constexpr size_t kNamed = 3;
  constexpr int kFewestForNominalTest = 2;
  UnsolvableRows d;
  d.rows = static_cast<int>(data.samples.size());
  Dataset kept = data;
  const size_t skipped_before = kept.skipped.size();
  d.failed = SkipUnsolvableSamples(model, model_name, attitudes, methods, &kept);
  if (d.failed == 0) return d;
  d.first = kept.skipped[skipped_before];
  // The failed rows alone, tried with the nominal model.
  std::set<int> kept_lines;
  for (const Sample& s : kept.samples) kept_lines.insert(s.line);
  Dataset failed = data;
  failed.samples.clear();
  for (const Sample& s : data.samples) {
    if (!kept_lines.count(s.line)) failed.samples.push_back(s);
  }
  d.solved_by_nominal =
      d.failed - SkipUnsolvableSamples(CableRobot::NominalFast(), "the nominal FAST model",
                                       attitudes, methods, &failed);
  d.model_likely = d.failed >= kFewestForNominalTest && 2 * d.solved_by_nominal >= d.failed;
  d.furthest_from_nominal = FurthestFromNominal(model, PlausibilityLimits(), kNamed);
  return d;
}

std::string DescribeUnsolvableRows(const UnsolvableRows& d, const std::string& model_name) {
  std::string text = model_name + " cannot solve " + std::to_string(d.failed) + " of " +
                     std::to_string(d.rows) + " rows (the nominal FAST model solves " +
                     std::to_string(d.solved_by_nominal) +
                     " of them): the model or the spec is the likely cause, not the data";
  if (!d.furthest_from_nominal.empty()) {
    text += "; furthest from nominal: ";
    for (size_t k = 0; k < d.furthest_from_nominal.size(); ++k) {
      text += (k ? ", " : "") + d.furthest_from_nominal[k];
    }
  }
  return text + ". First: " + d.first;
}

}  // namespace fastcal
