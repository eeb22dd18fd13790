// Dependency-free SVG chart writer for the self-contained HTML calibration report and
// workspace map: line plots, overlaid histograms, grouped bars, correlation heatmaps and
// polar maps, each returned as one
// <svg> element to inline in HTML (no JavaScript, no CSS, no external fonts, no element
// ids, so several charts can share a page).
//
// Common conventions:
//  - Series colours follow a fixed Okabe-Ito palette (PlotSeriesColour), cycling after 8.
//  - Axis ticks are "nice" numbers (NiceTicks). The axes of line plots and the value axis
//    of histograms are snug: they span the data range plus a small margin (1% of the
//    span on x, 4% on y), not out to the next tick, and the ticks are the nice numbers
//    inside. Count and bar axes start at 0 and end at the first tick above the data.
//  - All user text is XML-escaped; numbers are written compactly ("150", "0.25", "1e+05")
//    and non-finite values never reach the output as "nan" or "inf".
//  - Empty input (or input with no finite value) gives a valid SVG that says "no data".
//  - width_px and height_px are raised to at least 240 x 160 and capped at 20000.
#ifndef FASTCAL_SVG_PLOT_H_
#define FASTCAL_SVG_PLOT_H_

#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace fastcal {

struct PlotSeries {
  std::string name;  // Legend text; an empty name leaves the series out of the legend.
  // Points (x[i], y[i]) for i < min(x.size(), y.size()). A point with a non-finite
  // coordinate is skipped and breaks the line (a gap).
  std::vector<double> x, y;
  bool dashed = false;
  bool markers_only = false;      // Dots at the points instead of a line.
  double marker_radius_px = 3.0;  // Dot radius of a markers_only series, clamped to [0.5, 10].
  // Opacity of the dots or the line, clamped to [0.05, 1]; below 1 the grid and other
  // series show through.
  double opacity = 1.0;
  // Its colour, e.g. "#C00000"; empty: the palette's for its index (PlotSeriesColour).
  std::string colour{};
  // Drawn last, over every line: marks that must stay visible (gross errors).
  bool on_top = false;
};

struct PlotOptions {
  std::string title, x_label, y_label;  // Axis labels should carry units, e.g. "t [s]".
  int width_px = 720;
  int height_px = 300;
  // SvgLinePlot: the x values are Unix times (time_text.h): the x axis shows clock times
  // ("12:30", "12:30:15"; "05-02 00:00" or dates over more than a day) at round steps
  // (1 s to 4 weeks) in the zone x_time_offset_s (seconds east of UTC), not 1.7145e+09.
  bool x_unix_time = false;
  int x_time_offset_s = 0;
  // SvgLinePlot: the x axis spans at least [x_span_lo, x_span_hi] where both are finite
  // (e.g. the days a track's windows cover, also when one window's dot is all there is);
  // by default only the data's range.
  double x_span_lo = std::numeric_limits<double>::quiet_NaN();
  double x_span_hi = std::numeric_limits<double>::quiet_NaN();
};

// Lines (or markers) over shared axes. Each series with at least one finite point is
// written as exactly one <path> element; gaps become separate subpaths ("M") of that
// path, and an isolated point between gaps is drawn as a dot. A markers_only series is
// one zero-length subpath ("M x y h0") per point, stroked with round caps.
// Z-order: all markers_only series are drawn first (underneath), then the lines, each
// group in index order, so a line stays visible over dense measured points; series
// marked on_top come last. Colours (unless a series names its own) and the legend follow
// the index.
std::string SvgLinePlot(const std::vector<PlotSeries>& series, const PlotOptions& options);

// Thins a long series for drawing while keeping its peaks and outliers (min/max per
// bucket): if it has more than `max_points` points (at least 4), its indices are cut into
// runs ("buckets") of consecutive points of nearly equal length, and each bucket keeps
// its finite points of lowest and highest y, in their original order (one point if they
// are the same), plus its first non-finite point if it has one, so that a line still
// breaks there. There are max_points / 2 buckets, max_points / 3 if the series has a
// non-finite point, so the result never has more than `max_points` points. Names and
// style are kept; a series that is short enough is returned unchanged.
// *buckets (if not null) is set to the number of buckets, 0 if nothing was thinned.
PlotSeries ThinMinMaxPerBucket(const PlotSeries& series, int max_points, int* buckets = nullptr);

