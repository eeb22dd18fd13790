// SVG chart writer for the HTML calibration report (svg_plot.h): nice ticks, compact
// number formatting, layout, and the line, histogram, grouped-bar and heatmap charts.
#include "fastcal/svg_plot.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include "fastcal/internal/number_text.h"
#include "fastcal/time_text.h"

namespace fastcal {
namespace {

// Okabe-Ito, ordered for contrast on white (the pale yellow last).
constexpr std::array<const char*, 8> kPalette = {"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                                 "#E69F00", "#56B4E9", "#000000", "#F0E442"};

constexpr int kMinWidthPx = 240, kMinHeightPx = 160, kMaxSizePx = 20000;
constexpr double kFontPx = 12.0, kTickFontPx = 11.0, kTitleFontPx = 15.0;
// Average glyph advance of Helvetica/Arial in em; slightly generous for safety.
constexpr double kCharEm = 0.6;
constexpr double kLegendRowPx = 18.0, kLegendSwatchPx = 22.0, kLegendGapPx = 18.0;
constexpr double kTickLenPx = 4.0;
constexpr const char* kGridColour = "#e3e3e3";
constexpr const char* kAxisColour = "#444444";
constexpr const char* kTextColour = "#222222";
constexpr double kMinOpacity = 0.05;

const char* Colour(size_t index) { return kPalette[index % kPalette.size()]; }

// Pixel coordinate with one decimal, trailing ".0" dropped.
std::string Px(double v) {
  if (!std::isfinite(v)) return "0";
  v = std::clamp(v, -1e7, 1e7);
  std::string s = internal::FormatDouble("%.1f", v);
  if (s.size() > 2 && s.compare(s.size() - 2, 2, ".0") == 0) s.resize(s.size() - 2);
  if (s == "-0") s = "0";
  return s;
}

std::string Fixed(double v, int decimals) {
  return internal::WithoutNegativeZero(
      internal::FormatDouble("%." + std::to_string(std::clamp(decimals, 0, 20)) + "f", v));
}

std::string Scientific(double v, int decimals) {
  return internal::FormatDouble("%." + std::to_string(std::clamp(decimals, 0, 16)) + "e", v);
}

// Drops trailing zeros of the fraction (and a bare '.') in "12.50" or "1.20e+05".
std::string StripZeros(std::string s) {
  const size_t dot = s.find('.');
  if (dot == std::string::npos) return s;
  const size_t e = s.find('e');
  const size_t end = e == std::string::npos ? s.size() : e;
  size_t last = end;
  while (last > dot + 1 && s[last - 1] == '0') --last;
  if (last == dot + 1) last = dot;
  return s.substr(0, last) + s.substr(end);
}

// Compact number with `sig` significant digits: fixed notation for 1e-3 <= |v| < 1e5,
// scientific otherwise ("150", "0.25", "1e+05").
std::string Compact(double v, int sig) {
  if (!std::isfinite(v)) return "n/a";
  if (v == 0.0) return "0";
  const double a = std::fabs(v);
  if (a >= 1e-3 && a < 1e5) {
    const int exponent = static_cast<int>(std::floor(std::log10(a)));
    if (exponent >= sig) {  // 1234.5 -> 1230: round the integer digits too.
      const double unit = std::pow(10.0, exponent - sig + 1);
      v = std::round(v / unit) * unit;
    }
    return StripZeros(Fixed(v, std::max(0, sig - 1 - exponent)));
  }
  return StripZeros(Scientific(v, sig - 1));
}

int FloorLog10(double v) { return static_cast<int>(std::floor(std::log10(v) + 1e-9)); }

// Labels for evenly spaced ticks, all with the same number of decimals.
std::vector<std::string> TickLabels(const std::vector<double>& ticks) {
  std::vector<std::string> labels;
  if (ticks.empty()) return labels;
  const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : 1.0;
  double max_abs = 0.0;
  for (double t : ticks) max_abs = std::max(max_abs, std::fabs(t));
  const int step_exp = FloorLog10(step);
  const bool fixed = max_abs == 0.0 || (max_abs >= 1e-3 && max_abs < 1e5);
  for (double t : ticks) {
    if (fixed) {
      labels.push_back(Fixed(t, std::max(0, -step_exp)));
    } else if (t == 0.0) {
      labels.push_back("0");
    } else {
      labels.push_back(Scientific(t, std::clamp(FloorLog10(max_abs) - step_exp, 0, 15)));
    }
  }
  return labels;
}

double TextWidth(const std::string& text, double font_px) {
  size_t code_points = 0;
  for (unsigned char c : text) code_points += (c & 0xC0) != 0x80;
  return static_cast<double>(code_points) * font_px * kCharEm;
}

double MaxTextWidth(const std::vector<std::string>& texts, double font_px) {
  double w = 0.0;
  for (const std::string& t : texts) w = std::max(w, TextWidth(t, font_px));
  return w;
}

// Orders [lo, hi] and pads a degenerate range by 1% of |centre| (by 1 if it is 0).
void PadDegenerateRange(double* lo, double* hi) {
  if (*lo > *hi) std::swap(*lo, *hi);
  const double max_abs = std::max(std::fabs(*lo), std::fabs(*hi));
  if (*hi - *lo <= 1e-12 * max_abs || *hi - *lo < 1e-290) {
    const double centre = *lo + 0.5 * (*hi - *lo);
    const double pad = centre == 0.0 ? 1.0 : 0.01 * std::fabs(centre);
    *lo = centre - pad;
    *hi = centre + pad;
  }
}

std::vector<double> NiceTicksWithMinStep(double lo, double hi, int target, double min_step) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) return {};
  target = std::clamp(target, 2, 50);
  PadDegenerateRange(&lo, &hi);
  const double span = hi - lo;
  if (!std::isfinite(span)) return {lo, hi};
  const double raw = span / target;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double norm = raw / magnitude;
  // Nearest of 1, 2, 5, 10 on a log scale.
  double step = (norm < 1.4142   ? 1.0
                 : norm < 3.1623 ? 2.0
                 : norm < 7.0711 ? 5.0
                                 : 10.0) *
                magnitude;
  step = std::max(step, min_step);
  const double k_min = std::floor(lo / step + 1e-9);
  double k_max = std::ceil(hi / step - 1e-9);
  if (k_max <= k_min) k_max = k_min + 1.0;
  // Dividing by an integer keeps e.g. 3 * 0.1 at the double nearest 0.3.
  const double inverse = step < 1.0 ? std::round(1.0 / step) : 0.0;
  std::vector<double> ticks;
  for (double k = k_min; k <= k_max && ticks.size() < 1000; k += 1.0) {
    ticks.push_back(step < 1.0 ? k / inverse : k * step);
  }
  return ticks;
}

// ---- SVG pieces -----------------------------------------------------------------------

struct Box {
  double x = 0, y = 0, w = 0, h = 0;
};

// Linear map from [lo, hi] to pixels [p_lo, p_hi].
struct Scale {
  double lo, hi, p_lo, p_hi;
  double operator()(double v) const { return p_lo + (v - lo) / (hi - lo) * (p_hi - p_lo); }
};

void Text(std::string* out, double x, double y, const std::string& text, const char* anchor,
          double font_px, const std::string& extra = "") {
  *out += "<text x=\"" + Px(x) + "\" y=\"" + Px(y) + "\"";
  if (anchor[0] != '\0') *out += std::string(" text-anchor=\"") + anchor + "\"";
  if (font_px != kFontPx) *out += " font-size=\"" + Px(font_px) + "\"";
  if (!extra.empty()) *out += " " + extra;
  *out += ">" + XmlEscape(text) + "</text>\n";
}

void Line(std::string* out, double x1, double y1, double x2, double y2, const char* colour,
          double width = 1.0, const std::string& extra = "") {
  *out += "<line x1=\"" + Px(x1) + "\" y1=\"" + Px(y1) + "\" x2=\"" + Px(x2) + "\" y2=\"" + Px(y2) +
          "\" stroke=\"" + colour + "\"";
  if (width != 1.0) *out += " stroke-width=\"" + Px(width) + "\"";
  if (!extra.empty()) *out += " " + extra;
  *out += "/>\n";
}

std::string Rotate(double degrees, double x, double y) {
  return "transform=\"rotate(" + Px(degrees) + " " + Px(x) + " " + Px(y) + ")\"";
}

struct Size {
  int w, h;
};

Size ClampedSize(const PlotOptions& options) {
  return {std::clamp(options.width_px, kMinWidthPx, kMaxSizePx),
          std::clamp(options.height_px, kMinHeightPx, kMaxSizePx)};
}

// Opens the <svg>, writes background and title; the caller closes with CloseSvg.
void OpenSvg(std::string* out, Size size, const std::string& title) {
  const std::string w = std::to_string(size.w), h = std::to_string(size.h);
  *out += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + w + "\" height=\"" + h +
          "\" viewBox=\"0 0 " + w + " " + h + "\" role=\"img\">\n";
  if (!title.empty()) *out += "<title>" + XmlEscape(title) + "</title>\n";
  *out += "<rect width=\"" + w + "\" height=\"" + h + "\" fill=\"#ffffff\"/>\n";
  *out += std::string("<g font-family=\"Helvetica,Arial,sans-serif\" font-size=\"") + Px(kFontPx) +
          "\" fill=\"" + kTextColour + "\">\n";
  if (!title.empty()) {
    Text(out, size.w / 2.0, 21.0, title, "middle", kTitleFontPx, "font-weight=\"bold\"");
  }
}

void CloseSvg(std::string* out) { *out += "</g>\n</svg>"; }

double TitleBottom(const PlotOptions& options) { return options.title.empty() ? 8.0 : 30.0; }

std::string NoDataSvg(const PlotOptions& options, const std::string& message) {
  const Size size = ClampedSize(options);
  std::string out;
  OpenSvg(&out, size, options.title);
  Text(&out, size.w / 2.0, size.h / 2.0, message, "middle", 14.0, "fill=\"#777777\"");
  CloseSvg(&out);
  return out;
}

// ---- Legend ---------------------------------------------------------------------------

enum class Swatch { kLine, kDashed, kMarker, kBox, kSolidBox, kMark };

struct LegendItem {
  std::string label;
  const char* colour;
  Swatch swatch;
  double opacity = 1.0;                 // kMarker: of the dot, as drawn in the chart.
  MarkShape shape = MarkShape::kCross;  // kMark: as drawn in the chart.
  bool filled = false;                  // kMark: a closed shape filled dark
};

constexpr const char* kMarkColour = "#111111";

// Path data of a mark of half-size r centred at (x, y).
std::string MarkPath(MarkShape shape, double x, double y, double r) {
  const std::string X = Px(x), Y = Px(y);
  auto at = [](double a, double b) { return Px(a) + " " + Px(b); };
  switch (shape) {
    case MarkShape::kCross:
      return "M" + at(x - r, y - r) + "L" + at(x + r, y + r) + "M" + at(x - r, y + r) + "L" +
             at(x + r, y - r);
    case MarkShape::kPlus:
      return "M" + at(x - r, y) + "L" + at(x + r, y) + "M" + at(x, y - r) + "L" + at(x, y + r);
    case MarkShape::kTriangleUp:
      return "M" + at(x, y - r) + "L" + at(x + 0.87 * r, y + 0.5 * r) + "L" +
             at(x - 0.87 * r, y + 0.5 * r) + "Z";
    case MarkShape::kTriangleDown:
      return "M" + at(x, y + r) + "L" + at(x + 0.87 * r, y - 0.5 * r) + "L" +
             at(x - 0.87 * r, y - 0.5 * r) + "Z";
    case MarkShape::kSquare:
      return "M" + at(x - 0.75 * r, y - 0.75 * r) + "h" + Px(1.5 * r) + "v" + Px(1.5 * r) + "h" +
             Px(-1.5 * r) + "Z";
    case MarkShape::kDiamond:
      return "M" + at(x, y - r) + "L" + at(x + r, y) + "L" + at(x, y + r) + "L" + at(x - r, y) +
             "Z";
    case MarkShape::kCircle:
      return "M" + at(x - 0.8 * r, y) + "a" + Px(0.8 * r) + " " + Px(0.8 * r) + " 0 1 0 " +
             Px(1.6 * r) + " 0a" + Px(0.8 * r) + " " + Px(0.8 * r) + " 0 1 0 " + Px(-1.6 * r) +
             " 0Z";
  }
  return "";
}

// A mark drawn on a white halo, so that it reads on light and dark cells alike.
void DrawMark(std::string* out, MarkShape shape, double x, double y, double r, bool filled,
              const std::string& extra = "") {
  const std::string d = MarkPath(shape, x, y, r);
  const bool closed = shape != MarkShape::kCross && shape != MarkShape::kPlus;
  *out += "<path" + (extra.empty() ? "" : " " + extra) + " d=\"" + d + "\" fill=\"" +
          (closed ? "#ffffff" : "none") + "\" stroke=\"#ffffff\" stroke-width=\"3.2\"/>\n";
  *out += "<path d=\"" + d + "\" fill=\"" + (closed && filled ? kMarkColour : "none") +
          "\" stroke=\"" + kMarkColour + "\" stroke-width=\"1.3\" stroke-linejoin=\"round\"/>\n";
}

double LegendItemWidth(const LegendItem& item) {
  return kLegendSwatchPx + 5.0 + TextWidth(item.label, kFontPx);
}

// Splits items into rows no wider than `width`.
std::vector<std::vector<size_t>> LegendRows(const std::vector<LegendItem>& items, double width) {
  std::vector<std::vector<size_t>> rows;
  double used = 0.0;
  for (size_t i = 0; i < items.size(); ++i) {
    const double w = LegendItemWidth(items[i]);
    if (rows.empty() || used + kLegendGapPx + w > width) {
      rows.emplace_back();
      used = w;
    } else {
      used += kLegendGapPx + w;
    }
    rows.back().push_back(i);
  }
  return rows;
}

// Draws the rows centred horizontally in `svg_width`, starting at `top`.
void DrawLegend(std::string* out, const std::vector<LegendItem>& items,
                const std::vector<std::vector<size_t>>& rows, double svg_width, double top) {
  for (size_t r = 0; r < rows.size(); ++r) {
    double row_width = 0.0;
    for (size_t i : rows[r]) row_width += LegendItemWidth(items[i]);
    row_width += kLegendGapPx * static_cast<double>(rows[r].size() - 1);
    double x = std::max(4.0, (svg_width - row_width) / 2.0);
    const double mid = top + kLegendRowPx * (static_cast<double>(r) + 0.5);
    for (size_t i : rows[r]) {
      const LegendItem& item = items[i];
      switch (item.swatch) {
        case Swatch::kLine:
        case Swatch::kDashed:
          Line(out, x, mid, x + kLegendSwatchPx, mid, item.colour, 2.0,
               item.swatch == Swatch::kDashed ? "stroke-dasharray=\"6 4\"" : "");
          break;
        case Swatch::kMarker:
          *out += "<circle cx=\"" + Px(x + kLegendSwatchPx / 2) + "\" cy=\"" + Px(mid) +
                  "\" r=\"3.5\" fill=\"" + item.colour + "\"" +
                  (item.opacity < 1.0 ? " fill-opacity=\"" + Compact(item.opacity, 2) + "\"" : "") +
                  "/>\n";
          break;
        case Swatch::kMark:
          DrawMark(out, item.shape, x + kLegendSwatchPx / 2, mid, 4.5, item.filled);
          break;
        case Swatch::kBox:
        case Swatch::kSolidBox:
          *out += "<rect x=\"" + Px(x + 4) + "\" y=\"" + Px(mid - 5) +
                  "\" width=\"14\" height=\"10\" fill=\"" + item.colour + "\"" +
                  (item.swatch == Swatch::kBox ? " fill-opacity=\"0.45\"" : "") + " stroke=\"" +
                  item.colour + "\"/>\n";
          break;
      }
      Text(out, x + kLegendSwatchPx + 5.0, mid + 4.0, item.label, "", kFontPx);
      x += LegendItemWidth(item) + kLegendGapPx;
    }
  }
}

// ---- Cartesian frame ------------------------------------------------------------------

// Layout of a chart with a legend under the title, a y axis on the left and an x axis
// below. Vertical extents are fixed first; the plot's left edge depends on the y tick
// labels, which depend on the plot height.
struct Frame {
  Size size{0, 0};
  std::vector<LegendItem> legend;
  std::vector<std::vector<size_t>> legend_rows;
  double legend_top = 0.0;
  Box box;
};

Frame StartFrame(const PlotOptions& options, std::vector<LegendItem> legend,
                 double x_labels_height) {
  Frame f;
  f.size = ClampedSize(options);
  f.legend = std::move(legend);
  f.legend_rows = LegendRows(f.legend, f.size.w - 16.0);
  f.legend_top = TitleBottom(options);
  const double top = f.legend_top + kLegendRowPx * static_cast<double>(f.legend_rows.size()) +
                     (f.legend_rows.empty() ? 6.0 : 10.0);
  const double bottom = kTickLenPx + x_labels_height + (options.x_label.empty() ? 6.0 : 26.0);
  f.box.y = top;
  f.box.h = std::max(40.0, f.size.h - top - bottom);
  return f;
}

void FinishFrame(Frame* f, const PlotOptions& options,
                 const std::vector<std::string>& y_tick_labels, double right) {
  f->box.x = 8.0 + (options.y_label.empty() ? 0.0 : 20.0) +
             MaxTextWidth(y_tick_labels, kTickFontPx) + kTickLenPx + 4.0;
  f->box.w = std::max(40.0, f->size.w - f->box.x - right);
}

int YTickTarget(double plot_h) {
  return std::clamp(static_cast<int>(std::lround(plot_h / 45.0)), 2, 8);
}

// Margins of the snug axes, as fractions of the data span on each side.
constexpr double kXMargin = 0.01, kYMargin = 0.04;

// A numeric axis: the range it shows and its ticks, all inside that range.
struct Axis {
  double lo = 0.0, hi = 1.0;
  std::vector<double> ticks;
  double Step() const { return ticks.size() > 1 ? ticks[1] - ticks[0] : hi - lo; }
};

// Snug axis for data in [lo, hi] (finite): the data range widened by `margin` of its
// span on each side (a degenerate range padded as in NiceTicks), and the nice ticks for
// about `target` intervals that fall inside it; the target is raised until at least two
// ticks are inside. The axis ends less than one tick step beyond the data.
Axis SnugAxis(double lo, double hi, int target, double margin) {
  PadDegenerateRange(&lo, &hi);
  const double pad = margin * (hi - lo);
  Axis axis;
  axis.lo = lo - pad;
  axis.hi = hi + pad;
  const double eps = 1e-9 * (axis.hi - axis.lo);
  for (int t = std::clamp(target, 2, 50); t <= 50; ++t) {
    axis.ticks.clear();
    for (double tick : NiceTicks(axis.lo, axis.hi, t)) {
      if (tick >= axis.lo - eps && tick <= axis.hi + eps) axis.ticks.push_back(tick);
    }
    if (axis.ticks.size() >= 2) break;
  }
  return axis;
}

// Snug x axis with enough room between the tick labels.
Axis FitXAxis(double lo, double hi, double plot_w, double margin) {
  int target = std::clamp(static_cast<int>(plot_w / 90.0), 2, 10);
  while (true) {
    Axis axis = SnugAxis(lo, hi, target, margin);
    if (target <= 2 || axis.ticks.size() < 2) return axis;
    const double spacing = plot_w * axis.Step() / (axis.hi - axis.lo);
    if (spacing >= MaxTextWidth(TickLabels(axis.ticks), kTickFontPx) + 12.0) return axis;
    --target;
  }
}

// A time axis (PlotOptions::x_unix_time): tick steps of round times, from a second to a
// week, aligned in the axis' zone.
constexpr double kTimeSteps[] = {1,     2,     5,      10,     15,      30,     60,    120,
                                 300,   600,   900,    1800,   3600,    7200,   10800, 21600,
                                 43200, 86400, 172800, 604800, 1209600, 2419200};
constexpr double kDaySeconds = 86400.0;

// Ticks at multiples of `step` in local time (Unix time + offset_s) within [lo, hi].
std::vector<double> TimeTicks(double lo, double hi, double step, int offset_s) {
  std::vector<double> ticks;
  const double first = std::ceil((lo + offset_s) / step - 1e-9) * step - offset_s;
  for (double t = first; t <= hi + 1e-9 * step && ticks.size() < 1000; t += step) {
    ticks.push_back(t);
  }
  return ticks;
}

// The labels of time ticks: clock times ("12:30", "12:30:15"), with the date ("05-02
// 00:00", "2024-05-02") when the axis spans more than a day.
std::vector<std::string> TimeTickLabels(const std::vector<double>& ticks, double lo, double hi,
                                        double step, int offset_s) {
  const std::string first = FormatUnixTime(lo, offset_s), last = FormatUnixTime(hi, offset_s);
  const bool one_day =
      first.size() >= 19 && last.size() >= 19 && first.compare(0, 10, last, 0, 10) == 0;
  const bool one_year =
      first.size() >= 19 && last.size() >= 19 && first.compare(0, 4, last, 0, 4) == 0;
  std::vector<std::string> labels;
  for (double t : ticks) {
    const std::string text = FormatUnixTime(t, offset_s);  // "2024-05-01 12:34:56"
    if (text.size() < 19) {  // beyond the years shown as dates: the number
      labels.push_back(text);
    } else if (step >= kDaySeconds) {
      labels.push_back(one_year ? text.substr(5, 5) : text.substr(0, 10));
    } else {
      const std::string clock = text.substr(11, step < 60.0 ? 8 : 5);
      labels.push_back(one_day ? clock : text.substr(5, 5) + " " + clock);
    }
  }
  return labels;
}

struct TimeAxis {
  double lo = 0.0, hi = 1.0, step = 1.0;
  std::vector<double> ticks;
  std::vector<std::string> labels;
};

// A snug time axis (as SnugAxis) with room between its labels.
TimeAxis FitTimeAxis(double lo, double hi, double plot_w, double margin, int offset_s) {
  if (!(hi > lo)) {
    lo -= 30.0;
    hi += 30.0;
  }
  const double pad = margin * (hi - lo);
  TimeAxis axis;
  axis.lo = lo - pad;
  axis.hi = hi + pad;
  const int target = std::clamp(static_cast<int>(plot_w / 90.0), 2, 10);
  for (double step : kTimeSteps) {
    if ((axis.hi - axis.lo) / step > target * 1.5 &&
        step != kTimeSteps[std::size(kTimeSteps) - 1]) {
      continue;
    }
    axis.step = step;
    axis.ticks = TimeTicks(axis.lo, axis.hi, step, offset_s);
    axis.labels = TimeTickLabels(axis.ticks, axis.lo, axis.hi, step, offset_s);
    const double spacing = plot_w * step / (axis.hi - axis.lo);
    if (axis.ticks.size() >= 2 && spacing < MaxTextWidth(axis.labels, kTickFontPx) + 12.0) {
      continue;  // labels would overlap: a longer step
    }
    if (axis.ticks.size() >= 2 || step == kTimeSteps[std::size(kTimeSteps) - 1]) break;
  }
  return axis;
}

void DrawYAxis(std::string* out, const Box& box, const Scale& ys, const std::vector<double>& ticks,
               const PlotOptions& options) {
  const std::vector<std::string> labels = TickLabels(ticks);
  for (size_t i = 0; i < ticks.size(); ++i) {
    const double y = ys(ticks[i]);
    Line(out, box.x, y, box.x + box.w, y, kGridColour);
    Line(out, box.x - kTickLenPx, y, box.x, y, kAxisColour);
    Text(out, box.x - kTickLenPx - 3.0, y + 4.0, labels[i], "end", kTickFontPx);
  }
  if (!options.y_label.empty()) {
    const double x = 16.0, y = box.y + box.h / 2.0;
    Text(out, x, y, options.y_label, "middle", kFontPx, Rotate(-90.0, x, y));
  }
}

void XLabel(std::string* out, const Box& box, const PlotOptions& options, Size size) {
  if (options.x_label.empty()) return;
  Text(out, box.x + box.w / 2.0, size.h - 8.0, options.x_label, "middle", kFontPx);
}

void DrawXAxis(std::string* out, const Box& box, const Scale& xs, const std::vector<double>& ticks,
               const PlotOptions& options, Size size,
               const std::vector<std::string>* tick_labels = nullptr) {
  const std::vector<std::string> labels = tick_labels ? *tick_labels : TickLabels(ticks);
  const double bottom = box.y + box.h;
  for (size_t i = 0; i < ticks.size(); ++i) {
    const double x = xs(ticks[i]);
    Line(out, x, box.y, x, bottom, kGridColour);
    Line(out, x, bottom, x, bottom + kTickLenPx, kAxisColour);
    Text(out, x, bottom + kTickLenPx + 13.0, labels[i], "middle", kTickFontPx);
  }
  XLabel(out, box, options, size);
}

void DrawBorder(std::string* out, const Box& box) {
  *out += "<rect x=\"" + Px(box.x) + "\" y=\"" + Px(box.y) + "\" width=\"" + Px(box.w) +
          "\" height=\"" + Px(box.h) + "\" fill=\"none\" stroke=\"" + kAxisColour + "\"/>\n";
}

constexpr double kXTickLabelsPx = 17.0;

}  // namespace

