// The report's small document model (report.h): headings, paragraphs, lists, tables,
// preformatted blocks and SVG figures, built once by the report's sections and rendered as
// Markdown and as HTML (report.cc); and the number formatting every section shares.
// Non-finite values read "n/a", never "nan" or "inf".
#ifndef FASTCAL_INTERNAL_REPORT_DOCUMENT_H_
#define FASTCAL_INTERNAL_REPORT_DOCUMENT_H_

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "fastcal/internal/number_text.h"
#include "fastcal/internal/units.h"

namespace fastcal::internal {

inline constexpr double kReportPercent = 100.0;

// "-0.000" and "+0.00" -> "0.000", "0.00".
inline std::string DropSignOfZero(std::string s) {
  if (!s.empty() && (s[0] == '-' || s[0] == '+') &&
      s.find_first_not_of("0.", 1) == std::string::npos) {
    s.erase(0, 1);
  }
  return s;
}

inline std::string Printf(const char* format, double v) {
  if (!std::isfinite(v)) return "n/a";
  return DropSignOfZero(internal::FormatDouble(format, v));
}
inline std::string Sig6(double v) { return Printf("%.6g", v); }
inline std::string Sig3(double v) { return Printf("%.3g", v); }
inline std::string Kn3(double v_n) { return Printf("%.3f", v_n / kNPerKn); }
inline std::string Pct(double fraction, const char* format = "%.3g") {
  return Printf(format, fraction * kReportPercent);
}
inline std::string Int(long long v) { return std::to_string(v); }
// An estimate to the precision its uncertainty supports: down to one digit below the
// second significant digit of sigma ("0.24413" for 0.244125 +- 0.0044); 6 significant
// digits when there is no usable sigma. summary.json keeps every digit.
inline std::string EstimateText(double value, double sigma) {
  constexpr int kMaxDecimals = 12;
  if (!std::isfinite(value) || !std::isfinite(sigma) || sigma <= 0.0) return Sig6(value);
  const int decimals =
      std::clamp(2 - static_cast<int>(std::floor(std::log10(sigma))), 0, kMaxDecimals);
  return DropSignOfZero(internal::FormatDouble("%." + std::to_string(decimals) + "f", value));
}

struct Span {
  enum Kind { kPlain, kCode, kBold, kSwatch } kind;
  std::string text;  // for kSwatch: the colour
};

// Inline text: plain, code, bold, and (HTML only) a colour swatch matching a plot series.
class Text {
 public:
  Text() = default;
  Text(const std::string& plain) { Plain(plain); }  // NOLINT: implicit by design
  Text(const char* plain) { Plain(plain); }         // NOLINT
  Text& Plain(const std::string& s) { return Add(Span::kPlain, s); }
  Text& Code(const std::string& s) { return Add(Span::kCode, s); }
  Text& Bold(const std::string& s) { return Add(Span::kBold, s); }
  Text& Swatch(const std::string& colour) { return Add(Span::kSwatch, colour); }
  const std::vector<Span>& spans() const { return spans_; }

 private:
  Text& Add(Span::Kind kind, const std::string& s) {
    if (!s.empty()) spans_.push_back({kind, s});
    return *this;
  }
  std::vector<Span> spans_;
};

struct Table {
  Text caption;
  std::vector<Text> header;
  std::vector<bool> right_align;  // per column (numbers)
  std::vector<std::vector<Text>> rows;
};

enum class Target { kBoth, kMarkdownOnly, kHtmlOnly };

// How a banner (Document::Banner) looks: green for a sound result, amber for one to read
// with care, red for one not to use as it stands, blue for information.
enum class Tone { kGood, kCaution, kBad, kInfo };

struct Block {
  enum Kind { kHeading, kParagraph, kList, kTable, kPre, kFigure, kBanner } kind = kParagraph;
  Target target = Target::kBoth;
  int level = 2;                  // kHeading
  Text text;                      // kHeading, kParagraph; kPre and kFigure: summary / caption
  std::vector<Text> items;        // kList
  Table table;                    // kTable
  std::string pre;                // kPre: preformatted text
  bool collapsed = false;         // kPre: <details> in HTML
  std::vector<std::string> svgs;  // kFigure: one or more charts, laid out in a grid
  Tone tone = Tone::kInfo;        // kBanner
};

class Document {
 public:
  void Heading(int level, const Text& text) {
    Block b;
    b.kind = Block::kHeading;
    b.level = level;
    b.text = text;
    blocks_.push_back(std::move(b));
  }
  void Paragraph(const Text& text, Target target = Target::kBoth) {
    Block b;
    b.kind = Block::kParagraph;
    b.target = target;
    b.text = text;
    blocks_.push_back(std::move(b));
  }
  void List(std::vector<Text> items) {
    if (items.empty()) return;
    Block b;
    b.kind = Block::kList;
    b.items = std::move(items);
    blocks_.push_back(std::move(b));
  }
  void AddTable(Table table, Target target = Target::kBoth) {
    Block b;
    b.kind = Block::kTable;
    b.target = target;
    b.table = std::move(table);
    blocks_.push_back(std::move(b));
  }
  void Pre(const Text& summary, const std::string& text, bool collapsed) {
    Block b;
    b.kind = Block::kPre;
    b.text = summary;
    b.pre = text;
    b.collapsed = collapsed;
    blocks_.push_back(std::move(b));
  }
  void Figure(std::vector<std::string> svgs, const Text& caption) {
    Block b;
    b.kind = Block::kFigure;
    b.target = Target::kHtmlOnly;
    b.svgs = std::move(svgs);
    b.text = caption;
    blocks_.push_back(std::move(b));
  }
  // A paragraph set apart by colour (HTML: a tinted box with a coloured edge; Markdown: a
  // quote), e.g. the verdict, so that "model incomplete" never looks like "good fit".
  void Banner(Tone tone, const Text& text) {
    Block b;
    b.kind = Block::kBanner;
    b.tone = tone;
    b.text = text;
    blocks_.push_back(std::move(b));
  }
  const std::vector<Block>& blocks() const { return blocks_; }
  std::string title;

 private:
  std::vector<Block> blocks_;
};

// The document as a self-contained HTML page in the report's style (report.cc): the
// calibration report, design.html and solve's trajectory plot share it.
std::string RenderHtmlPage(const Document& doc);

// The document as Markdown (report.md): tables as pipe tables, figures as their captions.
std::string RenderMarkdown(const Document& doc);

}  // namespace fastcal::internal

#endif  // FASTCAL_INTERNAL_REPORT_DOCUMENT_H_
