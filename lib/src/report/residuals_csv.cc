// residuals.csv (residuals_csv.h); moved from the command line's calibrate and evaluate
// (issue 54: every output of a run written by one layer, the report's).
#include "fastcal/residuals_csv.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <sstream>

#include "fastcal/internal/sample_chunks.h"
#include "fastcal/internal/units.h"

namespace fastcal {
namespace {

using internal::kNPerKn;

// Appends FormatDouble(value) (10 significant digits, printf's %.10g, no "-0"): by
// to_chars, several times faster than snprintf, which counts at 10^6 rows of 27 numbers.
void AppendNumber(double value, std::string* out) {
  if (value == 0.0) {
    *out += '0';
    return;
  }
  char buf[48];
  const std::to_chars_result r =
      std::to_chars(buf, buf + sizeof(buf), value, std::chars_format::general, 10);
  out->append(buf, r.ptr);
}

}  // namespace

// residuals.csv's comment lines and column line: `variants` are the RMS table's rows, of
// which those with predictions (`predicted[v]`) get columns; `samples` how many the file
// is one in K of.
std::string ResidualsHeader(const std::vector<VariantEvaluation>& variants,
                            const std::vector<bool>& predicted, size_t samples, int every_k) {
  const size_t every = static_cast<size_t>(std::max(1, every_k));
  std::ostringstream head;
  for (size_t v = 0; v < variants.size(); ++v) {
    if (predicted[v]) head << "# v" << v + 1 << " = " << variants[v].name << "\n";
  }
  head << "# model minus measured is <variant>_T<i>_kN - T<i>_kN\n";
  if (every > 1) {
    head << "# one sample in " << every << " of the " << samples << " (--residuals-every=" << every
         << "), from the first\n";
  }
  head << "line,time_s,held_out,gross_error_cables";
  for (int i = 1; i <= kNumCables; ++i) head << ",T" << i << "_kN";
  for (size_t v = 0; v < variants.size(); ++v) {
    if (!predicted[v]) continue;
    for (int i = 1; i <= kNumCables; ++i) head << ",v" << v + 1 << "_T" << i << "_kN";
  }
  head << "\n";
  return head.str();
}

// One row of residuals.csv: the sample's line and time, whether it was held out, the
// cables whose reading was a gross error ("3", "1 4"; empty for none), the measured and
// each drawn variant's predicted tensions.
void AppendResidualsRow(int line, double time_s, bool held_out,
                        const std::array<bool, kNumCables>* gross,
                        const std::array<double, kNumCables>& measured_n,
                        const std::vector<const std::array<double, kNumCables>*>& predicted_n,
                        std::string* out) {
  *out += std::to_string(line);
  *out += ',';
  AppendNumber(time_s, out);
  *out += held_out ? ",1," : ",0,";
  bool first = true;
  for (int i = 0; gross != nullptr && i < kNumCables; ++i) {
    if (!(*gross)[i]) continue;
    if (!first) *out += ' ';
    *out += static_cast<char>('1' + i);
    first = false;
  }
  for (double t : measured_n) {
    *out += ',';
    AppendNumber(t / kNPerKn, out);
  }
  for (const std::array<double, kNumCables>* p : predicted_n) {
    for (double t : *p) {
      *out += ',';
      AppendNumber(t / kNPerKn, out);
    }
  }
  *out += '\n';
}

// calibrate's residuals.csv, one row per sample (one in --residuals-every): measured and
// each variant's predicted tensions, the held_out flag and the gross errors
// (`excluded`). Written into `dir` a batch of rows at a time, the rows of a batch
// formatted on `threads` threads and written in file order: memory independent of the
// number of samples (the whole file was one ~300 MB string at 10^6 samples).
bool WriteResidualsFile(const std::string& dir, const Dataset& data,
                        const std::vector<VariantEvaluation>& variants,
                        const std::vector<bool>& held_out, const ReadingMask& excluded, int every_k,
                        int threads, std::string* error) {
  constexpr int kChunkRows = 2048, kBatchChunks = 16;
  const std::string path = dir + "/residuals.csv";
  std::FILE* file = std::fopen(path.c_str(), "wbx");
  if (file == nullptr) {
    *error = path + ": cannot create: " + std::strerror(errno);
    return false;
  }
  const size_t every = static_cast<size_t>(std::max(1, every_k));
  std::vector<bool> predicted;
  for (const VariantEvaluation& v : variants) predicted.push_back(!v.predicted_n.empty());
  const std::string header = ResidualsHeader(variants, predicted, data.samples.size(), every_k);
  bool written = std::fwrite(header.data(), 1, header.size(), file) == header.size();
  const long long rows = static_cast<long long>((data.samples.size() + every - 1) / every);
  std::vector<std::string> texts(kBatchChunks);
  for (long long first = 0; written && first < rows; first += kChunkRows * kBatchChunks) {
    const int batch_rows =
        static_cast<int>(std::min<long long>(kChunkRows * kBatchChunks, rows - first));
    internal::ForEachChunk(
        batch_rows, threads,
        [&](int begin, int end) {
          std::string& text = texts[begin / kChunkRows];
          text.clear();
          std::vector<const std::array<double, kNumCables>*> row_predicted;
          for (int k = begin; k < end; ++k) {
            const size_t n = static_cast<size_t>(first + k) * every;
            row_predicted.clear();
            for (const VariantEvaluation& v : variants) {
              if (!v.predicted_n.empty()) row_predicted.push_back(&v.predicted_n[n]);
            }
            const Sample& s = data.samples[n];
            AppendResidualsRow(s.line, s.time_s, !held_out.empty() && held_out[n],
                               n < excluded.size() ? &excluded[n] : nullptr, s.tension_n,
                               row_predicted, &text);
          }
          return -1;
        },
        kChunkRows);
    for (int c = 0; written && c * kChunkRows < batch_rows; ++c) {
      written = std::fwrite(texts[c].data(), 1, texts[c].size(), file) == texts[c].size();
    }
  }
  written = written && std::fflush(file) == 0 && ::fsync(::fileno(file)) == 0;
  const bool closed = std::fclose(file) == 0;
  if (!written || !closed) {
    *error = path + ": cannot write: " + std::strerror(errno);
    return false;
  }
  return true;
}

// residuals.csv of a streamed evaluation, written into `dir` a sample at a time (the
// same bytes WriteResidualsFile gives for the same samples).
bool WriteStreamedResiduals(const std::string& dir, const StreamedEvaluation& evaluation,
                            int every_k, std::string* error) {
  constexpr size_t kFlushBytes = 1 << 20;
  const std::string path = dir + "/residuals.csv";
  std::FILE* file = std::fopen(path.c_str(), "wbx");
  if (file == nullptr) {
    *error = path + ": cannot create: " + std::strerror(errno);
    return false;
  }
  const std::vector<VariantEvaluation>& variants = evaluation.variants();
  std::vector<bool> predicted(variants.size(), false);
  for (int v = 0; v < evaluation.predicted_variants(); ++v) predicted[v] = true;
  std::string buffer = ResidualsHeader(variants, predicted, evaluation.samples(), every_k);
  const long long every = std::max(1, every_k);
  bool written = true;
  std::vector<const std::array<double, kNumCables>*> row_predicted;
  const bool read = evaluation.ForEach(
      [&](const EvaluatedSample& s) {
        if (s.index % every != 0) return;
        row_predicted.clear();
        for (const auto& p : s.predicted_n) row_predicted.push_back(&p);
        AppendResidualsRow(s.line, s.time_s, false, &s.gross, s.measured_n, row_predicted, &buffer);
        if (buffer.size() < kFlushBytes) return;
        written = written && std::fwrite(buffer.data(), 1, buffer.size(), file) == buffer.size();
        buffer.clear();
      },
      error);
  written = written && std::fwrite(buffer.data(), 1, buffer.size(), file) == buffer.size() &&
            std::fflush(file) == 0 && ::fsync(::fileno(file)) == 0;
  const bool closed = std::fclose(file) == 0;
  if (!read) return false;
  if (!written || !closed) {
    *error = path + ": cannot write: " + std::strerror(errno);
    return false;
  }
  return true;
}

}  // namespace fastcal