std::string XmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        if (static_cast<unsigned char>(c) >= 0x20 || c == '\t' || c == '\n' || c == '\r') {
          out += c;
        }
    }
  }
  return out;
}

std::vector<double> NiceTicks(double lo, double hi, int target) {
  return NiceTicksWithMinStep(lo, hi, target, 0.0);
}

std::string PlotSeriesColour(int index) {
  const int n = static_cast<int>(kPalette.size());
  return kPalette[((index % n) + n) % n];
}

std::string SvgLinePlot(const std::vector<PlotSeries>& series, const PlotOptions& options) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double x_lo = kInf, x_hi = -kInf, y_lo = kInf, y_hi = -kInf;
  auto finite = [](double x, double y) { return std::isfinite(x) && std::isfinite(y); };
  for (const PlotSeries& s : series) {
    const size_t n = std::min(s.x.size(), s.y.size());
    for (size_t i = 0; i < n; ++i) {
      if (!finite(s.x[i], s.y[i])) continue;
      x_lo = std::min(x_lo, s.x[i]);
      x_hi = std::max(x_hi, s.x[i]);
      y_lo = std::min(y_lo, s.y[i]);
      y_hi = std::max(y_hi, s.y[i]);
    }
  }
  if (x_lo > x_hi) return NoDataSvg(options, "no data");
  if (std::isfinite(options.x_span_lo) && std::isfinite(options.x_span_hi) &&
      options.x_span_lo < options.x_span_hi) {
    x_lo = std::min(x_lo, options.x_span_lo);
    x_hi = std::max(x_hi, options.x_span_hi);
  }

  std::vector<LegendItem> legend;
  for (size_t i = 0; i < series.size(); ++i) {
    const PlotSeries& s = series[i];
    if (s.name.empty()) continue;
    legend.push_back({s.name, s.colour.empty() ? Colour(i) : s.colour.c_str(),
                      s.markers_only ? Swatch::kMarker
                      : s.dashed     ? Swatch::kDashed
                                     : Swatch::kLine,
                      std::clamp(s.opacity, kMinOpacity, 1.0)});
  }
  Frame f = StartFrame(options, std::move(legend), kXTickLabelsPx);
  const Axis y_axis = SnugAxis(y_lo, y_hi, YTickTarget(f.box.h), kYMargin);
  FinishFrame(&f, options, TickLabels(y_axis.ticks), 30.0);
  Axis x_axis;
  TimeAxis time_axis;
  if (options.x_unix_time) {
    time_axis = FitTimeAxis(x_lo, x_hi, f.box.w, kXMargin, options.x_time_offset_s);
    x_axis.lo = time_axis.lo;
    x_axis.hi = time_axis.hi;
    x_axis.ticks = time_axis.ticks;
  } else {
    x_axis = FitXAxis(x_lo, x_hi, f.box.w, kXMargin);
  }
  const Box& box = f.box;
  const Scale xs{x_axis.lo, x_axis.hi, box.x, box.x + box.w};
  const Scale ys{y_axis.lo, y_axis.hi, box.y + box.h, box.y};

  std::string out;
  OpenSvg(&out, f.size, options.title);
  DrawYAxis(&out, box, ys, y_axis.ticks, options);
  DrawXAxis(&out, box, xs, x_axis.ticks, options, f.size,
            options.x_unix_time ? &time_axis.labels : nullptr);

  // An isolated point of a line (between gaps): a small stroked ring, reads as a dot.
  constexpr const char* kDot = "m-1.2 0a1.2 1.2 0 1 0 2.4 0a1.2 1.2 0 1 0 -2.4 0";
  auto draw = [&](size_t si) {
    const PlotSeries& s = series[si];
    const size_t n = std::min(s.x.size(), s.y.size());
    std::string d;
    size_t run = 0;  // Points in the current subpath.
    for (size_t i = 0; i < n; ++i) {
      if (!finite(s.x[i], s.y[i])) {
        if (run == 1 && !s.markers_only) d += kDot;
        run = 0;
        continue;
      }
      const double px = xs(s.x[i]), py = ys(s.y[i]);
      if (s.markers_only) {
        d += "M" + Px(px) + " " + Px(py) + "h0";
      } else {
        d += (run == 0 ? "M" : "L") + Px(px) + " " + Px(py);
      }
      ++run;
    }
    if (run == 1 && !s.markers_only) d += kDot;
    if (d.empty()) return;
    const std::string colour = s.colour.empty() ? Colour(si) : XmlEscape(s.colour);
    const double opacity = std::clamp(s.opacity, kMinOpacity, 1.0);
    const std::string opacity_attr =
        opacity < 1.0 ? " stroke-opacity=\"" + Compact(opacity, 2) + "\"" : "";
    if (s.markers_only) {
      const double r = std::clamp(s.marker_radius_px, 0.5, 10.0);
      out += "<path d=\"" + d + "\" fill=\"none\" stroke=\"" + colour + "\" stroke-width=\"" +
             Px(2.0 * r) + "\" stroke-linecap=\"round\"" + opacity_attr + "/>\n";
    } else {
      out += "<path d=\"" + d + "\" fill=\"none\" stroke=\"" + colour +
             "\" stroke-width=\"1.8\" stroke-linejoin=\"round\" stroke-linecap=\"round\"" +
             (s.dashed ? " stroke-dasharray=\"6 5\"" : "") + opacity_attr + "/>\n";
    }
  };
  // Markers underneath, lines on top, then what must stay visible.
  for (size_t si = 0; si < series.size(); ++si) {
    if (series[si].markers_only && !series[si].on_top) draw(si);
  }
  for (size_t si = 0; si < series.size(); ++si) {
    if (!series[si].markers_only && !series[si].on_top) draw(si);
  }
  for (size_t si = 0; si < series.size(); ++si) {
    if (series[si].on_top) draw(si);
  }
  DrawBorder(&out, box);
  DrawLegend(&out, f.legend, f.legend_rows, f.size.w, f.legend_top);
  CloseSvg(&out);
  return out;
}