// ThinMinMaxPerBucket fed a point at a time, for a series too long to hold: given its
// length n and whether any of its points is non-finite (both known from a first pass),
// Add each point in order, then Finish gives exactly ThinMinMaxPerBucket's result (the
// style of `style`, the points thinned). Memory: at most max_points points.
class MinMaxBucketThinner {
 public:
  MinMaxBucketThinner(size_t n, bool any_gap, int max_points);
  void Add(double x, double y);
  PlotSeries Finish(PlotSeries style) const;
  int buckets() const { return thinning_ ? static_cast<int>(num_buckets_) : 0; }

 private:
  void CloseBucket();
  struct Point {
    size_t index;
    double x, y;
  };
  size_t n_, num_buckets_ = 0, bucket_ = 0, next_ = 0, end_ = 0;
  bool thinning_ = false, lo_set_ = false, hi_set_ = false, gap_set_ = false;
  Point lo_{}, hi_{}, gap_{};
  std::vector<double> x_, y_;
};

struct HistogramSeries {
  std::string name;
  std::vector<double> values;  // Non-finite values are ignored.
};

// Overlaid translucent histograms with common bin edges spanning the finite values of all
// series; `bins` is clamped to [1, 1000]. Each non-empty bin is one
// <rect class="bar" data-count="N">; the legend gives each series' count n. The y label
// defaults to "count".
std::string SvgHistogram(const std::vector<HistogramSeries>& series, int bins,
                         const PlotOptions& options);

// SvgHistogram's bins, filled a value at a time (values too many to hold): bin edges
// from the finite extremes lo and hi of all series (a first pass), widened as
// SvgHistogram widens them when they are equal; Add a finite value of series s; Svg draws
// exactly what SvgHistogram draws for the same values. Series are named as in
// HistogramSeries (empty: no legend entry).
class HistogramBins {
 public:
  HistogramBins(std::vector<std::string> names, double lo, double hi, int bins);
  void Add(size_t series, double value);
  std::string Svg(const PlotOptions& options) const;

 private:
  std::vector<std::string> names_;
  double lo_, hi_, bin_width_;
  int bins_;
  std::vector<std::vector<long>> counts_;
  std::vector<long> n_;
};

// One group per category (e.g. cable 1..6), one bar per series.
struct BarGroup {
  std::string label;
  std::vector<double> values;  // values[s] belongs to series s; missing or non-finite: no bar.
};

// Grouped bars from a zero baseline, each a <rect class="bar">, with its value printed
// above it (below it if negative) to 3 significant digits. Group labels are rotated when
// they do not fit under their group.
std::string SvgGroupedBars(const std::vector<BarGroup>& groups,
                           const std::vector<std::string>& series_names,
                           const PlotOptions& options);

// Heatmap of a square matrix of values in [-1, 1] (e.g. parameter correlations; values
// outside are clamped for colour only) on a diverging blue-white-red scale with a colour
// bar. Row i / column j is labels[i] / labels[j]. Each cell is a
// <rect class="cell" data-value="0.53"> followed by its value as text (2 decimals,
// "n/a" if non-finite). Column labels are rotated when long. A matrix that is not
// labels.size() x labels.size() gives a "no data" SVG naming the problem.
std::string SvgMatrixHeatmap(const std::vector<std::string>& labels,
                             const std::vector<std::vector<double>>& matrix,
                             const PlotOptions& options);

// One row of an interval plot: a value with its standard deviation.
struct IntervalRow {
  std::string label;        // left of the row, e.g. "mass_centre_m.x: day1 → day2"
  double value = 0.0;       // non-finite: the row shows its label only
  double sigma = 0.0;       // the thick bar spans value ± sigma (< 0 or non-finite: none)
  std::string note;         // right of the row, e.g. "+0.051 ± 0.0015 m (33.9 σ)"
  bool emphasised = false;  // drawn in the second palette colour (vermillion), not the first
};

struct IntervalPlotOptions {
  PlotOptions plot;  // title, x_label (with the unit), width; the height follows the rows
  // A vertical reference line, e.g. 0 for differences; non-finite: none.
  double reference = std::numeric_limits<double>::quiet_NaN();
  // > 0: a thin bar of value ± wide_sigmas sigma around each thick one (e.g. the 3 σ at
  // which a difference counts as a change: it reaches the reference line or not).
  double wide_sigmas = 0.0;
};

// A dot-and-whisker ("forest") plot, one row per item, on one shared value axis with
// snug nice ticks: a difference and its sigma read at once against the reference line,
// where separate bars of the two values would overlap. Each row's dot is a
// <circle class="value">, its bars <line class="sigma"> (and class="wide"). No rows with a
// finite value: a "no data" SVG.
std::string SvgIntervalPlot(const std::vector<IntervalRow>& rows,
                            const IntervalPlotOptions& options);

