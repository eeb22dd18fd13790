// Tests of the SVG chart writer (svg_plot.h): nice ticks, XML escaping, well-formed
// output, gaps and non-finite data, histogram counts, grouped-bar labels, the heatmap
// cells and the "no data" charts.
#include "fastcal/svg_plot.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <regex>
#include <set>
#include <string>
#include <vector>

namespace fastcal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Minimal XML check: balanced start/end tags (a stack), quoted attributes, and every '&'
// starting one of the five predefined entities. Returns "" or a description.
std::string XmlProblem(const std::string& xml) {
  std::vector<std::string> stack;
  size_t i = 0;
  while (i < xml.size()) {
    const char c = xml[i];
    if (c == '&') {
      static const std::regex kEntity("^&(amp|lt|gt|quot|apos);");
      if (!std::regex_search(xml.substr(i, 8), kEntity)) return "bare '&' at " + std::to_string(i);
      ++i;
      continue;
    }
    if (c == '>') return "stray '>' at " + std::to_string(i);
    if (c != '<') {
      ++i;
      continue;
    }
    // Find the closing '>' outside quoted attribute values.
    size_t j = i + 1;
    bool in_quote = false;
    while (j < xml.size() && (in_quote || xml[j] != '>')) {
      if (xml[j] == '"') in_quote = !in_quote;
      if (!in_quote && xml[j] == '<') return "'<' inside tag at " + std::to_string(j);
      ++j;
    }
    if (j == xml.size()) return "unterminated tag at " + std::to_string(i);
    const std::string tag = xml.substr(i + 1, j - i - 1);
    i = j + 1;
    if (tag.empty()) return "empty tag";
    if (tag[0] == '/') {
      const std::string name = tag.substr(1);
      if (stack.empty() || stack.back() != name) return "unexpected </" + name + ">";
      stack.pop_back();
      continue;
    }
    const std::string name = tag.substr(0, tag.find_first_of(" \n/"));
    if (name.empty()) return "nameless tag";
    if (stack.empty() && name != "svg") return "content outside <svg>: " + name;
    if (tag.back() != '/') stack.push_back(name);
  }
  if (!stack.empty()) return "unclosed <" + stack.back() + ">";
  return "";
}

void ExpectValidSvg(const std::string& svg) {
  EXPECT_EQ(svg.rfind("<svg", 0), 0u) << svg.substr(0, 80);
  ASSERT_GE(svg.size(), 6u);
  EXPECT_EQ(svg.substr(svg.size() - 6), "</svg>");
  EXPECT_EQ(XmlProblem(svg), "") << svg;
}

int Count(const std::string& text, const std::string& needle) {
  int n = 0;
  for (size_t p = text.find(needle); p != std::string::npos; p = text.find(needle, p + 1)) ++n;
  return n;
}

// Attribute values of all elements starting with `element_prefix`, e.g. "<rect class=\"bar\"".
std::vector<std::string> Attribute(const std::string& svg, const std::string& element_prefix,
                                   const std::string& attribute) {
  std::vector<std::string> values;
  for (size_t p = svg.find(element_prefix); p != std::string::npos;
       p = svg.find(element_prefix, p + 1)) {
    const std::string tag = svg.substr(p, svg.find('>', p) - p);
    const size_t a = tag.find(" " + attribute + "=\"");
    if (a == std::string::npos) continue;
    const size_t start = a + attribute.size() + 3;
    values.push_back(tag.substr(start, tag.find('"', start) - start));
  }
  return values;
}

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

void ExpectNiceStep(double step) {
  ASSERT_GT(step, 0.0);
  const double mantissa = step / std::pow(10.0, std::floor(std::log10(step) + 1e-9));
  const bool nice = std::fabs(mantissa - 1.0) < 1e-6 || std::fabs(mantissa - 2.0) < 1e-6 ||
                    std::fabs(mantissa - 5.0) < 1e-6;
  EXPECT_TRUE(nice) << "step " << step;
}

void ExpectGoodTicks(const std::vector<double>& ticks, double lo, double hi) {
  ASSERT_GE(ticks.size(), 2u);
  EXPECT_LE(ticks.front(), lo);
  EXPECT_GE(ticks.back(), hi);
  const double step = ticks[1] - ticks[0];
  ExpectNiceStep(step);
  for (size_t i = 1; i < ticks.size(); ++i) {
    EXPECT_NEAR(ticks[i] - ticks[i - 1], step, 1e-9 * step) << "at " << i;
  }
}

// PlotOptions::x_span_lo/hi: a lone point's axis spans the given range (its ticks reach
// both ends), not a padded sliver around the point; without a span it does not.
TEST(SvgLinePlot, XSpanWidensTheAxis) {
  PlotSeries dot;
  dot.name = "estimate";
  dot.markers_only = true;
  dot.x = {50.0};
  dot.y = {1.0};
  PlotOptions o;
  o.x_label = "t [s]";
  const std::string alone = SvgLinePlot({dot}, o);
  EXPECT_EQ(alone.find(">100<"), std::string::npos);
  o.x_span_lo = 0.0;
  o.x_span_hi = 100.0;
  const std::string spanned = SvgLinePlot({dot}, o);
  ExpectValidSvg(spanned);
  EXPECT_NE(spanned.find(">0<"), std::string::npos);
  EXPECT_NE(spanned.find(">100<"), std::string::npos);
}