MinMaxBucketThinner::MinMaxBucketThinner(size_t n, bool any_gap, int max_points) : n_(n) {
  max_points = std::max(max_points, 4);
  thinning_ = n > static_cast<size_t>(max_points);
  if (!thinning_) return;
  num_buckets_ = static_cast<size_t>(max_points) / (any_gap ? 3 : 2);
  // Bucket b holds the indices [n b / B, n (b + 1) / B): lengths differ by at most 1.
  end_ = n_ / num_buckets_;
  x_.reserve(static_cast<size_t>(max_points));
  y_.reserve(static_cast<size_t>(max_points));
}

void MinMaxBucketThinner::CloseBucket() {
  constexpr size_t kNone = static_cast<size_t>(-1);
  std::array<Point, 3> keep = {lo_set_ ? lo_ : Point{kNone, 0, 0},
                               hi_set_ && hi_.index != lo_.index ? hi_ : Point{kNone, 0, 0},
                               gap_set_ ? gap_ : Point{kNone, 0, 0}};
  std::sort(keep.begin(), keep.end(),
            [](const Point& a, const Point& b) { return a.index < b.index; });  // kNone last
  for (const Point& p : keep) {
    if (p.index == kNone) break;
    x_.push_back(p.x);
    y_.push_back(p.y);
  }
  lo_set_ = hi_set_ = gap_set_ = false;
  ++bucket_;
  end_ = n_ * (bucket_ + 1) / num_buckets_;
}

