// residuals.csv, a calibration's or an evaluation's model-minus-measured per sample (docs/
// cli.md, "calibrate"): comment lines naming the variants, then per sample (one in K) its
// line and time, whether it was held out, the cables whose reading was a gross error, the
// measured and each drawn variant's predicted tensions (kN, 10 significant digits). Written
// into the run's output directory a batch at a time: memory independent of the samples.
#ifndef FASTCAL_RESIDUALS_CSV_H_
#define FASTCAL_RESIDUALS_CSV_H_

#include <array>
#include <string>
#include <vector>

#include "fastcal/calibration.h"
#include "fastcal/dataset.h"
#include "fastcal/evaluation.h"
#include "fastcal/evaluation_stream.h"

namespace fastcal {

// The comment lines and the column line: `variants` are the RMS table's rows, of which
// those with predictions (`predicted[v]`) get columns; `samples` how many the file is one
// in `every_k` of.
std::string ResidualsHeader(const std::vector<VariantEvaluation>& variants,
                            const std::vector<bool>& predicted, size_t samples, int every_k);
// Appends one row (the sample's line, time, held-out flag, gross-error cables ("3", "1
// 4"; empty for none), measured and predicted tensions in N, written in kN).
void AppendResidualsRow(int line, double time_s, bool held_out,
                        const std::array<bool, kNumCables>* gross,
                        const std::array<double, kNumCables>& measured_n,
                        const std::vector<const std::array<double, kNumCables>*>& predicted_n,
                        std::string* out);
// A calibration's: `dir`/residuals.csv, every `every_k`-th sample of `data` (>= 1), the rows
// formatted on `threads` threads. False with *error naming the file.
bool WriteResidualsFile(const std::string& dir, const Dataset& data,
                        const std::vector<VariantEvaluation>& variants,
                        const std::vector<bool>& held_out, const ReadingMask& excluded, int every_k,
                        int threads, std::string* error);
// A streamed evaluation's, the same bytes for the same samples.
bool WriteStreamedResiduals(const std::string& dir, const StreamedEvaluation& evaluation,
                            int every_k, std::string* error);

}  // namespace fastcal

#endif  // FASTCAL_RESIDUALS_CSV_H_