TEST(NiceTicks, UnitInterval) {
  const std::vector<double> ticks = NiceTicks(0.0, 1.0, 5);
  const std::vector<double> expected = {0.0, 0.2, 0.4, 0.6, 0.8, 1.0};
  ASSERT_EQ(ticks.size(), expected.size());
  for (size_t i = 0; i < ticks.size(); ++i) EXPECT_DOUBLE_EQ(ticks[i], expected[i]);
}

TEST(NiceTicks, MixedSignRange) {
  const std::vector<double> ticks = NiceTicks(-3.7, 12.2, 5);
  ExpectGoodTicks(ticks, -3.7, 12.2);
  const std::vector<double> expected = {-5.0, 0.0, 5.0, 10.0, 15.0};
  ASSERT_EQ(ticks.size(), expected.size());
  for (size_t i = 0; i < ticks.size(); ++i) EXPECT_DOUBLE_EQ(ticks[i], expected[i]);
}

TEST(NiceTicks, DegenerateRangeIsPadded) {
  for (double v : {149.5, 0.0, -2.5e-7, 3e12}) {
    const std::vector<double> ticks = NiceTicks(v, v, 5);
    ASSERT_GE(ticks.size(), 2u) << v;
    for (size_t i = 1; i < ticks.size(); ++i) EXPECT_GT(ticks[i], ticks[i - 1]) << v;
    EXPECT_LT(ticks.front(), v);
    EXPECT_GT(ticks.back(), v);
    ExpectGoodTicks(ticks, v, v);
  }
}

TEST(NiceTicks, RandomRangesHaveNiceCoveringSteps) {
  std::mt19937_64 rng(20261121);
  std::uniform_real_distribution<double> exponent(-8.0, 8.0), unit(-1.0, 1.0);
  std::uniform_int_distribution<int> target(2, 10);
  for (int trial = 0; trial < 2000; ++trial) {
    const double scale = std::pow(10.0, exponent(rng));
    const double a = unit(rng) * scale, b = a + std::fabs(unit(rng)) * scale * 0.5;
    const int t = target(rng);
    const std::vector<double> ticks = NiceTicks(a, b, t);
    SCOPED_TRACE(::testing::Message() << "[" << a << ", " << b << "] target " << t);
    ExpectGoodTicks(ticks, a, b);
    EXPECT_LE(ticks.size(), static_cast<size_t>(2 * t + 3));
  }
}

TEST(NiceTicks, SwappedAndNonFiniteInput) {
  EXPECT_EQ(NiceTicks(1.0, 0.0, 5), NiceTicks(0.0, 1.0, 5));
  EXPECT_TRUE(NiceTicks(kNaN, 1.0, 5).empty());
  EXPECT_TRUE(NiceTicks(0.0, kInf, 5).empty());
}

TEST(XmlEscape, EscapesMarkupAndDropsForbiddenControls) {
  EXPECT_EQ(XmlEscape("<a & \"b\">"), "&lt;a &amp; &quot;b&quot;&gt;");
  EXPECT_EQ(XmlEscape("it's"), "it&apos;s");
  EXPECT_EQ(XmlEscape(std::string("a\x01\tb\n")), "a\tb\n");
  EXPECT_EQ(XmlEscape("\xCE\xB8 [rad]"), "\xCE\xB8 [rad]");  // UTF-8 passes through.
}

TEST(PlotSeriesColour, EightDistinctColoursThenCycle) {
  std::set<std::string> colours;
  for (int i = 0; i < 8; ++i) colours.insert(PlotSeriesColour(i));
  EXPECT_EQ(colours.size(), 8u);
  EXPECT_EQ(PlotSeriesColour(8), PlotSeriesColour(0));
  EXPECT_EQ(PlotSeriesColour(-1), PlotSeriesColour(7));
}

PlotOptions Options() {
  PlotOptions o;
  o.title = "Cable length residuals";
  o.x_label = "time [s]";
  o.y_label = "residual [mm]";
  return o;
}

TEST(SvgLinePlot, ContainsTitleLabelsAndOnePathPerSeries) {
  std::vector<PlotSeries> series(3);
  series[0].name = "cable 1";
  series[1].name = "cable <2>";
  series[1].dashed = true;
  series[2].name = "measured";
  series[2].markers_only = true;
  for (int i = 0; i <= 50; ++i) {
    for (int s = 0; s < 3; ++s) {
      series[s].x.push_back(i * 0.2);
      series[s].y.push_back(std::sin(i * 0.2 + s) * (s + 1));
    }
  }
  const std::string svg = SvgLinePlot(series, Options());
  ExpectValidSvg(svg);
  EXPECT_NE(svg.find("Cable length residuals"), std::string::npos);
  EXPECT_NE(svg.find(">time [s]<"), std::string::npos);
  EXPECT_NE(svg.find(">residual [mm]<"), std::string::npos);
  EXPECT_NE(svg.find(">cable 1<"), std::string::npos);
  EXPECT_NE(svg.find(">cable &lt;2&gt;<"), std::string::npos);
  EXPECT_EQ(svg.find("cable <2>"), std::string::npos);
  EXPECT_NE(svg.find(">measured<"), std::string::npos);
  EXPECT_EQ(Count(svg, "<path"), 3);
  EXPECT_EQ(Count(svg, "stroke-dasharray"), 2);  // The dashed path and its legend swatch.
  EXPECT_NE(svg.find("width=\"720\" height=\"300\""), std::string::npos);
  // Series colours come from the palette by index; the markers are drawn first.
  const std::vector<std::string> strokes = Attribute(svg, "<path", "stroke");
  ASSERT_EQ(strokes.size(), 3u);
  EXPECT_EQ(strokes[0], PlotSeriesColour(2));
  EXPECT_EQ(strokes[1], PlotSeriesColour(0));
  EXPECT_EQ(strokes[2], PlotSeriesColour(1));
  // A marker is a zero-length subpath with round caps: one per point.
  EXPECT_EQ(Count(Attribute(svg, "<path", "d")[0], "h0"), 51);
  EXPECT_EQ(Attribute(svg, "<path", "stroke-linecap")[0], "round");
}