void MinMaxBucketThinner::Add(double x, double y) {
  const size_t i = next_++;
  if (!thinning_) {
    x_.push_back(x);
    y_.push_back(y);
    return;
  }
  while (bucket_ < num_buckets_ && i >= end_) CloseBucket();
  if (!std::isfinite(x) || !std::isfinite(y)) {
    if (!gap_set_) gap_ = {i, x, y};
    gap_set_ = true;
    return;
  }
  if (!lo_set_ || y < lo_.y) lo_ = {i, x, y};
  if (!hi_set_ || y > hi_.y) hi_ = {i, x, y};
  lo_set_ = hi_set_ = true;
}

PlotSeries MinMaxBucketThinner::Finish(PlotSeries style) const {
  MinMaxBucketThinner copy = *this;
  while (copy.thinning_ && copy.bucket_ < copy.num_buckets_) copy.CloseBucket();
  style.x = std::move(copy.x_);
  style.y = std::move(copy.y_);
  return style;
}

PlotSeries ThinMinMaxPerBucket(const PlotSeries& series, int max_points, int* buckets) {
  const size_t n = std::min(series.x.size(), series.y.size());
  bool any_gap = false;
  for (size_t i = 0; i < n && !any_gap; ++i) {
    any_gap = !std::isfinite(series.x[i]) || !std::isfinite(series.y[i]);
  }
  MinMaxBucketThinner thinner(n, any_gap, max_points);
  for (size_t i = 0; i < n; ++i) thinner.Add(series.x[i], series.y[i]);
  if (buckets != nullptr) *buckets = thinner.buckets();
  if (thinner.buckets() == 0) return series;
  PlotSeries style = series;
  style.x.clear();
  style.y.clear();
  return thinner.Finish(std::move(style));
}

