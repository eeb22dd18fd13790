// The tensions along a trajectory as an HTML page (trajectory_plot.h): the paper's Figs. 9
// and 10 (lower-end tensions against the distance travelled, one curve per cable), and
// for two methods the first one's relative error, e_i = 100 (T_first / T_second - 1) %,
// whose maxima are its Tables 4 and 5. Built with the report's document model, so the
// page looks like report.html.
#include "fastcal/trajectory_plot.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "fastcal/internal/report_document.h"
#include "fastcal/internal/units.h"
#include "fastcal/svg_plot.h"

namespace fastcal {
namespace {

using internal::Document;
using internal::Int;
using internal::Printf;
using internal::Table;
using internal::Text;

using internal::kNPerKn;
constexpr double kPercent = 100.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kPlotWidthPx = 540, kPlotHeightPx = 340;
constexpr size_t kFailuresNamed = 5;

bool Ok(const StaticsSolution& s) { return s.status == StaticsStatus::kOk; }

// s_n: the distance travelled to pose n (m), or n itself.
std::vector<double> Abscissa(const TrajectoryPlotInputs& in) {
  const std::vector<Pose>& poses = *in.poses;
  std::vector<double> x(poses.size(), 0.0);
  for (size_t n = 1; n < poses.size(); ++n) {
    x[n] = in.along_path ? x[n - 1] + (poses[n].position_m - poses[n - 1].position_m).norm()
                         : static_cast<double>(n);
  }
  return x;
}

std::string XLabel(const TrajectoryPlotInputs& in) {
  return in.along_path ? "distance travelled [m]" : "node";
}

// One curve per cable, coloured by cable in every chart, cables 4-6 dashed (FAST's cables
// come in symmetric pairs, 1-6, 2-3, 4-5, whose curves often lie on each other); a failed
// pose is a gap.
std::vector<PlotSeries> CableSeries(const std::vector<double>& x,
                                    const std::vector<double>& value_of_pose_and_cable) {
  std::vector<PlotSeries> series(kNumCables);
  for (int i = 0; i < kNumCables; ++i) {
    series[i].name = "T" + std::to_string(i + 1);
    series[i].dashed = i >= kNumCables / 2;
    series[i].x = x;
    for (size_t n = 0; n < x.size(); ++n) {
      series[i].y.push_back(value_of_pose_and_cable[n * kNumCables + i]);
    }
  }
  return series;
}

std::vector<double> TensionsKn(const std::vector<StaticsSolution>& run) {
  std::vector<double> t(run.size() * kNumCables, kNaN);
  for (size_t n = 0; n < run.size(); ++n) {
    if (!Ok(run[n])) continue;
    for (int i = 0; i < kNumCables; ++i) {
      t[n * kNumCables + i] = run[n].cables[i].lower_tension_n / kNPerKn;
    }
  }
  return t;
}

// e_i(s) of the first run against the second, where both are ok.
std::vector<double> RelativeErrorPct(const std::vector<StaticsSolution>& first,
                                     const std::vector<StaticsSolution>& second) {
  std::vector<double> e(first.size() * kNumCables, kNaN);
  for (size_t n = 0; n < first.size(); ++n) {
    if (!Ok(first[n]) || !Ok(second[n])) continue;
    for (int i = 0; i < kNumCables; ++i) {
      e[n * kNumCables + i] =
          kPercent *
          (first[n].cables[i].lower_tension_n / second[n].cables[i].lower_tension_n - 1.0);
    }
  }
  return e;
}

// Per cable: the smallest and largest tension of each run, and the largest |e_i|.
Table ExtremesTable(const TrajectoryPlotInputs& in, const std::vector<double>& error_pct) {
  Table t;
  t.caption = "Per cable along the trajectory (lower-end tension, kN)";
  t.header = {"cable"};
  for (const TrajectoryRun& run : in.runs) {
    t.header.push_back("min, " + run.method);
    t.header.push_back("max, " + run.method);
  }
  if (!error_pct.empty()) {
    t.header.push_back("max |" + in.runs[0].method + " − " + in.runs[1].method + "| / " +
                       in.runs[1].method + " (%)");
  }
  t.right_align.assign(t.header.size(), true);
  t.right_align[0] = false;
  std::vector<std::vector<double>> tensions;
  for (const TrajectoryRun& run : in.runs) tensions.push_back(TensionsKn(*run.solutions));
  for (int i = 0; i < kNumCables; ++i) {
    std::vector<Text> row = {Text().Swatch(PlotSeriesColour(i)).Plain("T" + Int(i + 1))};
    auto extreme = [i](const std::vector<double>& v, bool largest) {
      double out = kNaN;
      for (size_t k = i; k < v.size(); k += kNumCables) {
        if (!std::isfinite(v[k])) continue;
        if (!std::isfinite(out) || (largest ? v[k] > out : v[k] < out)) out = v[k];
      }
      return out;
    };
    for (const std::vector<double>& v : tensions) {
      row.push_back(Printf("%.3f", extreme(v, false)));
      row.push_back(Printf("%.3f", extreme(v, true)));
    }
    if (!error_pct.empty()) {
      std::vector<double> magnitude(error_pct.size());
      std::transform(error_pct.begin(), error_pct.end(), magnitude.begin(),
                     [](double e) { return std::abs(e); });
      row.push_back(Printf("%.4f", extreme(magnitude, true)));
    }
    t.rows.push_back(row);
  }
  return t;
}

// What failed, in words: how many poses and the first few, by node and status.
void AddFailures(const TrajectoryPlotInputs& in, Document* doc) {
  std::vector<std::string> named;
  size_t failed = 0;
  for (size_t n = 0; n < in.poses->size(); ++n) {
    for (const TrajectoryRun& run : in.runs) {
      const StaticsSolution& s = (*run.solutions)[n];
      if (Ok(s)) continue;
      if (named.size() < kFailuresNamed) {
        named.push_back("node " + Int(static_cast<long long>(n)) + " (" + run.method + ": " +
                        StaticsStatusName(s.status) + ")");
      }
      ++failed;
      break;
    }
  }
  if (failed == 0) return;
  std::string list;
  for (const std::string& f : named) list += (list.empty() ? "" : ", ") + f;
  doc->Banner(
      internal::Tone::kCaution,
      Text()
          .Bold(Int(static_cast<long long>(failed)) + " of " +
                Int(static_cast<long long>(in.poses->size())) + " poses failed")
          .Plain(" and are gaps in the curves: " + list + (failed > named.size() ? ", ..." : "") +
                 ". The CSV's status and message columns say why."));
}

bool Fits(const TrajectoryPlotInputs& in) {
  if (in.poses == nullptr || in.poses->empty() || in.runs.empty() || in.runs.size() > 2) {
    return false;
  }
  return std::all_of(in.runs.begin(), in.runs.end(), [&in](const TrajectoryRun& r) {
    return r.solutions != nullptr && r.solutions->size() == in.poses->size();
  });
}

}  // namespace

std::string TrajectoryPlotHtml(const TrajectoryPlotInputs& in) {
  if (!Fits(in)) return "";
  Document doc;
  doc.title = in.title;
  doc.Heading(1, in.title);
  doc.Pre("", in.provenance, false);
  const std::vector<double> x = Abscissa(in);
  doc.Paragraph(Int(static_cast<long long>(in.poses->size())) + " poses" +
                (in.along_path ? ", " + Printf("%.4g", x.back()) + " m of path" : "") +
                ". Lower-end tensions: what the cabin-side sensors read (solve's T<i>_kN).");
  AddFailures(in, &doc);
  std::vector<std::string> charts;
  for (size_t r = 0; r < in.runs.size(); ++r) {
    PlotOptions o;
    o.title = (in.runs.size() == 2 ? std::string(r == 0 ? "(a) " : "(b) ") : std::string()) +
              "Lower-end tensions, " + in.runs[r].method;
    o.x_label = XLabel(in);
    o.y_label = "T [kN]";
    o.width_px = kPlotWidthPx;
    o.height_px = kPlotHeightPx;
    charts.push_back(SvgLinePlot(CableSeries(x, TensionsKn(*in.runs[r].solutions)), o));
  }
  doc.Figure(charts, in.runs.size() == 2
                         ? Text("The six cables' tensions by each method, as the paper's Figs. 9 "
                                "and 10 (there: the straight line G1 → G2 and the half circle).")
                         : Text("The six cables' tensions along the trajectory, as the paper's "
                                "Figs. 9 and 10."));
  std::vector<double> error_pct;
  if (in.runs.size() == 2) {
    error_pct = RelativeErrorPct(*in.runs[0].solutions, *in.runs[1].solutions);
    PlotOptions o;
    o.title = "Relative error of " + in.runs[0].method + " against " + in.runs[1].method;
    o.x_label = XLabel(in);
    o.y_label =
        "(" + in.runs[0].method + " − " + in.runs[1].method + ") / " + in.runs[1].method + " [%]";
    o.width_px = kPlotWidthPx;
    o.height_px = kPlotHeightPx;
    doc.Figure({SvgLinePlot(CableSeries(x, error_pct), o)},
               Text("Per cable along the path; its largest magnitudes, in the table below, are "
                    "the paper's Tables 4 and 5."));
  }
  doc.AddTable(ExtremesTable(in, error_pct));
  return internal::RenderHtmlPage(doc);
}

}  // namespace fastcal