TEST(SvgLinePlot, MarkersAreSmallTranslucentAndUnderTheLines) {
  // Index order: line, markers, dashed line. Drawing order must be markers first.
  std::vector<PlotSeries> series(3);
  series[0].name = "model before";
  series[0].dashed = true;
  series[1].name = "measured";
  series[1].markers_only = true;
  series[1].marker_radius_px = 1.5;
  series[1].opacity = 0.4;
  series[2].name = "model after";
  for (int i = 0; i < 40; ++i) {
    for (PlotSeries& s : series) {
      s.x.push_back(i);
      s.y.push_back(100.0 + i);  // All three on top of each other.
    }
  }
  const std::string svg = SvgLinePlot(series, Options());
  ExpectValidSvg(svg);
  const size_t markers = svg.find("<path d=\"M");
  ASSERT_NE(markers, std::string::npos);
  EXPECT_NE(svg.find("stroke=\"" + PlotSeriesColour(1) + "\"", markers), std::string::npos);
  EXPECT_LT(svg.find("stroke=\"" + PlotSeriesColour(1) + "\""),
            svg.find("stroke=\"" + PlotSeriesColour(0) + "\""));
  EXPECT_LT(svg.find("stroke=\"" + PlotSeriesColour(0) + "\""),
            svg.find("stroke=\"" + PlotSeriesColour(2) + "\""));
  // The markers' size and opacity; the lines stay opaque.
  EXPECT_EQ(Attribute(svg, "<path", "stroke-width"), (std::vector<std::string>{"3", "1.8", "1.8"}));
  EXPECT_EQ(Attribute(svg, "<path", "stroke-opacity"), std::vector<std::string>{"0.4"});
  // The legend, in index order, says which is which: a dashed line, a dot, a line.
  const size_t before = svg.find(">model before<"), measured = svg.find(">measured<"),
               after = svg.find(">model after<");
  ASSERT_NE(before, std::string::npos);
  ASSERT_NE(measured, std::string::npos);
  ASSERT_NE(after, std::string::npos);
  EXPECT_LT(before, measured);
  EXPECT_LT(measured, after);
  EXPECT_EQ(Attribute(svg, "<circle", "fill"), std::vector<std::string>{PlotSeriesColour(1)});
  EXPECT_EQ(Attribute(svg, "<circle", "fill-opacity"), std::vector<std::string>{"0.4"});
}

// The plot area (the border rect drawn after the series) as {left, top, right, bottom}.
std::array<double, 4> PlotBox(const std::string& svg) {
  const std::string tag = "<rect x=";
  size_t at = std::string::npos;
  for (size_t p = svg.find(tag); p != std::string::npos; p = svg.find(tag, p + 1)) {
    if (svg.substr(p, svg.find('>', p) - p).find("fill=\"none\"") != std::string::npos) at = p;
  }
  if (at == std::string::npos) return {0, 0, 0, 0};
  const std::string rect = svg.substr(at, svg.find('>', at) - at);
  const double x = std::stod(Attribute(rect, "<rect", "x")[0]);
  const double y = std::stod(Attribute(rect, "<rect", "y")[0]);
  return {x, y, x + std::stod(Attribute(rect, "<rect", "width")[0]),
          y + std::stod(Attribute(rect, "<rect", "height")[0])};
}

// The (x, y) pixel coordinates of "M"/"L" commands in a path's d attribute.
std::vector<std::array<double, 2>> PathPoints(const std::string& d) {
  std::vector<std::array<double, 2>> points;
  static const std::regex kPoint("[ML](-?[0-9.]+) (-?[0-9.]+)");
  for (std::sregex_iterator it(d.begin(), d.end(), kPoint), end; it != end; ++it) {
    points.push_back({std::stod((*it)[1]), std::stod((*it)[2])});
  }
  return points;
}