std::string SvgHistogram(const std::vector<HistogramSeries>& series, int bins,
                         const PlotOptions& options) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double lo = kInf, hi = -kInf;
  std::vector<std::string> names;
  for (const HistogramSeries& s : series) {
    names.push_back(s.name);
    for (double v : s.values) {
      if (!std::isfinite(v)) continue;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  HistogramBins h(std::move(names), lo, hi, bins);
  for (size_t si = 0; si < series.size(); ++si) {
    for (double v : series[si].values) h.Add(si, v);
  }
  return h.Svg(options);
}

HistogramBins::HistogramBins(std::vector<std::string> names, double lo, double hi, int bins)
    : names_(std::move(names)), lo_(lo), hi_(hi), bins_(std::clamp(bins, 1, 1000)) {
  if (lo_ <= hi_ && hi_ - lo_ <= 1e-12 * std::max(std::fabs(lo_), std::fabs(hi_))) {
    const double pad = lo_ == 0.0 ? 0.5 : 0.005 * std::fabs(lo_);
    lo_ -= pad;
    hi_ += pad;
  }
  bin_width_ = (hi_ - lo_) / bins_;
  counts_.assign(names_.size(), std::vector<long>(bins_, 0));
  n_.assign(names_.size(), 0);
}

void HistogramBins::Add(size_t series, double value) {
  if (!std::isfinite(value) || series >= counts_.size() || !(lo_ <= hi_)) return;
  const int b = std::clamp(static_cast<int>(std::floor((value - lo_) / bin_width_)), 0, bins_ - 1);
  ++counts_[series][b];
  ++n_[series];
}

std::string HistogramBins::Svg(const PlotOptions& options) const {
  if (!(lo_ <= hi_)) return NoDataSvg(options, "no data");
  const double lo = lo_, hi = hi_, bin_width = bin_width_;
  const int bins = bins_;
  long max_count = 0;
  for (const std::vector<long>& c : counts_) {
    for (long v : c) max_count = std::max(max_count, v);
  }
  std::vector<LegendItem> legend;
  for (size_t si = 0; si < names_.size(); ++si) {
    if (!names_[si].empty()) {
      legend.push_back(
          {names_[si] + " (n=" + std::to_string(n_[si]) + ")", Colour(si), Swatch::kBox});
    }
  }
  PlotOptions opts = options;
  if (opts.y_label.empty()) opts.y_label = "count";
  Frame f = StartFrame(opts, std::move(legend), kXTickLabelsPx);
  const std::vector<double> y_ticks =
      NiceTicksWithMinStep(0.0, static_cast<double>(max_count), YTickTarget(f.box.h), 1.0);
  FinishFrame(&f, opts, TickLabels(y_ticks), 30.0);
  const Axis x_axis = FitXAxis(lo, hi, f.box.w, kXMargin);
  const Box& box = f.box;
  const Scale xs{x_axis.lo, x_axis.hi, box.x, box.x + box.w};
  const Scale ys{y_ticks.front(), y_ticks.back(), box.y + box.h, box.y};

  std::string out;
  OpenSvg(&out, f.size, opts.title);
  DrawYAxis(&out, box, ys, y_ticks, opts);
  DrawXAxis(&out, box, xs, x_axis.ticks, opts, f.size);
  for (size_t si = 0; si < counts_.size(); ++si) {
    const char* colour = Colour(si);
    for (int b = 0; b < bins; ++b) {
      const long c = counts_[si][b];
      if (c == 0) continue;
      const double x0 = xs(lo + b * bin_width), x1 = xs(lo + (b + 1) * bin_width);
      const double y = ys(static_cast<double>(c));
      out += "<rect class=\"bar\" data-count=\"" + std::to_string(c) + "\" x=\"" + Px(x0) +
             "\" y=\"" + Px(y) + "\" width=\"" + Px(x1 - x0) + "\" height=\"" +
             Px(box.y + box.h - y) + "\" fill=\"" + colour + "\" fill-opacity=\"0.4\" stroke=\"" +
             colour + "\" stroke-width=\"0.8\"/>\n";
    }
  }
  DrawBorder(&out, box);
  DrawLegend(&out, f.legend, f.legend_rows, f.size.w, f.legend_top);
  CloseSvg(&out);
  return out;
}

std::string SvgGroupedBars(const std::vector<BarGroup>& groups,
                           const std::vector<std::string>& series_names,
                           const PlotOptions& options) {
  size_t num_series = series_names.size();
  if (num_series == 0) {
    for (const BarGroup& g : groups) num_series = std::max(num_series, g.values.size());
  }
  double v_min = 0.0, v_max = 0.0;
  bool any = false, any_negative = false, any_positive = false;
  std::vector<std::string> value_labels;
  for (const BarGroup& g : groups) {
    for (size_t s = 0; s < std::min(num_series, g.values.size()); ++s) {
      const double v = g.values[s];
      if (!std::isfinite(v)) continue;
      any = true;
      v_min = std::min(v_min, v);
      v_max = std::max(v_max, v);
      any_negative |= v < 0.0;
      any_positive |= v >= 0.0;
      value_labels.push_back(Compact(v, 3));
    }
  }
  if (!any) return NoDataSvg(options, "no data");

  std::vector<LegendItem> legend;
  for (size_t s = 0; s < series_names.size(); ++s) {
    if (!series_names[s].empty()) legend.push_back({series_names[s], Colour(s), Swatch::kSolidBox});
  }
  // Group labels: horizontal if they fit their slot, else rotated by 40 degrees. The
  // slot width is estimated from the full width; the y labels take little of it.
  const Size size = ClampedSize(options);
  std::vector<std::string> group_labels;
  for (const BarGroup& g : groups) group_labels.push_back(g.label);
  const double max_group_label_w = MaxTextWidth(group_labels, kTickFontPx);
  const double est_slot_w = (size.w - 90.0) / static_cast<double>(groups.size());
  const bool rotate_groups = max_group_label_w > est_slot_w - 6.0;
  constexpr double kRotateDeg = 40.0;
  const double group_labels_h = rotate_groups
                                    ? max_group_label_w * std::sin(kRotateDeg * M_PI / 180.0) + 16.0
                                    : kXTickLabelsPx;

  Frame f = StartFrame(options, std::move(legend), group_labels_h);
  constexpr double kValueFontPx = 10.0;
  const double bar_pitch_est = est_slot_w * 0.8 / static_cast<double>(num_series);
  const double max_value_label_w = MaxTextWidth(value_labels, kValueFontPx);
  const bool rotate_values = max_value_label_w > bar_pitch_est - 1.0;
  // Head room so value labels stay inside the plot.
  const double label_px = rotate_values ? max_value_label_w + 6.0 : kValueFontPx + 6.0;
  const double top_px = any_positive ? label_px : 0.0;
  const double bottom_px = any_negative ? label_px : 0.0;
  double span = v_max - v_min;
  if (span == 0.0) span = 1.0;
  const double data_px = std::max(20.0, f.box.h - top_px - bottom_px);
  const double per_px = span / data_px;
  const std::vector<double> y_ticks =
      NiceTicks(v_min - bottom_px * per_px, v_max + top_px * per_px, YTickTarget(f.box.h));
  FinishFrame(&f, options, TickLabels(y_ticks), 12.0);
  const Box& box = f.box;
  const Scale ys{y_ticks.front(), y_ticks.back(), box.y + box.h, box.y};

  std::string out;
  OpenSvg(&out, f.size, options.title);
  DrawYAxis(&out, box, ys, y_ticks, options);
  const double slot_w = box.w / static_cast<double>(groups.size());
  const double bar_w = slot_w * 0.8 / static_cast<double>(num_series);
  const double bottom = box.y + box.h;
  for (size_t g = 0; g < groups.size(); ++g) {
    const double cx = box.x + slot_w * (static_cast<double>(g) + 0.5);
    if (g > 0) {
      const double x = box.x + slot_w * static_cast<double>(g);
      Line(&out, x, bottom, x, bottom + kTickLenPx, kAxisColour);
    }
    if (rotate_groups) {
      const double y = bottom + kTickLenPx + 11.0;
      Text(&out, cx + 4.0, y, groups[g].label, "end", kTickFontPx,
           Rotate(-kRotateDeg, cx + 4.0, y));
    } else {
      Text(&out, cx, bottom + kTickLenPx + 13.0, groups[g].label, "middle", kTickFontPx);
    }
    const double x_first = box.x + slot_w * (static_cast<double>(g) + 0.1);
    for (size_t s = 0; s < std::min(num_series, groups[g].values.size()); ++s) {
      const double v = groups[g].values[s];
      if (!std::isfinite(v)) continue;
      const double x = x_first + bar_w * static_cast<double>(s);
      const double y0 = ys(0.0), y1 = ys(v);
      const char* colour = Colour(s);
      out += "<rect class=\"bar\" x=\"" + Px(x) + "\" y=\"" + Px(std::min(y0, y1)) + "\" width=\"" +
             Px(bar_w * 0.92) + "\" height=\"" + Px(std::fabs(y1 - y0)) + "\" fill=\"" + colour +
             "\"/>\n";
      const double lx = x + bar_w * 0.46;
      const std::string label = Compact(v, 3);
      if (rotate_values) {
        const double ly = v < 0.0 ? y1 + 3.0 : y1 - 3.0;
        Text(&out, lx, ly, label, v < 0.0 ? "end" : "start", kValueFontPx,
             Rotate(-90.0, lx, ly) + " dy=\"0.35em\"");
      } else {
        Text(&out, lx, v < 0.0 ? y1 + kValueFontPx + 2.0 : y1 - 3.0, label, "middle", kValueFontPx);
      }
    }
  }
  if (y_ticks.front() < 0.0) Line(&out, box.x, ys(0.0), box.x + box.w, ys(0.0), kAxisColour);
  XLabel(&out, box, options, f.size);
  DrawBorder(&out, box);
  DrawLegend(&out, f.legend, f.legend_rows, f.size.w, f.legend_top);
  CloseSvg(&out);
  return out;
}

namespace {

// Diverging scale: -1 blue, 0 near-white, +1 red (ColorBrewer RdBu end points).
std::string DivergingColour(double v) {
  const double t = std::clamp(v, -1.0, 1.0);
  constexpr double kMid[3] = {247, 247, 247}, kNeg[3] = {33, 102, 172}, kPos[3] = {178, 24, 43};
  const double* end = t < 0.0 ? kNeg : kPos;
  const double a = std::fabs(t);
  char buf[8];
  int rgb[3];
  for (int i = 0; i < 3; ++i) {
    rgb[i] = static_cast<int>(std::lround(kMid[i] + (end[i] - kMid[i]) * a));
  }
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", rgb[0], rgb[1], rgb[2]);
  return buf;
}

}  // namespace

std::string SvgMatrixHeatmap(const std::vector<std::string>& labels,
                             const std::vector<std::vector<double>>& matrix,
                             const PlotOptions& options) {
  const size_t n = labels.size();
  if (n == 0 || matrix.empty()) return NoDataSvg(options, "no data");
  bool square = matrix.size() == n;
  for (const std::vector<double>& row : matrix) square = square && row.size() == n;
  if (!square) return NoDataSvg(options, "no data (matrix is not labels x labels)");

  const Size size = ClampedSize(options);
  const double label_w = MaxTextWidth(labels, kTickFontPx);
  const double top = TitleBottom(options) + 6.0;
  double left = 8.0 + (options.y_label.empty() ? 0.0 : 20.0) + label_w + 6.0;
  constexpr double kColourBarPx = 64.0;  // Gap, bar and its labels on the right.
  const double x_label_px = options.x_label.empty() ? 6.0 : 26.0;
  auto cell_for = [&](double labels_h) {
    const double avail_w = size.w - left - kColourBarPx;
    const double avail_h = size.h - top - labels_h - x_label_px;
    return std::max(4.0, std::min(avail_w, avail_h) / static_cast<double>(n));
  };
  double labels_h = 18.0;
  double cell = cell_for(labels_h);
  constexpr double kRotateDeg = 45.0;
  const bool rotate = label_w > cell - 4.0;
  if (rotate) {
    labels_h = label_w * std::sin(kRotateDeg * M_PI / 180.0) + 16.0;
    cell = cell_for(labels_h);
  }
  const double grid = cell * static_cast<double>(n);
  // Centre labels, grid and colour bar horizontally.
  const double shift = std::max(0.0, (size.w - left - grid - kColourBarPx) / 2.0);
  left += shift;
  const double value_font = std::clamp(cell * 0.28, 5.0, 12.0);

  std::string out;
  OpenSvg(&out, size, options.title);
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 0; j < n; ++j) {
      const double v = matrix[i][j];
      const double x = left + cell * static_cast<double>(j);
      const double y = top + cell * static_cast<double>(i);
      const bool ok = std::isfinite(v);
      const std::string text = ok ? Fixed(v, 2) : "n/a";
      out += "<rect class=\"cell\" data-value=\"" + text + "\" x=\"" + Px(x) + "\" y=\"" + Px(y) +
             "\" width=\"" + Px(cell) + "\" height=\"" + Px(cell) + "\" fill=\"" +
             (ok ? DivergingColour(v) : std::string("#d0d0d0")) + "\"/>\n";
      const bool dark = ok && std::fabs(v) > 0.55;
      Text(&out, x + cell / 2.0, y + cell / 2.0 + value_font * 0.35, text, "middle", value_font,
           dark ? "fill=\"#ffffff\"" : "");
    }
  }
  out += "<rect x=\"" + Px(left) + "\" y=\"" + Px(top) + "\" width=\"" + Px(grid) + "\" height=\"" +
         Px(grid) + "\" fill=\"none\" stroke=\"" + kAxisColour + "\"/>\n";
  for (size_t i = 0; i < n; ++i) {
    const double c = cell * (static_cast<double>(i) + 0.5);
    Text(&out, left - 5.0, top + c + 4.0, labels[i], "end", kTickFontPx);
    const double x = left + c, y = top + grid + 14.0;
    if (rotate) {
      Text(&out, x + 4.0, y - 4.0, labels[i], "end", kTickFontPx,
           Rotate(-kRotateDeg, x + 4.0, y - 4.0));
    } else {
      Text(&out, x, y, labels[i], "middle", kTickFontPx);
    }
  }
  if (!options.y_label.empty()) {
    const double x = shift + 16.0, y = top + grid / 2.0;
    Text(&out, x, y, options.y_label, "middle", kFontPx, Rotate(-90.0, x, y));
  }
  if (!options.x_label.empty()) {
    Text(&out, left + grid / 2.0, top + grid + labels_h + 18.0, options.x_label, "middle", kFontPx);
  }
  // Colour bar: stacked bands from +1 (top) to -1, no gradient so no element ids.
  constexpr int kBands = 40;
  const double bar_x = left + grid + 14.0, bar_w = 12.0;
  const double bar_h = std::max(60.0, std::min(grid, 220.0));
  const double band_h = bar_h / kBands;
  for (int b = 0; b < kBands; ++b) {
    const double v = 1.0 - (b + 0.5) * 2.0 / kBands;
    out += "<rect x=\"" + Px(bar_x) + "\" y=\"" + Px(top + b * band_h) + "\" width=\"" + Px(bar_w) +
           "\" height=\"" + Px(band_h + 0.5) + "\" fill=\"" + DivergingColour(v) + "\"/>\n";
  }
  out += "<rect x=\"" + Px(bar_x) + "\" y=\"" + Px(top) + "\" width=\"" + Px(bar_w) +
         "\" height=\"" + Px(bar_h) + "\" fill=\"none\" stroke=\"" + kAxisColour + "\"/>\n";
  for (int k = 0; k <= 4; ++k) {
    const double v = 1.0 - 0.5 * k;
    const double y = top + bar_h * k / 4.0;
    Line(&out, bar_x + bar_w, y, bar_x + bar_w + 3.0, y, kAxisColour);
    Text(&out, bar_x + bar_w + 5.0, y + 4.0, Fixed(v, 1), "", kTickFontPx);
  }
  CloseSvg(&out);
  return out;
}

