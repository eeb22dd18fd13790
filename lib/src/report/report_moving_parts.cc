// The report's section on the cabin's moving parts (moving_parts.h): the calibrated first
// moments and masses with sigma_total, what they mean to an engineer (how far a rotating
// assembly's centre sits from its axes, per 10 t of its mass; the largest shift of the
// whole cabin's mass centre over the joints' ranges), and a plot of the mass centre's shift
// as each revolute joint sweeps its range:
//   c(q) - c0 = sum_k [ (R_k(q) - I) Q_k + (t_k(q) - t_k(0)) m_k ] / M.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "fastcal/internal/report_sections.h"

namespace fastcal::internal {
namespace {

constexpr int kSweepPoints = 61;
// A joint without a range in the model or the data is swept over this (deg or m).
constexpr double kDefaultSweepDeg = 15.0, kDefaultSweepM = 0.05;
// The mass a rotating assembly's distance from its axes is quoted for.
constexpr double kQuotedMassKg = 10000.0;

const ParameterEstimate* Find(const CalibrationResult& r, const std::string& name) {
  for (const ParameterEstimate& p : r.parameters) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

// Each joint's sweep: the model's range, else the data's, else the defaults.
std::vector<std::pair<double, double>> JointSpans(const CableRobot& m, const Dataset* data) {
  std::vector<std::pair<double, double>> spans;
  const auto joints = m.moving_parts.Joints();
  for (size_t j = 0; j < joints.size(); ++j) {
    const Joint& joint = *joints[j].second;
    if (joint.has_range) {
      spans.emplace_back(joint.range_low, joint.range_high);
      continue;
    }
    double lo = 0.0, hi = 0.0;
    if (data != nullptr && data->joint_columns.size() == joints.size()) {
      for (const Sample& s : data->samples) {
        lo = std::min(lo, s.joint[j]);
        hi = std::max(hi, s.joint[j]);
      }
    }
    if (!(hi > lo)) {
      const double d = joint.type == JointType::kRevolute ? kDefaultSweepDeg : kDefaultSweepM;
      lo = -d;
      hi = d;
    }
    spans.emplace_back(lo, hi);
  }
  return spans;
}

// The largest |c(q) - c0| over the corners, zeros and mid-points of the joints' spans
// (3^n points, n <= kMaxJoints: at most 6561).
double LargestShiftM(const CableRobot& m, const std::vector<std::pair<double, double>>& spans) {
  const int n = static_cast<int>(spans.size());
  int total = 1;
  for (int j = 0; j < n; ++j) total *= 3;
  double largest = 0.0;
  for (int code = 0; code < total; ++code) {
    JointValues q{};
    for (int j = 0, c = code; j < n; ++j, c /= 3) {
      q[j] = c % 3 == 0 ? spans[j].first : c % 3 == 1 ? 0.0 : spans[j].second;
    }
    largest = std::max(largest, (m.MassCentreAt(q) - m.mass_centre_cabin_m).norm());
  }
  return largest;
}

// The shift's x, y, z (mm) as joint j sweeps its span, the others at zero.
std::string SweepPlot(const CableRobot& m, int j, const Joint& joint,
                      const std::pair<double, double>& span) {
  std::vector<PlotSeries> series(3);
  const char* axes[] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) series[a].name = std::string("c_") + axes[a] + " - c0_" + axes[a];
  for (int k = 0; k < kSweepPoints; ++k) {
    JointValues q{};
    q[j] = span.first + (span.second - span.first) * k / (kSweepPoints - 1);
    const Eigen::Vector3d shift = m.MassCentreAt(q) - m.mass_centre_cabin_m;
    for (int a = 0; a < 3; ++a) {
      series[a].x.push_back(q[j]);
      series[a].y.push_back(1e3 * shift[a]);
    }
  }
  PlotOptions o;
  o.title = "Mass centre against " + joint.column;
  o.x_label = joint.column + (joint.type == JointType::kRevolute ? " [deg]" : " [m]");
  o.y_label = "shift, cabin frame [mm]";
  o.width_px = 520;
  o.height_px = 260;
  return SvgLinePlot(series, o);
}

// "moving_parts.rotator.first_moment_kg_m: (x, y, z) ± (...)" and what it means.
Text PartText(const CalibrationResult& r, const MovingPart& part) {
  const std::string stem = "moving_parts." + part.name + ".";
  Text t;
  t.Code(part.name);
  std::string moment, sigma;
  bool any_free = false;
  const Eigen::Vector3d q = part.first_moment_kg_m;
  for (int a = 0; a < 3; ++a) {
    const ParameterEstimate* p = Find(r, stem + "first_moment_kg_m." + std::string(1, "xyz"[a]));
    const bool free = p != nullptr && p->free;
    any_free = any_free || free;
    moment += (a ? ", " : "") + Printf("%.0f", q[a]);
    sigma += (a ? ", " : "") + (free ? Printf("%.0f", p->sigma_total) : std::string("fixed"));
  }
  // |Q| without its components along the part's revolute axes.
  Eigen::Vector3d off = q;
  for (const Joint& j : part.joints) {
    if (j.type == JointType::kRevolute) off -= j.axis * j.axis.dot(off);
  }
  // Issue 59: the components only their prior holds, marked as docs/calibration.md says.
  const auto prior_set = [](const ParameterEstimate* p) {
    return p != nullptr && p->free && p->note.find("set mostly by its prior") != std::string::npos;
  };
  std::string held;
  for (int a = 0; a < 3; ++a) {
    if (prior_set(Find(r, stem + "first_moment_kg_m." + std::string(1, "xyz"[a])))) {
      held += std::string(held.empty() ? "" : ", ") + "xyz"[a];
    }
  }
  std::vector<std::string> phrases;
  if (any_free || q.norm() > 0.0) {
    phrases.push_back("first moment (" + moment + ") kg m, sigma_total (" + sigma + ") kg m" +
                      (held.empty() ? "" : " (" + held + " set mostly by the prior)"));
  }
  if (q.norm() > 0.0 && !part.joints.empty() && part.joints.front().type == JointType::kRevolute) {
    // d = |Q| / m: the distance of the assembly's centre from its axes' origin, for a mass.
    phrases.push_back("a " + Printf("%.0f", kQuotedMassKg / 1e3) +
                      " t rotating assembly has its centre " +
                      Printf("%.3g", q.norm() / kQuotedMassKg) + " m from its axes' origin (" +
                      Printf("%.3g", off.norm() / kQuotedMassKg) +
                      " m of it across its axes, the part the data see at first order; twice "
                      "the mass, half the distance)");
  }
  if (const ParameterEstimate* p = Find(r, stem + "mass_kg")) {
    phrases.push_back("mass " + Printf("%.0f", p->estimate) + " kg" +
                      (p->free ? " ± " + Printf("%.0f", p->sigma_total) + " kg" : " (fixed)") +
                      (prior_set(p) ? " (set mostly by the prior)" : ""));
  }
  for (size_t k = 0; k < phrases.size(); ++k) t.Plain((k ? "; " : ": ") + phrases[k]);
  return t;
}

}  // namespace

void AddMovingParts(const ReportInputs& in, bool with_plots, Document* doc) {
  if (in.result == nullptr || in.result->calibrated.moving_parts.empty()) return;
  const CalibrationResult& r = *in.result;
  const CableRobot& m = r.calibrated;
  doc->Heading(2, "Moving parts");
  doc->Paragraph(
      "The cabin's mass centre follows its moving parts' joints: c(q) = c0 + sum_k [(R_k(q) - "
      "I) Q_k + (t_k(q) - t_k(0)) m_k] / M (docs/model.md, \"Moving parts\"), c0 the mass centre "
      "with every joint at zero. A first moment's component along its part's own rotation axis "
      "is seen only at second order in the angles: where the survey turns the part little, its "
      "estimate leans on its prior. A component set mostly by its prior (its posterior σ over "
      "half the prior's, as Estimates marks any parameter) is marked below.");
  std::vector<Text> items;
  for (const MovingPart& part : m.moving_parts.parts) items.push_back(PartText(r, part));
  doc->List(items);
  const auto spans = JointSpans(m, in.data);
  doc->Paragraph("Over the joints' ranges (the model's, else the data's) the whole cabin's mass "
                 "centre moves by up to " +
                 Printf("%.3g", 1e3 * LargestShiftM(m, spans)) + " mm from c0.");
  if (!with_plots) return;
  std::vector<std::string> svgs;
  const auto joints = m.moving_parts.Joints();
  for (size_t j = 0; j < joints.size(); ++j) {
    svgs.push_back(SweepPlot(m, static_cast<int>(j), *joints[j].second, spans[j]));
  }
  doc->Figure(svgs, Text("The calibrated model's mass centre minus c0 (cabin frame, mm), each "
                         "joint swept over its range with the others at 0."));
}

}  // namespace fastcal::internal