TEST(SvgLinePlot, AxesAreSnugAroundTheData) {
  // Times 0 ... 359 s used to get an axis to 400 s (10% empty); values 98 ... 262 one
  // from 50 to 300.
  PlotSeries s{"tension", {}, {}};
  for (int i = 0; i < 360; ++i) {
    s.x.push_back(i);
    s.y.push_back(180.0 + 82.0 * std::sin(i * 0.0175));
  }
  for (int width : {540, 720, 1000}) {
    PlotOptions o = Options();
    o.width_px = width;
    const std::string svg = SvgLinePlot({s}, o);
    ExpectValidSvg(svg);
    SCOPED_TRACE(width);
    const std::array<double, 4> box = PlotBox(svg);
    const std::vector<std::array<double, 2>> points = PathPoints(Attribute(svg, "<path", "d")[0]);
    ASSERT_EQ(points.size(), 360u);
    double left = 1e9, right = -1e9, top = 1e9, bottom = -1e9;
    for (const auto& p : points) {
      left = std::min(left, p[0]);
      right = std::max(right, p[0]);
      top = std::min(top, p[1]);
      bottom = std::max(bottom, p[1]);
    }
    const double w = box[2] - box[0], h = box[3] - box[1];
    // At most the margins (1% on x, 4% on y) plus rounding to 0.1 px.
    EXPECT_LE(left - box[0], 0.011 * w);
    EXPECT_LE(box[2] - right, 0.011 * w);
    EXPECT_LE(top - box[1], 0.041 * h);
    EXPECT_LE(box[3] - bottom, 0.041 * h);
    EXPECT_GE(left, box[0]);
    EXPECT_LE(right, box[2]);
    // Every tick is inside the axis: no "400" past the last sample.
    EXPECT_EQ(svg.find(">400<"), std::string::npos);
    EXPECT_NE(svg.find(">0<"), std::string::npos);
    EXPECT_GE(Count(svg, "text-anchor=\"middle\" font-size=\"11\""), 2);  // x tick labels
  }
}

TEST(ThinMinMaxPerBucket, ShortSeriesAreUnchanged) {
  PlotSeries s{"short", {0, 1, 2, kNaN}, {5, 6, 7, 8}, true, false, 2.0, 0.5};
  int buckets = -1;
  const PlotSeries t = ThinMinMaxPerBucket(s, 4, &buckets);
  EXPECT_EQ(buckets, 0);
  EXPECT_EQ(t.y, s.y);
  EXPECT_EQ(t.name, "short");
  EXPECT_TRUE(t.dashed);
}

TEST(ThinMinMaxPerBucket, KeepsOutliersOrderAndTheLimit) {
  PlotSeries s{"long", {}, {}, false, true, 1.8, 0.45};
  constexpr int kN = 60000;
  for (int i = 0; i < kN; ++i) {
    s.x.push_back(0.1 * i);
    s.y.push_back(200.0 + 20.0 * std::sin(i * 1e-4) + std::sin(i * 7.3));
  }
  s.y[31337] = 900.0;  // Outliers a stride would drop.
  s.y[4243] = -50.0;
  int buckets = 0;
  const PlotSeries t = ThinMinMaxPerBucket(s, 2000, &buckets);
  EXPECT_EQ(buckets, 1000);
  EXPECT_LE(t.x.size(), 2000u);
  EXPECT_GE(t.x.size(), 1900u);
  ASSERT_EQ(t.x.size(), t.y.size());
  EXPECT_TRUE(t.markers_only);
  EXPECT_EQ(t.opacity, 0.45);
  EXPECT_TRUE(std::is_sorted(t.x.begin(), t.x.end()));
  EXPECT_EQ(*std::max_element(t.y.begin(), t.y.end()), 900.0);
  EXPECT_EQ(*std::min_element(t.y.begin(), t.y.end()), -50.0);
  // The outliers keep their times.
  EXPECT_DOUBLE_EQ(t.x[std::max_element(t.y.begin(), t.y.end()) - t.y.begin()], 3133.7);
  // Every kept point is a point of the series.
  for (size_t i = 0; i < t.x.size(); ++i) {
    const size_t n = static_cast<size_t>(std::lround(t.x[i] * 10.0));
    ASSERT_LT(n, s.y.size());
    EXPECT_EQ(t.y[i], s.y[n]) << i;
  }
}

TEST(ThinMinMaxPerBucket, GapsStillBreakTheLine) {
  PlotSeries s{"gappy", {}, {}};
  for (int i = 0; i < 10000; ++i) {
    s.x.push_back(i);
    s.y.push_back(i >= 5000 && i < 5100 ? kNaN : std::cos(i * 0.01));
  }
  int buckets = 0;
  const PlotSeries t = ThinMinMaxPerBucket(s, 300, &buckets);
  EXPECT_EQ(buckets, 100);  // A third of the points: min, max and a gap per bucket.
  EXPECT_LE(t.x.size(), 300u);
  EXPECT_TRUE(std::any_of(t.y.begin(), t.y.end(), [](double v) { return std::isnan(v); }));
  const std::string svg = SvgLinePlot({t}, Options());
  ExpectValidSvg(svg);
  EXPECT_EQ(Count(Attribute(svg, "<path", "d")[0], "M"), 2);  // Before and after the gap.
}