namespace {

// A perceptually uniform sequential scale (viridis' end and seven inner colours), t in
// [0, 1]: dark purple for the smallest values, yellow for the largest.
std::string SequentialColour(double t) {
  constexpr int kStops = 9;
  constexpr double kRgb[kStops][3] = {{68, 1, 84},    {71, 45, 123},  {59, 82, 139},
                                      {44, 114, 142}, {33, 145, 140}, {40, 174, 128},
                                      {94, 201, 98},  {173, 220, 48}, {253, 231, 37}};
  const double x = std::clamp(t, 0.0, 1.0) * (kStops - 1);
  const int k = std::min(static_cast<int>(x), kStops - 2);
  const double f = x - k;
  char buf[8];
  int rgb[3];
  for (int i = 0; i < 3; ++i) {
    rgb[i] = static_cast<int>(std::lround(kRgb[k][i] + (kRgb[k + 1][i] - kRgb[k][i]) * f));
  }
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", rgb[0], rgb[1], rgb[2]);
  return buf;
}

constexpr const char* kNoValueColour = "#d4d4d4";

// Where a polar map's disc and its colour bar go.
struct PolarLayout {
  Size size{0, 0};
  double cx = 0, cy = 0, radius_px = 0;    // the disc
  double bar_x = 0, bar_y = 0, bar_w = 0;  // the colour bar, under the disc
  std::vector<LegendItem> legend;
  std::vector<std::vector<size_t>> legend_rows;
  double legend_top = 0;
};

constexpr double kRimLabelsPx = 30.0;  // azimuth and rim labels, outside the disc
constexpr double kBarHeightPx = 12.0;
constexpr double kBarBlockPx = 66.0;    // bar, its tick labels, its label, the rings' label
constexpr double kValueMarksPx = 14.0;  // the value marks' labels above the bar

PolarLayout LayOutPolarMap(const PolarMapOptions& options) {
  PolarLayout l;
  l.size = ClampedSize(options.plot);
  for (const PolarMark& m : options.marks) {
    if (!m.label.empty()) {
      l.legend.push_back({m.label, kMarkColour, Swatch::kMark, 1.0, m.shape, m.filled});
    }
  }
  l.legend_rows = LegendRows(l.legend, l.size.w - 16.0);
  const double legend_h = kLegendRowPx * static_cast<double>(l.legend_rows.size());
  const double top = TitleBottom(options.plot) + kRimLabelsPx;
  // Room above the bar for the labels of its value marks.
  const double marks_h = options.value_marks.empty() ? 0.0 : kValueMarksPx;
  const double bottom = kRimLabelsPx + marks_h + kBarBlockPx + legend_h + 8.0;
  l.radius_px = std::max(
      20.0, std::min(0.5 * l.size.w - kRimLabelsPx - 8.0, 0.5 * (l.size.h - top - bottom)));
  l.cx = 0.5 * l.size.w;
  l.cy = top + l.radius_px;
  l.bar_w = std::min(360.0, l.size.w - 80.0);
  l.bar_x = l.cx - 0.5 * l.bar_w;
  l.bar_y = l.cy + l.radius_px + kRimLabelsPx + marks_h;
  l.legend_top = l.bar_y + kBarBlockPx;
  return l;
}

// The point at radius r_px and angle a_deg (counter-clockwise from +x, +y up the page).
std::string PolarPoint(const PolarLayout& l, double r_px, double a_deg) {
  const double a = a_deg * M_PI / 180.0;
  return Px(l.cx + r_px * std::cos(a)) + " " + Px(l.cy - r_px * std::sin(a));
}

// Path data of an annular sector; a full turn gives a disc or a ring (two half arcs each).
std::string SectorPath(const PolarLayout& l, double r0, double r1, double a0, double a1) {
  const std::string R0 = Px(r0), R1 = Px(r1);
  if (a1 - a0 >= 360.0 - 1e-9) {
    std::string d = "M" + PolarPoint(l, r1, 0) + "A" + R1 + " " + R1 + " 0 1 0 " +
                    PolarPoint(l, r1, 180) + "A" + R1 + " " + R1 + " 0 1 0 " +
                    PolarPoint(l, r1, 0) + "Z";
    if (r0 > 0.0) {
      d += "M" + PolarPoint(l, r0, 0) + "A" + R0 + " " + R0 + " 0 1 1 " + PolarPoint(l, r0, 180) +
           "A" + R0 + " " + R0 + " 0 1 1 " + PolarPoint(l, r0, 0) + "Z";
    }
    return d;
  }
  const char* large = a1 - a0 > 180.0 ? "1" : "0";
  // Counter-clockwise on the page is SVG's negative sweep (its y axis points down).
  std::string d = "M" + PolarPoint(l, r1, a0) + "A" + R1 + " " + R1 + " 0 " + large + " 0 " +
                  PolarPoint(l, r1, a1);
  if (r0 > 0.0) {
    d += "L" + PolarPoint(l, r0, a1) + "A" + R0 + " " + R0 + " 0 " + large + " 1 " +
         PolarPoint(l, r0, a0);
  } else {
    d += "L" + Px(l.cx) + " " + Px(l.cy);
  }
  return d + "Z";
}

// Rings every nice step of the radius (labelled along the 80 deg spoke, between the
// usual tower directions), spokes every 30 deg with their azimuth where no rim label is
// within 10 deg, the rim labels.
void DrawPolarGrid(std::string* out, const PolarLayout& l, double radius_max,
                   const PolarMapOptions& options) {
  const std::vector<double> ticks = NiceTicks(0.0, radius_max, 4);
  const std::vector<std::string> labels = TickLabels(ticks);
  for (size_t k = 0; k < ticks.size(); ++k) {
    if (ticks[k] <= 0.0 || ticks[k] > radius_max * (1.0 + 1e-9)) continue;
    const double r = l.radius_px * ticks[k] / radius_max;
    *out += "<circle cx=\"" + Px(l.cx) + "\" cy=\"" + Px(l.cy) + "\" r=\"" + Px(r) +
            "\" fill=\"none\" stroke=\"#ffffff\" stroke-opacity=\"0.7\" stroke-width=\"0.8\"/>\n";
    const double a = 80.0 * M_PI / 180.0;
    Text(out, l.cx + r * std::cos(a) + 3.0, l.cy - r * std::sin(a) - 3.0, labels[k], "",
         kTickFontPx,
         "fill=\"#333333\" stroke=\"#ffffff\" stroke-width=\"2.5\" paint-order=\"stroke\"");
  }
  for (int deg = 0; deg < 360; deg += 30) {
    const double a = deg * M_PI / 180.0, c = std::cos(a), s = std::sin(a);
    Line(out, l.cx, l.cy, l.cx + l.radius_px * c, l.cy - l.radius_px * s, "#ffffff", 0.6,
         "stroke-opacity=\"0.5\"");
    // A rim label (a tower) says the direction there; its degrees would collide with it.
    const bool labelled =
        std::any_of(options.rim_labels.begin(), options.rim_labels.end(), [deg](const auto& label) {
          return std::abs(std::remainder(label.first - deg, 360.0)) < 10.0;
        });
    if (labelled) continue;
    const double r = l.radius_px + 11.0;
    const char* anchor = c > 0.3 ? "start" : c < -0.3 ? "end" : "middle";
    Text(out, l.cx + r * c, l.cy - r * s + 4.0 - 4.0 * s, std::to_string(deg) + "\u00b0", anchor,
         10.0, "fill=\"#777777\"");
  }
  *out += "<circle cx=\"" + Px(l.cx) + "\" cy=\"" + Px(l.cy) + "\" r=\"" + Px(l.radius_px) +
          "\" fill=\"none\" stroke=\"" + kAxisColour + "\"/>\n";
  for (const auto& [deg, text] : options.rim_labels) {
    const double a = deg * M_PI / 180.0, c = std::cos(a), s = std::sin(a);
    const double r = l.radius_px + 12.0;
    const char* anchor = c > 0.3 ? "start" : c < -0.3 ? "end" : "middle";
    Text(out, l.cx + r * c, l.cy - r * s + 4.0 - 4.0 * s, text, anchor, kFontPx,
         "font-weight=\"bold\"");
  }
}

// The colour bar for values in [lo, hi] and its label, then the radial axis' label.
void DrawColourBar(std::string* out, const PolarLayout& l, double lo, double hi,
                   const PolarMapOptions& options) {
  constexpr int kBands = 60;
  const double band = l.bar_w / kBands;
  for (int b = 0; b < kBands; ++b) {
    *out += "<rect x=\"" + Px(l.bar_x + b * band) + "\" y=\"" + Px(l.bar_y) + "\" width=\"" +
            Px(band + 0.5) + "\" height=\"" + Px(kBarHeightPx) + "\" fill=\"" +
            SequentialColour((b + 0.5) / kBands) + "\"/>\n";
  }
  *out += "<rect x=\"" + Px(l.bar_x) + "\" y=\"" + Px(l.bar_y) + "\" width=\"" + Px(l.bar_w) +
          "\" height=\"" + Px(kBarHeightPx) + "\" fill=\"none\" stroke=\"" + kAxisColour + "\"/>\n";
  std::vector<double> ticks;
  for (double t : NiceTicks(lo, hi, 5)) {
    if (t >= lo - 1e-9 * (hi - lo) && t <= hi + 1e-9 * (hi - lo)) ticks.push_back(t);
  }
  if (ticks.size() < 2) ticks = {lo, hi};
  const std::vector<std::string> labels = TickLabels(ticks);
  for (size_t k = 0; k < ticks.size(); ++k) {
    const double x = hi > lo ? l.bar_x + l.bar_w * (ticks[k] - lo) / (hi - lo) : l.cx;
    Line(out, x, l.bar_y + kBarHeightPx, x, l.bar_y + kBarHeightPx + kTickLenPx, kAxisColour);
    Text(out, x, l.bar_y + kBarHeightPx + 15.0, labels[k], "middle", kTickFontPx);
  }
  for (const auto& [value, label] : options.value_marks) {
    if (!std::isfinite(value) || !(hi > lo)) continue;
    const double x = l.bar_x + l.bar_w * std::clamp((value - lo) / (hi - lo), 0.0, 1.0);
    Line(out, x, l.bar_y - 4.0, x, l.bar_y + kBarHeightPx, "#000000", 2.0);
    Text(out, x, l.bar_y - 7.0, label, "middle", kTickFontPx, "font-weight=\"bold\"");
  }
  Text(out, l.cx, l.bar_y + kBarHeightPx + 31.0, options.value_label, "middle", kFontPx);
  if (!options.radius_label.empty()) {
    Text(out, l.cx, l.bar_y + kBarHeightPx + 46.0, "rings: " + options.radius_label, "middle",
         kTickFontPx, "fill=\"#555555\"");
  }
}

}  // namespace