// Shapes of the marks a polar map puts on its cells (e.g. why a workspace node fails).
enum class MarkShape { kCross, kTriangleUp, kTriangleDown, kSquare, kDiamond, kCircle, kPlus };

struct PolarMark {
  std::string label;  // legend text; empty leaves the mark out of the legend
  MarkShape shape = MarkShape::kCross;
  // A closed shape filled dark instead of white: two marks of one shape family (▼ and
  // △) then differ in more than their direction.
  bool filled = false;
};

// One cell of a polar map: an annular sector, angles from +x toward +y (counter-clockwise
// seen from above, +y up on the page), radii in the map's radial unit.
struct PolarCell {
  double radius_lo = 0.0, radius_hi = 0.0;        // >= 0
  double angle_lo_deg = 0.0, angle_hi_deg = 0.0;  // a full turn (360) gives a disc or ring
  // Its colour on the map's sequential scale; non-finite: light grey, no value.
  double value = 0.0;
  int mark = -1;        // index into PolarMapOptions::marks, drawn at its centre; -1: none
  std::string tooltip;  // shown on hover (an SVG <title> inside the cell)
};

struct PolarMapOptions {
  PlotOptions plot;          // title, size (x_label and y_label are not used)
  std::string radius_label;  // what the rings measure, e.g. "off-axis angle [deg]"
  std::string value_label;   // the colour bar's label, with its unit, e.g. "T [kN]"
  double radius_max = 0.0;   // the outer ring; <= 0: the cells' largest radius
  // The colour scale's range; value_lo >= value_hi: the cells' values' range. Several
  // maps meant to be compared should share one.
  double value_lo = 0.0, value_hi = 0.0;
  std::vector<PolarMark> marks;
  // Labels outside the outer ring at these angles (deg), e.g. the towers.
  std::vector<std::pair<double, std::string>> rim_labels;
  // Values marked on the colour bar, e.g. {130, "minimum 130"}: a line across it and its
  // label above; a value beyond the scale is drawn at the bar's end.
  std::vector<std::pair<double, std::string>> value_marks;
};

// A polar map: each cell filled by its value on a sequential (viridis-like) scale with a
// colour bar, light grey where it has none, and its mark; rings every nice step of the
// radius, labelled, spokes and azimuth labels every 30 deg. Each cell is one
// <path class="cell" data-value="..."> (data-value "n/a" without one) holding its
// <title>; each mark one <path class="mark" data-mark="k">. The legend lists the marks,
// each with its label. No cells with a positive extent: a "no data" SVG.
std::string SvgPolarMap(const std::vector<PolarCell>& cells, const PolarMapOptions& options);

// Escapes & < > " ' for XML text and attribute values; drops control characters that
// XML 1.0 forbids (all below 0x20 except tab, newline and carriage return).
std::string XmlEscape(const std::string& text);

// "Nice" axis ticks covering [lo, hi] (the first tick <= lo, the last >= hi): about
// `target` ticks (clamped to [2, 50]) spaced by 1, 2 or 5 x 10^k. A degenerate range
// (lo == hi) is padded by 1% of |lo| (by 1 if lo == 0). lo > hi is treated as swapped.
// Returns an empty vector if lo or hi is not finite.
std::vector<double> NiceTicks(double lo, double hi, int target);

// A label to put beside a circle (a stop's number on the design's map of the cap).
struct CircleLabel {
  double x_px = 0.0, y_px = 0.0, radius_px = 0.0;  // the circle
  std::string text;
};
// Where a label goes: its left edge and its baseline (SVG <text x y>).
struct LabelSpot {
  double x_px = 0.0, baseline_px = 0.0;
};

// Each label at the first of six spots around its circle (right, right below, left, left
// below, above, below) where its box (char_px a character wide, height_px high) overlaps
// no label placed before it; where every spot is taken, the first. Labels in the given
// order: circles a few pixels apart stay readable.
std::vector<LabelSpot> PlaceCircleLabels(const std::vector<CircleLabel>& labels, double char_px,
                                         double height_px);

// Colour (e.g. "#0072B2") of series `index` in every chart, for matching tables or text
// in the report to the plots. Cycles through the 8 Okabe-Ito colours.
std::string PlotSeriesColour(int index);

}  // namespace fastcal

#endif  // FASTCAL_SVG_PLOT_H_