TEST(SvgLinePlot, NonFiniteValuesMakeGapsNotNan) {
  PlotSeries s;
  s.name = "with gaps";
  s.x = {0, 1, 2, 3, 4, 5, 6, 7};
  s.y = {1, 2, kNaN, 3, 4, kInf, 5, -kInf};
  s.x[4] = kNaN;  // Point 4 is also skipped: run {3} is an isolated point.
  const std::string svg = SvgLinePlot({s}, Options());
  ExpectValidSvg(svg);
  EXPECT_EQ(Lower(svg).find("nan"), std::string::npos);
  EXPECT_EQ(Lower(svg).find("inf"), std::string::npos);
  // One path per series; each finite run is a subpath.
  ASSERT_EQ(Count(svg, "<path"), 1);
  const std::string d = Attribute(svg, "<path", "d")[0];
  EXPECT_EQ(Count(d, "M"), 3) << d;  // {0,1}, {3}, {6}
  EXPECT_EQ(Count(d, "L"), 1) << d;
  EXPECT_EQ(Count(d, "a"), 4) << d;  // The isolated points are drawn as dots (2 arcs each).
}

TEST(SvgLinePlot, SinglePointAndConstantDataGiveSensibleAxes) {
  PlotSeries s;
  s.name = "one";
  s.x = {149.5};
  s.y = {149.5};
  std::string svg = SvgLinePlot({s}, Options());
  ExpectValidSvg(svg);
  EXPECT_EQ(Lower(svg).find("nan"), std::string::npos);
  EXPECT_NE(svg.find(">149.5<"), std::string::npos);  // The point sits on a padded axis.

  s.x = {0, 1, 2};
  s.y = {7, 7, 7};
  svg = SvgLinePlot({s}, Options());
  ExpectValidSvg(svg);
  EXPECT_GE(Count(svg, "<text"), 6);
}

TEST(SvgLinePlot, EmptyInputSaysNoData) {
  for (const std::vector<PlotSeries>& input :
       {std::vector<PlotSeries>{}, std::vector<PlotSeries>{PlotSeries{"x", {}, {}}},
        std::vector<PlotSeries>{PlotSeries{"nan", {kNaN}, {1.0}}}}) {
    const std::string svg = SvgLinePlot(input, Options());
    ExpectValidSvg(svg);
    EXPECT_NE(svg.find("no data"), std::string::npos);
    EXPECT_NE(svg.find("Cable length residuals"), std::string::npos);
  }
}

TEST(SvgLinePlot, SizeIsConfigurableAndTickLabelsAreCompact) {
  PlotOptions o = Options();
  o.width_px = 400;
  o.height_px = 200;
  PlotSeries s{"big", {0, 1, 2}, {0, 5e5, 1e6}};
  const std::string svg = SvgLinePlot({s}, o);
  ExpectValidSvg(svg);
  EXPECT_NE(svg.find("width=\"400\" height=\"200\" viewBox=\"0 0 400 200\""), std::string::npos);
  EXPECT_NE(svg.find("e+05<"), std::string::npos);
  EXPECT_EQ(svg.find("500000"), std::string::npos);
}

TEST(SvgHistogram, BarHeightsAreProportionalToCounts) {
  HistogramSeries a{"before", {0.0, 0.1, 0.2, 1.0, 1.1, 2.9, kNaN}};
  HistogramSeries b{"after", {0.0, 3.0, 2.95, 2.9}};
  const std::string svg = SvgHistogram({a, b}, 3, Options());
  ExpectValidSvg(svg);
  EXPECT_EQ(Lower(svg).find("nan"), std::string::npos);
  EXPECT_NE(svg.find(">before (n=6)<"), std::string::npos);
  EXPECT_NE(svg.find(">after (n=4)<"), std::string::npos);
  const std::vector<std::string> counts = Attribute(svg, "<rect class=\"bar\"", "data-count");
  const std::vector<std::string> heights = Attribute(svg, "<rect class=\"bar\"", "height");
  const std::vector<std::string> xs = Attribute(svg, "<rect class=\"bar\"", "x");
  // Edges 0, 1, 2, 3: "before" has 3, 2, 1; "after" has 1, 0 (no bar), 3.
  ASSERT_EQ(counts, (std::vector<std::string>{"3", "2", "1", "1", "3"}));
  ASSERT_EQ(heights.size(), counts.size());
  const double per_count = std::stod(heights[0]) / 3.0;
  for (size_t i = 0; i < counts.size(); ++i) {
    EXPECT_NEAR(std::stod(heights[i]), per_count * std::stod(counts[i]), 0.11) << i;
  }
  // Common bin edges.
  EXPECT_EQ(xs[0], xs[3]);
  EXPECT_EQ(xs[2], xs[4]);
  EXPECT_NE(svg.find(">residual [mm]<"), std::string::npos);
}

TEST(SvgHistogram, CountAxisDefaultsAndDegenerateValues) {
  PlotOptions o = Options();
  o.y_label.clear();
  const std::string svg = SvgHistogram({{"same", {2.5, 2.5}}}, 10, o);
  ExpectValidSvg(svg);
  EXPECT_NE(svg.find(">count<"), std::string::npos);
  EXPECT_EQ(Attribute(svg, "<rect class=\"bar\"", "data-count"), std::vector<std::string>{"2"});
  // Integer count axis: no fractional tick labels.
  EXPECT_EQ(svg.find(">0.5<"), std::string::npos);
}

TEST(SvgHistogram, EmptyInputSaysNoData) {
  for (const std::vector<HistogramSeries>& input :
       {std::vector<HistogramSeries>{}, std::vector<HistogramSeries>{{"x", {kNaN, kInf}}}}) {
    const std::string svg = SvgHistogram(input, 20, Options());
    ExpectValidSvg(svg);
    EXPECT_NE(svg.find("no data"), std::string::npos);
  }
}