std::string SvgPolarMap(const std::vector<PolarCell>& cells, const PolarMapOptions& options) {
  double radius_max = options.radius_max, lo = HUGE_VAL, hi = -HUGE_VAL;
  bool any = false;
  for (const PolarCell& c : cells) {
    if (!(c.radius_hi > c.radius_lo) || !(c.angle_hi_deg > c.angle_lo_deg)) continue;
    any = true;
    if (options.radius_max <= 0.0) radius_max = std::max(radius_max, c.radius_hi);
    if (std::isfinite(c.value)) {
      lo = std::min(lo, c.value);
      hi = std::max(hi, c.value);
    }
  }
  if (!any || !(radius_max > 0.0) || !std::isfinite(radius_max)) {
    return NoDataSvg(options.plot, "no data");
  }
  if (options.value_lo < options.value_hi) {
    lo = options.value_lo;
    hi = options.value_hi;
  }
  if (lo > hi) lo = hi = 0.0;  // no values: every cell grey, the bar still drawn
  const PolarLayout l = LayOutPolarMap(options);
  std::string out;
  OpenSvg(&out, l.size, options.plot.title);
  const double scale = l.radius_px / radius_max;
  for (const PolarCell& c : cells) {
    if (!(c.radius_hi > c.radius_lo) || !(c.angle_hi_deg > c.angle_lo_deg)) continue;
    const bool has_value = std::isfinite(c.value);
    const double t = hi > lo ? (c.value - lo) / (hi - lo) : 0.5;
    out += "<path class=\"cell\" data-value=\"" + (has_value ? Compact(c.value, 6) : "n/a") +
           "\" d=\"" +
           SectorPath(l, std::min(c.radius_lo, radius_max) * scale,
                      std::min(c.radius_hi, radius_max) * scale, c.angle_lo_deg, c.angle_hi_deg) +
           "\" fill=\"" + (has_value ? SequentialColour(t) : std::string(kNoValueColour)) +
           "\" fill-rule=\"evenodd\" stroke=\"" +
           (has_value ? SequentialColour(t) : kNoValueColour) + "\" stroke-width=\"0.3\">";
    if (!c.tooltip.empty()) out += "<title>" + XmlEscape(c.tooltip) + "</title>";
    out += "</path>\n";
  }
  DrawPolarGrid(&out, l, radius_max, options);
  for (const PolarCell& c : cells) {
    if (c.mark < 0 || c.mark >= static_cast<int>(options.marks.size())) continue;
    if (!(c.radius_hi > c.radius_lo) || !(c.angle_hi_deg > c.angle_lo_deg)) continue;
    const bool disc = c.angle_hi_deg - c.angle_lo_deg >= 360.0 - 1e-9 && c.radius_lo <= 0.0;
    const double r_mid = disc ? 0.0 : 0.5 * (c.radius_lo + c.radius_hi) * scale;
    const double a_mid = 0.5 * (c.angle_lo_deg + c.angle_hi_deg);
    const double arc_px = r_mid * (c.angle_hi_deg - c.angle_lo_deg) * M_PI / 180.0;
    const double size_px = std::clamp(
        0.45 * std::min((c.radius_hi - c.radius_lo) * scale, disc ? 1e9 : arc_px), 3.0, 7.0);
    const double a = a_mid * M_PI / 180.0;
    DrawMark(&out, options.marks[c.mark].shape, l.cx + r_mid * std::cos(a),
             l.cy - r_mid * std::sin(a), size_px, options.marks[c.mark].filled,
             "class=\"mark\" data-mark=\"" + std::to_string(c.mark) + "\"");
  }
  DrawColourBar(&out, l, lo, hi, options);
  DrawLegend(&out, l.legend, l.legend_rows, l.size.w, l.legend_top);
  CloseSvg(&out);
  return out;
}