TEST(SvgGroupedBars, ValuesArePrintedWithThreeSignificantDigits) {
  std::vector<BarGroup> groups = {
      {"cable 1", {150.0, 0.25}}, {"cable 2", {1234.5, -0.001234}}, {"cable 3", {1e5, kNaN}}};
  const std::string svg = SvgGroupedBars(groups, {"RMS [mm]", "bias <mm>"}, Options());
  ExpectValidSvg(svg);
  for (const char* label : {">150<", ">0.25<", ">1230<", ">-0.00123<", ">1e+05<", ">cable 1<",
                            ">cable 3<", ">RMS [mm]<", ">bias &lt;mm&gt;<"}) {
    EXPECT_NE(svg.find(label), std::string::npos) << label;
  }
  EXPECT_EQ(Count(svg, "<rect class=\"bar\""), 5);  // The NaN value has no bar.
  EXPECT_EQ(Lower(svg).find("nan"), std::string::npos);
}

TEST(SvgGroupedBars, LongGroupLabelsAreRotated) {
  std::vector<BarGroup> groups;
  for (int i = 1; i <= 12; ++i) {
    groups.push_back({"tower " + std::to_string(i) + " pulley exit", {1.0 * i, 2.0 * i}});
  }
  const std::string svg = SvgGroupedBars(groups, {"a", "b"}, Options());
  ExpectValidSvg(svg);
  EXPECT_NE(svg.find("rotate(-40"), std::string::npos);
}

TEST(SvgGroupedBars, EmptyInputSaysNoData) {
  const std::string svg = SvgGroupedBars({}, {"a"}, Options());
  ExpectValidSvg(svg);
  EXPECT_NE(svg.find("no data"), std::string::npos);
  EXPECT_NE(SvgGroupedBars({{"g", {kNaN}}}, {"a"}, Options()).find("no data"), std::string::npos);
}

TEST(SvgMatrixHeatmap, HasOneCellPerEntryWithItsValue) {
  const std::vector<std::string> labels = {"EA", "rho", "m", "<dz>"};
  const std::vector<std::vector<double>> m = {{1.0, 0.534, -0.25, 0.0},
                                              {0.534, 1.0, -0.999, -0.001},
                                              {-0.25, -0.999, 1.0, kNaN},
                                              {0.0, -0.001, kNaN, 1.0}};
  const std::string svg = SvgMatrixHeatmap(labels, m, Options());
  ExpectValidSvg(svg);
  EXPECT_EQ(Count(svg, "<rect class=\"cell\""), 16);
  const std::vector<std::string> values = Attribute(svg, "<rect class=\"cell\"", "data-value");
  ASSERT_EQ(values.size(), 16u);
  EXPECT_EQ(values[0], "1.00");
  EXPECT_EQ(values[1], "0.53");
  EXPECT_EQ(values[2], "-0.25");
  EXPECT_EQ(values[6], "-1.00");
  EXPECT_EQ(values[7], "0.00");  // -0.001 rounds to 0.00, not "-0.00".
  EXPECT_EQ(values[11], "n/a");
  EXPECT_NE(svg.find(">0.53</text>"), std::string::npos);
  EXPECT_NE(svg.find(">-0.25</text>"), std::string::npos);
  EXPECT_EQ(Count(svg, ">&lt;dz&gt;</text>"), 2);  // Row and column labels.
  EXPECT_EQ(Lower(svg).find("nan"), std::string::npos);
  // Diverging scale: +1 red, -1 blue.
  EXPECT_EQ(Attribute(svg, "<rect class=\"cell\"", "fill")[0], "#b2182b");
  EXPECT_EQ(Attribute(svg, "<rect class=\"cell\"", "fill")[6], "#2166ac");
}

TEST(SvgMatrixHeatmap, LongLabelsAreRotated) {
  std::vector<std::string> labels;
  for (int i = 0; i < 9; ++i) labels.push_back("anchor offset " + std::to_string(i) + " x");
  const std::vector<std::vector<double>> m(9, std::vector<double>(9, 0.1));
  const std::string svg = SvgMatrixHeatmap(labels, m, Options());
  ExpectValidSvg(svg);
  EXPECT_EQ(Count(svg, "<rect class=\"cell\""), 81);
  EXPECT_EQ(Count(svg, "rotate(-45"), 9);
}

TEST(SvgMatrixHeatmap, EmptyOrNonSquareSaysNoData) {
  std::string svg = SvgMatrixHeatmap({}, {}, Options());
  ExpectValidSvg(svg);
  EXPECT_NE(svg.find("no data"), std::string::npos);
  svg = SvgMatrixHeatmap({"a", "b"}, {{1.0, 0.0}, {0.0}}, Options());
  ExpectValidSvg(svg);
  EXPECT_NE(svg.find("no data"), std::string::npos);
  EXPECT_EQ(Count(svg, "class=\"cell\""), 0);
}

// A polar map: one cell path per cell with its value (n/a without one, grey), the colour
// scale's range from the cells or the options, a mark per marked cell with the legend's
// labels, the rim labels, and the azimuth labels only where no rim label is near.
TEST(SvgPolarMap, CellsMarksScaleAndLabels) {
  std::vector<PolarCell> cells;
  cells.push_back({0.0, 0.5, 0.0, 360.0, 150.0, -1, "axis"});  // the centre disc
  for (int k = 0; k < 12; ++k) {
    const double a = 30.0 * k;
    cells.push_back({0.5, 1.5, a - 15.0, a + 15.0, k == 3 ? kNaN : 100.0 + k, k % 4 == 0 ? 1 : -1,
                     "cell <" + std::to_string(k) + ">"});
  }
  PolarMapOptions options;
  options.plot.title = "cap";
  options.value_label = "T [kN]";
  options.radius_label = "off-axis angle [deg]";
  options.marks = {{"", MarkShape::kCross}, {"below the minimum (3)", MarkShape::kTriangleDown}};
  options.rim_labels = {{0.0, "T1"}, {120.0, "T3"}};
  std::string svg = SvgPolarMap(cells, options);
  ExpectValidSvg(svg);
  EXPECT_EQ(Count(svg, "<path class=\"cell\""), 13);
  const std::vector<std::string> values = Attribute(svg, "<path class=\"cell\"", "data-value");
  EXPECT_EQ(values[0], "150");
  EXPECT_EQ(Count(svg, "data-value=\"n/a\""), 1);
  EXPECT_EQ(Count(svg, "class=\"mark\" data-mark=\"1\""), 3);
  EXPECT_NE(svg.find("below the minimum (3)"), std::string::npos);
  EXPECT_NE(svg.find("cell &lt;4&gt;"), std::string::npos);  // tooltips escaped
  EXPECT_NE(svg.find(">T1<"), std::string::npos);
  EXPECT_NE(svg.find(">T3<"), std::string::npos);
  EXPECT_EQ(svg.find(">120\u00b0<"), std::string::npos);  // T3 is there
  EXPECT_NE(svg.find(">90\u00b0<"), std::string::npos);
  EXPECT_NE(svg.find("T [kN]"), std::string::npos);
  EXPECT_EQ(Lower(svg).find("nan"), std::string::npos);
  // The scale from the cells spans 100 to 150 kN; a shared one from the options.
  EXPECT_NE(svg.find(">110<"), std::string::npos);
  options.value_lo = 0.0;
  options.value_hi = 500.0;
  svg = SvgPolarMap(cells, options);
  EXPECT_NE(svg.find(">400<"), std::string::npos);
  EXPECT_NE(SvgPolarMap({}, options).find("no data"), std::string::npos);
}

// The colour bar marks a value (a limit) with its label; a value beyond the scale at the
// bar's end. A filled mark is drawn dark, in the map and in the legend.
TEST(SvgPolarMap, ValueMarksOnTheColourBarAndFilledMarks) {
  std::vector<PolarCell> cells;
  for (int k = 0; k < 12; ++k) {
    cells.push_back(
        {0.5, 1.5, 30.0 * k - 15.0, 30.0 * k + 15.0, 100.0 + 5.0 * k, k % 2 == 0 ? 0 : 1, ""});
  }
  PolarMapOptions options;
  options.marks = {{"below the minimum", MarkShape::kTriangleDown, true},
                   {"above the maximum", MarkShape::kTriangleUp, false}};
  options.value_marks = {{130.0, "minimum 130 kN"}, {900.0, "beyond"}};
  const std::string svg = SvgPolarMap(cells, options);
  ExpectValidSvg(svg);
  EXPECT_NE(svg.find(">minimum 130 kN<"), std::string::npos);
  EXPECT_NE(svg.find(">beyond<"), std::string::npos);
  // Six marks of each kind, plus one in each legend entry: the filled one's outline is
  // filled with the outline's dark colour, the other's not (its white halo shows).
  const std::regex outline("<path d=\"[^\"]+\" fill=\"([^\"]+)\" stroke=\"#111111\"");
  int filled = 0, hollow = 0;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), outline);
       it != std::sregex_iterator(); ++it) {
    ((*it)[1] == "none" ? hollow : filled) += 1;
    if ((*it)[1] != "none") {
      EXPECT_EQ((*it)[1], "#111111");
    }
  }
  EXPECT_EQ(filled, 7);
  EXPECT_EQ(hollow, 7);
}

// A series may name its colour and be drawn over everything else (gross errors).
TEST(SvgLinePlot, ASeriesOwnColourAndOnTop) {
  PlotSeries line{"model", {0, 1, 2}, {1, 2, 3}};
  PlotSeries gross{"gross error", {1}, {9}, false, true};
  gross.colour = "#C00000";
  gross.on_top = true;
  const std::string svg = SvgLinePlot({gross, line}, PlotOptions());
  ExpectValidSvg(svg);
  const size_t model = svg.find("stroke=\"" + PlotSeriesColour(1) + "\" stroke-width=\"1.8\"");
  const size_t red = svg.find("stroke=\"#C00000\" stroke-width=\"6\"");
  ASSERT_NE(model, std::string::npos) << svg;
  ASSERT_NE(red, std::string::npos) << svg;
  EXPECT_GT(red, model);  // drawn after the line, though a marker and first in the list
  EXPECT_EQ(svg.find(PlotSeriesColour(0)), std::string::npos);  // its own colour, not slot 0's
}