std::string SvgIntervalPlot(const std::vector<IntervalRow>& rows,
                            const IntervalPlotOptions& options) {
  constexpr double kRowPx = 26.0, kAxisPx = 46.0, kGapPx = 10.0, kDotRadiusPx = 4.0;
  constexpr double kThickPx = 5.0, kThinPx = 1.5;
  const double reach = std::max(1.0, options.wide_sigmas);
  auto sigma_of = [](const IntervalRow& r) {
    return std::isfinite(r.sigma) && r.sigma > 0.0 ? r.sigma : 0.0;
  };
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  std::vector<std::string> labels, notes;
  for (const IntervalRow& r : rows) {
    labels.push_back(r.label);
    notes.push_back(r.note);
    if (!std::isfinite(r.value)) continue;
    lo = std::min(lo, r.value - reach * sigma_of(r));
    hi = std::max(hi, r.value + reach * sigma_of(r));
  }
  PlotOptions sized = options.plot;
  sized.height_px = static_cast<int>(TitleBottom(sized) + kGapPx + kRowPx * rows.size() + kAxisPx);
  if (lo > hi) return NoDataSvg(sized, "no data");
  if (std::isfinite(options.reference)) {
    lo = std::min(lo, options.reference);
    hi = std::max(hi, options.reference);
  }
  PadDegenerateRange(&lo, &hi);
  const double margin = kYMargin * (hi - lo);
  lo -= margin;
  hi += margin;
  const Size size = ClampedSize(sized);
  Box box;
  box.x = std::min(MaxTextWidth(labels, kFontPx) + 2.0 * kGapPx, 0.45 * size.w);
  box.w = std::max(60.0, size.w - box.x - MaxTextWidth(notes, kFontPx) - 2.0 * kGapPx);
  box.y = TitleBottom(sized) + kGapPx;
  box.h = kRowPx * rows.size();
  const Scale xs{lo, hi, box.x, box.x + box.w};
  std::vector<double> ticks;
  for (double t : NiceTicks(lo, hi, std::max(2, static_cast<int>(box.w / 90.0)))) {
    if (t >= lo && t <= hi) ticks.push_back(t);
  }
  std::string out;
  OpenSvg(&out, size, sized.title);
  const std::vector<std::string> tick_labels = TickLabels(ticks);
  for (size_t k = 0; k < ticks.size(); ++k) {
    Line(&out, xs(ticks[k]), box.y, xs(ticks[k]), box.y + box.h, kGridColour);
    Text(&out, xs(ticks[k]), box.y + box.h + 16.0, tick_labels[k], "middle", kTickFontPx);
  }
  Text(&out, box.x + box.w / 2.0, box.y + box.h + 36.0, sized.x_label, "middle", kFontPx);
  if (std::isfinite(options.reference)) {
    Line(&out, xs(options.reference), box.y, xs(options.reference), box.y + box.h, kAxisColour, 1.2,
         "stroke-dasharray=\"5 4\"");
  }
  for (size_t k = 0; k < rows.size(); ++k) {
    const IntervalRow& r = rows[k];
    const double y = box.y + kRowPx * (k + 0.5);
    Text(&out, box.x - kGapPx, y + 4.0, r.label, "end", kFontPx);
    Text(&out, box.x + box.w + kGapPx, y + 4.0, r.note, "", kFontPx);
    if (!std::isfinite(r.value)) continue;
    const char* colour = Colour(r.emphasised ? 1 : 0);
    const double s = sigma_of(r);
    if (options.wide_sigmas > 0.0 && s > 0.0) {
      Line(&out, xs(r.value - options.wide_sigmas * s), y, xs(r.value + options.wide_sigmas * s), y,
           colour, kThinPx, "class=\"wide\"");
    }
    if (s > 0.0) {
      Line(&out, xs(r.value - s), y, xs(r.value + s), y, colour, kThickPx,
           "class=\"sigma\" stroke-opacity=\"0.55\"");
    }
    out += "<circle class=\"value\" cx=\"" + Px(xs(r.value)) + "\" cy=\"" + Px(y) + "\" r=\"" +
           Px(kDotRadiusPx) + "\" fill=\"" + colour + "\"/>\n";
  }
  DrawBorder(&out, box);
  CloseSvg(&out);
  return out;
}

std::vector<LabelSpot> PlaceCircleLabels(const std::vector<CircleLabel>& labels, double char_px,
                                         double height_px) {
  struct Box {
    double x0, y0, x1, y1;  // y1 the baseline
  };
  std::vector<Box> placed;
  std::vector<LabelSpot> spots_chosen;
  for (const CircleLabel& n : labels) {
    const double w = char_px * static_cast<double>(n.text.size());
    const double r = n.radius_px + 2.0;
    const std::pair<double, double> spots[] = {
        // (left edge, baseline)
        {n.x_px + r, n.y_px - 3.0},         {n.x_px + r, n.y_px + height_px},
        {n.x_px - r - w, n.y_px - 3.0},     {n.x_px - r - w, n.y_px + height_px},
        {n.x_px - w / 2, n.y_px - r - 1.0}, {n.x_px - w / 2, n.y_px + r + height_px}};
    Box chosen{spots[0].first, spots[0].second - height_px, spots[0].first + w, spots[0].second};
    for (const auto& [x, y] : spots) {
      const Box b{x, y - height_px, x + w, y};
      const bool free = std::none_of(placed.begin(), placed.end(), [&](const Box& o) {
        return b.x0 < o.x1 && o.x0 < b.x1 && b.y0 < o.y1 && o.y0 < b.y1;
      });
      if (free) {
        chosen = b;
        break;
      }
    }
    placed.push_back(chosen);
    spots_chosen.push_back({chosen.x0, chosen.y1});
  }
  return spots_chosen;
}

}  // namespace fastcal