// A dot-and-whisker plot: one dot per row at its value, a thick bar of +-sigma and a thin
// one of +-wide_sigmas sigma, the reference line, labels and notes; the axis covers the
// bars and the reference; the emphasised row in the second colour.
TEST(SvgIntervalPlot, DotsBarsReferenceAndLabels) {
  IntervalPlotOptions o;
  o.plot.title = "later minus earlier";
  o.plot.x_label = "difference [m]";
  o.reference = 0.0;
  o.wide_sigmas = 3.0;
  const std::vector<IntervalRow> rows = {
      {"x: day1 \u2192 day2", 0.05, 0.002, "+0.05 \u00b1 0.002 m (25 \u03c3)", true},
      {"y: day1 \u2192 day2", 0.001, 0.002, "+0.001 \u00b1 0.002 m (0.5 \u03c3)", false},
      {"z: (none)", kNaN, 0.0, "n/a", false}};
  const std::string svg = SvgIntervalPlot(rows, o);
  ExpectValidSvg(svg);
  EXPECT_EQ(Count(svg, "<circle class=\"value\""), 2);
  EXPECT_EQ(Count(svg, "class=\"sigma\""), 2);
  EXPECT_EQ(Count(svg, "class=\"wide\""), 2);
  EXPECT_EQ(Count(svg, "stroke-dasharray=\"5 4\""), 1);  // the reference line
  EXPECT_NE(svg.find("x: day1 \u2192 day2"), std::string::npos);
  EXPECT_NE(svg.find("(25 \u03c3)"), std::string::npos);
  EXPECT_NE(svg.find(">z: (none)<"), std::string::npos);
  EXPECT_NE(svg.find("fill=\"" + PlotSeriesColour(1) + "\""), std::string::npos);
  EXPECT_NE(svg.find("fill=\"" + PlotSeriesColour(0) + "\""), std::string::npos);
  // The thin bar of row 2 (0.001 +- 0.006) reaches below zero, inside the frame.
  std::smatch reference;
  ASSERT_TRUE(std::regex_search(svg, reference,
                                std::regex("<line x1=\"([0-9.]+)\"[^>]*stroke-dasharray=\"5 4\"")));
  std::vector<double> wide;
  const std::regex wide_line("<line x1=\"([0-9.]+)\"[^>]*class=\"wide\"");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), wide_line);
       it != std::sregex_iterator(); ++it) {
    wide.push_back(std::stod((*it)[1]));
  }
  ASSERT_EQ(wide.size(), 2u);
  EXPECT_LT(wide[1], std::stod(reference[1]));
  EXPECT_GT(wide[1], 0.0);
  EXPECT_GT(wide[0], std::stod(reference[1]));  // row 1's reaches 0.044: clear of zero
  // The dots sit where their values are: x's to the right of y's.
  const std::vector<std::string> cx = Attribute(svg, "<circle class=\"value\"", "cx");
  ASSERT_EQ(cx.size(), 2u);
  EXPECT_GT(std::stod(cx[0]), std::stod(cx[1]));
  EXPECT_NE(SvgIntervalPlot({{"a", kNaN, 1.0, "", false}}, o).find("no data"), std::string::npos);
}

TEST(XmlProblem, DetectsMalformedMarkup) {
  EXPECT_EQ(XmlProblem("<svg><g></g></svg>"), "");
  EXPECT_NE(XmlProblem("<svg><g></svg>"), "");
  EXPECT_NE(XmlProblem("<svg><text>a & b</text></svg>"), "");
  EXPECT_NE(XmlProblem("<svg><text>a < b</text></svg>"), "");
}

}  // namespace
}  // namespace fastcal

namespace fastcal {
namespace {

// Labels of circles a few pixels apart (design.html's stops 12 and 13 at the rim) must not
// overlap; a lone circle's label goes to its right, clear of the circle.
TEST(PlaceCircleLabelsTest, NearbyCirclesGetLabelsThatDoNotOverlap) {
  constexpr double kCharPx = 7.0, kHeightPx = 11.0;
  const std::vector<CircleLabel> labels = {
      {100.0, 100.0, 8.0, "12"}, {104.0, 101.0, 4.0, "13"}, {103.0, 96.0, 6.0, "14"}};
  const std::vector<LabelSpot> spots = PlaceCircleLabels(labels, kCharPx, kHeightPx);
  ASSERT_EQ(spots.size(), labels.size());
  // The first takes the first spot: right of its circle, just above its centre.
  EXPECT_DOUBLE_EQ(spots[0].x_px, 100.0 + 8.0 + 2.0);
  EXPECT_DOUBLE_EQ(spots[0].baseline_px, 100.0 - 3.0);
  for (size_t a = 0; a < spots.size(); ++a) {
    for (size_t b = a + 1; b < spots.size(); ++b) {
      const double wa = kCharPx * labels[a].text.size(), wb = kCharPx * labels[b].text.size();
      const bool apart = spots[a].x_px + wa <= spots[b].x_px ||
                         spots[b].x_px + wb <= spots[a].x_px ||
                         spots[a].baseline_px <= spots[b].baseline_px - kHeightPx ||
                         spots[b].baseline_px <= spots[a].baseline_px - kHeightPx;
      EXPECT_TRUE(apart) << labels[a].text << " and " << labels[b].text << " overlap";
    }
  }
}

}  // namespace
}  // namespace fastcal
