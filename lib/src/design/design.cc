// Survey design (design.h): the approximate design by Frank-Wolfe, rounding to N
// samples, Fedorov exchange, the time budget, the flight path and the predictions.
#include "fastcal/design.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "fastcal/internal/design_information.h"
#include "fastcal/internal/design_range.h"
#include "fastcal/survey_path.h"

namespace fastcal {
namespace {

using internal::DesignProblem;
using internal::DesignSums;

// A swap or step must lower the criterion by this fraction of it to count: rounding
// cannot make the exchange cycle.
constexpr double kRelativeImprovement = 1e-10;
// Frank-Wolfe stops when its duality gap is below this fraction of the criterion.
constexpr double kRelativeGap = 1e-6;
// Golden-section steps of the Frank-Wolfe line search (step known to 1e-6 of [0, 1]).
constexpr int kLineSearchSteps = 30;
// The exchange's sums are updated per swap and summed afresh every this many swaps.
constexpr int kResumEvery = 64;

std::string Num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

// Minutes for a person: "11.6 min", not "11.6164 min" (issue 39).
std::string Minutes(double seconds) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g min", seconds / 60.0);
  return b;
}

DesignSums Combine(const DesignSums& a, double wa, const DesignSums& b, double wb) {
  return {wa * a.m + wb * b.m, wa * a.c + wb * b.c};
}

Eigen::VectorXd ToWeights(const std::vector<int>& counts) {
  Eigen::VectorXd w(counts.size());
  for (size_t i = 0; i < counts.size(); ++i) w[i] = counts[i];
  return w;
}

// Indices of the `count` smallest (or largest) values among `allowed`, ties to the lower
// index.
std::vector<int> Extremes(const Eigen::VectorXd& v, const std::vector<int>& allowed, int count,
                          bool smallest) {
  std::vector<int> idx = allowed;
  const int keep = std::min<int>(count, static_cast<int>(idx.size()));
  std::partial_sort(idx.begin(), idx.begin() + keep, idx.end(), [&](int a, int b) {
    if (v[a] != v[b]) return smallest ? v[a] < v[b] : v[a] > v[b];
    return a < b;
  });
  idx.resize(keep);
  return idx;
}

// Stage: the approximate design (weights summing to N) by Frank-Wolfe with a line search.
Eigen::VectorXd ApproximateDesign(const DesignProblem& pr, int samples, int iterations) {
  const int k = pr.candidates();
  Eigen::VectorXd w = Eigen::VectorXd::Constant(k, static_cast<double>(samples) / k);
  DesignSums s = internal::SumsOf(pr, w);
  double f = internal::CriterionOf(pr, s);
  for (int it = 0; it < iterations && std::isfinite(f); ++it) {
    Eigen::VectorXd g;
    if (!internal::CriterionGradient(pr, s, &g)) break;
    Eigen::Index j = 0;
    g.minCoeff(&j);
    const double gap = w.dot(g) - samples * g[j];
    if (!(gap > kRelativeGap * std::abs(f))) break;
    const DesignSums vertex = internal::SumsOfCandidate(pr, static_cast<int>(j));
    auto at = [&](double a) {
      return internal::CriterionOf(pr, Combine(s, 1.0 - a, vertex, a * samples));
    };
    double lo = 0.0, hi = 1.0;
    const double r = (std::sqrt(5.0) - 1.0) / 2.0;
    for (int step = 0; step < kLineSearchSteps; ++step) {
      const double a = hi - r * (hi - lo), b = lo + r * (hi - lo);
      if (at(a) < at(b)) {
        hi = b;
      } else {
        lo = a;
      }
    }
    const double alpha = 0.5 * (lo + hi);
    const double f_new = at(alpha);
    if (!(f_new < f)) break;
    w *= 1.0 - alpha;
    w[j] += alpha * samples;
    s = Combine(s, 1.0 - alpha, vertex, alpha * samples);
    f = f_new;
  }
  return w;
}

// Stage: N samples from the weights (largest remainders).
std::vector<int> RoundToSamples(const Eigen::VectorXd& w, int samples) {
  const int k = static_cast<int>(w.size());
  const double total = w.sum();
  std::vector<int> counts(k);
  std::vector<double> rest(k);
  int used = 0;
  for (int i = 0; i < k; ++i) {
    const double target = total > 0.0 ? w[i] * samples / total : 0.0;
    counts[i] = static_cast<int>(std::floor(target));
    rest[i] = target - counts[i];
    used += counts[i];
  }
  std::vector<int> order(k);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return rest[a] > rest[b]; });
  for (int i = 0; used < samples; ++i, ++used) ++counts[order[i % k]];
  return counts;
}

// Stage: Fedorov exchange of single samples, additions among `allowed` candidates.
void Exchange(const DesignProblem& pr, const std::vector<int>& allowed, int width, int iterations,
              std::vector<int>* counts) {
  DesignSums s = internal::SumsOf(pr, ToWeights(*counts));
  double f = internal::CriterionOf(pr, s);
  for (int it = 0; it < iterations; ++it) {
    Eigen::VectorXd g;
    if (!internal::CriterionGradient(pr, s, &g)) return;
    std::vector<int> support;
    for (int i = 0; i < pr.candidates(); ++i) {
      if ((*counts)[i] > 0) support.push_back(i);
    }
    const std::vector<int> add = Extremes(g, allowed, width, true);
    const std::vector<int> remove = Extremes(g, support, width, false);
    double best = f;
    int best_add = -1, best_remove = -1;
    for (int a : add) {
      const DesignSums plus = Combine(s, 1.0, internal::SumsOfCandidate(pr, a), 1.0);
      for (int r : remove) {
        if (a == r) continue;
        const double fs =
            internal::CriterionOf(pr, Combine(plus, 1.0, internal::SumsOfCandidate(pr, r), -1.0));
        if (fs < best) {
          best = fs;
          best_add = a;
          best_remove = r;
        }
      }
    }
    if (best_add < 0 || !(best < f - kRelativeImprovement * std::abs(f))) return;
    ++(*counts)[best_add];
    --(*counts)[best_remove];
    s = Combine(Combine(s, 1.0, internal::SumsOfCandidate(pr, best_add), 1.0), 1.0,
                internal::SumsOfCandidate(pr, best_remove), -1.0);
    // Afresh now and then: no drift from many updates.
    if (it % kResumEvery == kResumEvery - 1) s = internal::SumsOf(pr, ToWeights(*counts));
    f = best;
  }
}

std::vector<int> SupportOf(const std::vector<int>& counts) {
  std::vector<int> support;
  for (size_t i = 0; i < counts.size(); ++i) {
    if (counts[i] > 0) support.push_back(static_cast<int>(i));
  }
  return support;
}

// Stage: the stops in flight order, the path's length and its time.
void FlyStops(const std::vector<DesignCandidate>& candidates, const std::vector<int>& counts,
              const DesignOptions& o, Design* d) {
  const std::vector<int> support = SupportOf(counts);
  std::vector<Eigen::Vector3d> points;
  for (int i : support) points.push_back(candidates[i].pose.position_m);
  // Start nearest the bottom of the cap (the cabin's usual parking place).
  const FocalGridSpec& grid = o.workspace.grid;
  const Eigen::Vector3d bottom =
      grid.focal_centre_m - grid.focal_radius_m * Eigen::Vector3d::UnitZ();
  int start = 0;
  for (size_t k = 0; k < points.size(); ++k) {
    if ((points[k] - bottom).norm() < (points[start] - bottom).norm()) start = static_cast<int>(k);
  }
  const std::vector<int> order = ShortPathOrder(points, start);
  d->path_length_m = PathLength(points, order);
  d->stops.clear();
  d->poses.clear();
  d->data_poses.clear();
  d->joints.clear();
  for (int k : order) {
    const DesignCandidate& c = candidates[support[k]];
    d->stops.push_back({support[k], counts[support[k]], {}, {}});
    for (int s = 0; s < counts[support[k]]; ++s) {
      d->poses.push_back(c.pose);
      d->data_poses.push_back(c.data_pose);
      if (!d->joint_columns.empty()) d->joints.push_back(c.joints);
    }
  }
  d->dwell_s = o.samples * o.sample_interval_s;
  d->travel_s = o.speed_m_per_s > 0.0 ? d->path_length_m / o.speed_m_per_s : 0.0;
  d->duration_s = o.speed_m_per_s > 0.0 ? d->travel_s + d->dwell_s : 0.0;
}

// Stage: drop the stop whose samples are missed least (moved to the others in
// proportion), round, and rebalance within the remaining stops. False when every removal
// leaves the parameters undetermined.
bool DropOneStop(const DesignProblem& pr, const DesignOptions& o, std::vector<int>* counts) {
  const std::vector<int> support = SupportOf(*counts);
  if (support.size() <= 1) return false;
  const DesignSums s = internal::SumsOf(pr, ToWeights(*counts));
  double best = std::numeric_limits<double>::infinity();
  int drop = -1;
  for (int i : support) {
    const int ni = (*counts)[i];
    // Its samples spread over the others: the remaining sums scaled up to N.
    const double scale = static_cast<double>(o.samples) / (o.samples - ni);
    const double f =
        internal::CriterionOf(pr, Combine(s, scale, internal::SumsOfCandidate(pr, i), -ni * scale));
    if (f < best) {
      best = f;
      drop = i;
    }
  }
  if (drop < 0) return false;
  Eigen::VectorXd w = ToWeights(*counts);
  w[drop] = 0.0;
  *counts = RoundToSamples(w, o.samples);
  std::vector<int> kept = SupportOf(*counts);
  Exchange(pr, kept, o.exchange_width, o.exchange_iterations, counts);
  return true;
}

// Stage: keep within the time budget (fewer stops, more dwell at each).
bool KeepWithinBudget(const DesignProblem& pr, const std::vector<DesignCandidate>& candidates,
                      const DesignOptions& o, std::vector<int>* counts, Design* d,
                      std::string* error) {
  FlyStops(candidates, *counts, o, d);
  d->unconstrained_stops = static_cast<int>(d->stops.size());
  if (o.time_budget_s <= 0.0) return true;
  if (d->dwell_s > o.time_budget_s) {
    *error = "infeasible time budget: " + std::to_string(o.samples) + " samples at " +
             Num(o.sample_interval_s) + " s each take " + Minutes(d->dwell_s) +
             " before the cabin moves at all, more than the " + Minutes(o.time_budget_s) +
             " allowed; ask for fewer samples or more time";
    return false;
  }
  while (d->duration_s > o.time_budget_s) {
    if (!DropOneStop(pr, o, counts)) {
      *error = "infeasible time budget: the fewest stops that still determine the parameters (" +
               std::to_string(d->stops.size()) + ") take " + Minutes(d->duration_s) + " at " +
               Num(o.speed_m_per_s) + " m/s, more than the " + Minutes(o.time_budget_s) +
               " allowed";
      return false;
    }
    FlyStops(candidates, *counts, o, d);
  }
  return true;
}

}  // namespace

const char* DesignCriterionName(DesignCriterion criterion) {
  return criterion == DesignCriterion::kA ? "A" : "D";
}

SlowErrorProcess PredictionSlowError(const CalibrationSpec& spec, const DesignOptions& options) {
  const SlowErrorSpec& slow = spec.slow_error;
  if (!slow.enabled) return SlowErrorProcess();
  SlowErrorProcess p = slow.stated;
  if (slow.estimate_amplitude) {
    p.sigma_percent = slow.amplitude_in_percent ? options.slow_error_percent : 0.0;
    p.sigma_n = slow.amplitude_in_percent ? 0.0 : options.slow_error_kn * 1e3;
  }
  if (slow.estimate_time_constant) p.time_constant_s = options.slow_error_time_s;
  return p;
}

bool DesignOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& message) {
    if (error != nullptr) *error = message;
    return false;
  };
  std::string why;
  if (!workspace.IsValid(&why)) return fail("workspace." + why);
  if (!(max_extra_tilt_deg >= 0.0 && max_extra_tilt_deg <= 30.0)) {
    return fail("max_extra_tilt_deg must be in [0, 30] (got " + Num(max_extra_tilt_deg) + ")");
  }
  if (!(max_extra_yaw_deg >= 0.0 && max_extra_yaw_deg <= 90.0)) {
    return fail("max_extra_yaw_deg must be in [0, 90] (got " + Num(max_extra_yaw_deg) + ")");
  }
  if (tilt_directions < 1 || tilt_directions > 36) {
    return fail("tilt_directions must be in [1, 36] (got " + std::to_string(tilt_directions) + ")");
  }
  for (const auto& [name, value] :
       {std::pair<const char*, double>{"range_prior_sigmas", range_prior_sigmas},
        {"range_mass_centre_m", range_mass_centre_m},
        {"range_offset_m", range_offset_m},
        {"range_relative", range_relative}}) {
    if (!(value >= 0.0) || !std::isfinite(value)) {
      return fail(std::string(name) + " must be >= 0 and finite (got " + Num(value) + ")");
    }
  }
  if (!(range_relative < 1.0)) {
    return fail("range_relative must be below 1 (got " + Num(range_relative) + ")");
  }
  if (!(hold_probability >= 0.0 && hold_probability < 0.5)) {
    return fail("hold_probability must be in [0, 0.5) (got " + Num(hold_probability) + ")");
  }
  for (const auto& [name, value] :
       {std::pair<const char*, double>{"slow_error_percent", slow_error_percent},
        {"slow_error_kn", slow_error_kn},
        {"slow_error_time_s", slow_error_time_s}}) {
    if (!(value >= 0.0) || !std::isfinite(value) || value > 1e8) {
      return fail(std::string(name) + " must be >= 0 and finite (got " + Num(value) + ")");
    }
  }
  // Each grid value a candidate of its own per pose: 9 values give 81 per pose already.
  constexpr size_t kMaxJointGridValues = 9;
  if (joint_grid_deg.size() > kMaxJointGridValues) {
    return fail("joint_grid_deg: at most " + std::to_string(kMaxJointGridValues) + " values (got " +
                std::to_string(joint_grid_deg.size()) + ")");
  }
  for (double v : joint_grid_deg) {
    if (!std::isfinite(v) || std::abs(v) > 180.0) {
      return fail("joint_grid_deg: values must be finite angles within +-180 deg (got " + Num(v) +
                  ")");
    }
  }
  if (samples < 1 || samples > 1000000) {
    return fail("samples must be in [1, 1e6] (got " + std::to_string(samples) + ")");
  }
  if (approximate_iterations < 0 || exchange_iterations < 0 || exchange_width < 1) {
    return fail("approximate_iterations and exchange_iterations must be >= 0, exchange_width >= 1");
  }
  if (!(speed_m_per_s >= 0.0) || !std::isfinite(speed_m_per_s)) {
    return fail("speed_m_per_s must be >= 0 and finite (got " + Num(speed_m_per_s) + ")");
  }
  if (!(sample_interval_s > 0.0) || !std::isfinite(sample_interval_s)) {
    return fail("sample_interval_s must be > 0 and finite (got " + Num(sample_interval_s) + ")");
  }
  if (!(time_budget_s >= 0.0) || !std::isfinite(time_budget_s)) {
    return fail("time_budget_s must be >= 0 and finite (got " + Num(time_budget_s) + ")");
  }
  if (time_budget_s > 0.0 && speed_m_per_s <= 0.0) {
    return fail("time_budget_s needs speed_m_per_s > 0 (the time to fly between stops)");
  }
  if (!circle_centre_m.allFinite() || !(circle_radius_m > 0.0) || !std::isfinite(circle_radius_m)) {
    return fail("circle_centre_m must be finite and circle_radius_m > 0");
  }
  if (settle_after_moves && !settle.IsValid(error)) return false;
  return true;
}

namespace {

// Stage: the wanted parameters (indices into the free ones) and the A-criterion's weights.
bool ChooseWanted(const CalibrationSpec& spec, const DesignOptions& o, DesignProblem* pr,
                  std::string* error) {
  pr->wanted.clear();
  if (!o.wanted.empty()) {
    for (const std::string& name : o.wanted) {
      int found = -1;
      for (int k = 0; k < pr->n; ++k) {
        if (spec.parameters[pr->free_spec[k]].name == name) found = k;
      }
      if (found < 0) {
        std::string names;
        for (int k = 0; k < pr->n; ++k) {
          names += (k ? ", " : "") + spec.parameters[pr->free_spec[k]].name;
        }
        *error = "wanted parameter '" + name +
                 "' is not a free parameter of the spec (free: " + names + ")";
        return false;
      }
      if (std::find(pr->wanted.begin(), pr->wanted.end(), found) == pr->wanted.end()) {
        pr->wanted.push_back(found);
      }
    }
  } else {
    for (int k = 0; k < pr->n; ++k) {
      if (!spec.parameters[pr->free_spec[k]].has_prior) pr->wanted.push_back(k);
    }
    if (pr->wanted.empty()) {
      for (int k = 0; k < pr->n; ++k) pr->wanted.push_back(k);
    }
  }
  pr->criterion = o.criterion;
  pr->wanted_weight = Eigen::VectorXd::Zero(pr->n);
  for (int k : pr->wanted) pr->wanted_weight[k] = 1.0;
  return true;
}

// With wanted parameters of different units, the A-criterion sums variances relative to
// their values in a reference design (every candidate equally): unit-free.
void NormaliseWeights(const CalibrationSpec& spec, int samples, DesignProblem* pr) {
  bool same_unit = true;
  for (int k : pr->wanted) {
    same_unit &= spec.parameters[pr->free_spec[k]].unit ==
                 spec.parameters[pr->free_spec[pr->wanted[0]]].unit;
  }
  if (same_unit || pr->criterion != DesignCriterion::kA) return;
  const Eigen::VectorXd w =
      Eigen::VectorXd::Constant(pr->candidates(), static_cast<double>(samples) / pr->candidates());
  internal::DesignCovariance cov;
  if (!internal::CovarianceOf(*pr, internal::SumsOf(*pr, w), &cov)) return;
  for (int k : pr->wanted) pr->wanted_weight[k] = 1.0 / cov.total(k, k);
}

// The prediction of the sums: the calibration's budget (white residuals at the stated
// noise) and its parts.
DesignPrediction Predict(const DesignProblem& pr, const DesignSums& s, int samples) {
  DesignPrediction out;
  out.samples = samples;
  out.criterion = internal::CriterionOf(pr, s);
  internal::DesignCovariance cov;
  if (!internal::CovarianceOf(pr, s, &cov)) {
    out.note = "the parameters are not determined by this survey";
    return out;
  }
  BudgetInputs in;
  in.information = s.m;
  in.information.diagonal() += pr.prior_information;
  in.prior_information = pr.prior_information;
  int priors = 0;
  for (int k = 0; k < pr.n; ++k) priors += pr.prior_information[k] > 0.0;
  in.num_residuals = pr.rows * samples + priors;
  in.chi_square = in.num_residuals - pr.n;  // chi^2 / nu = 1: no misfit widening
  in.consider_cross = s.c;
  in.consider_sigma = pr.consider_variance.cwiseSqrt();
  in.consider_group = pr.consider_group;
  in.consider_groups = pr.consider_groups;
  out.ok = ComputeUncertaintyBudget(in, &out.budget);
  if (!out.ok) {
    out.note = "the parameters are not determined by this survey";
    return out;
  }
  const Eigen::MatrixXd& k = cov.k;
  out.noise_variance.resize(pr.n);
  const Eigen::MatrixXd noise = k * s.m * k;
  for (int j = 0; j < pr.n; ++j) out.noise_variance[j] = noise(j, j);
  return out;
}

}  // namespace

namespace {

// Stage: the budget's parts per free parameter: each prior group's K Lambda_g K and each
// consider group's systematic variance (the noise part is Predict's).
void AddParts(const CalibrationSpec& spec, const DesignProblem& pr, const DesignSums& s,
              DesignPrediction* out) {
  if (!out->ok) return;
  internal::DesignCovariance cov;
  internal::CovarianceOf(pr, s, &cov);
  std::vector<std::string> groups;
  std::vector<int> group_of(pr.n, -1);
  for (int j = 0; j < pr.n; ++j) {
    if (pr.prior_information[j] <= 0.0) continue;
    const std::string g = ParameterGroupName(spec.parameters[pr.free_spec[j]].kind);
    auto it = std::find(groups.begin(), groups.end(), g);
    group_of[j] = static_cast<int>(it - groups.begin());
    if (it == groups.end()) groups.push_back(g);
  }
  for (size_t g = 0; g < groups.size(); ++g) {
    Eigen::VectorXd lambda = Eigen::VectorXd::Zero(pr.n);
    for (int j = 0; j < pr.n; ++j) {
      if (group_of[j] == static_cast<int>(g)) lambda[j] = pr.prior_information[j];
    }
    const Eigen::MatrixXd part = cov.k * lambda.asDiagonal() * cov.k;
    out->parts.push_back(groups[g] + " (prior)");
    std::vector<double> v(pr.n);
    for (int j = 0; j < pr.n; ++j) v[j] = part(j, j);
    out->part_variance.push_back(v);
  }
  for (size_t g = 0; g < pr.consider_groups.size(); ++g) {
    out->parts.push_back(pr.consider_groups[g] + " (consider)");
    std::vector<double> v(pr.n);
    for (int j = 0; j < pr.n; ++j) {
      const double sg = out->budget.parameters[j].systematic_by_group[g];
      v[j] = sg * sg;
    }
    out->part_variance.push_back(v);
  }
}

DesignPrediction PredictWithParts(const CalibrationSpec& spec, const DesignProblem& pr,
                                  const DesignSums& s, int samples) {
  DesignPrediction p = Predict(pr, s, samples);
  AddParts(spec, pr, s, &p);
  return p;
}

// Stage: what limits the design (the largest part of the wanted variances) and what
// halving each prior or consider group's sigma would buy.
void ExplainLimits(const CalibrationSpec& spec, const DesignProblem& pr, const DesignSums& s,
                   Design* d) {
  const DesignPrediction& p = d->design;
  if (!p.ok) return;
  double total = 0.0, noise = 0.0;
  for (int j : pr.wanted) {
    total += p.noise_variance[j];
    noise += p.noise_variance[j];
    for (const auto& part : p.part_variance) total += part[j];
  }
  d->limiting_part = "noise";
  double largest = noise;
  for (size_t g = 0; g < p.parts.size(); ++g) {
    double v = 0.0;
    for (int j : pr.wanted) v += p.part_variance[g][j];
    if (v > largest) {
      largest = v;
      d->limiting_part = p.parts[g];
    }
  }
  d->limiting_share = total > 0.0 ? largest / total : 0.0;
  // Halve one group's sigma at a time: 4x its prior information, or 1/4 its variance.
  auto effect = [&](const std::string& group, bool consider, const DesignProblem& changed) {
    DesignPriorEffect e;
    e.group = group;
    e.consider = consider;
    internal::DesignCovariance cov;
    if (!internal::CovarianceOf(changed, s, &cov)) return;
    for (int j : pr.wanted) e.sigma_total.push_back(std::sqrt(cov.total(j, j)));
    d->prior_effects.push_back(e);
  };
  std::vector<std::string> seen;
  for (int j = 0; j < pr.n; ++j) {
    if (pr.prior_information[j] <= 0.0) continue;
    const std::string g = ParameterGroupName(spec.parameters[pr.free_spec[j]].kind);
    if (std::find(seen.begin(), seen.end(), g) != seen.end()) continue;
    seen.push_back(g);
    DesignProblem changed = pr;
    for (int i = 0; i < pr.n; ++i) {
      if (pr.prior_information[i] > 0.0 &&
          ParameterGroupName(spec.parameters[pr.free_spec[i]].kind) == g) {
        changed.prior_information[i] *= 4.0;
      }
    }
    effect(g, false, changed);
  }
  for (size_t g = 0; g < pr.consider_groups.size(); ++g) {
    DesignProblem changed = pr;
    for (int c = 0; c < pr.q; ++c) {
      if (pr.consider_group[c] == static_cast<int>(g)) changed.consider_variance[c] *= 0.25;
    }
    effect(pr.consider_groups[g], true, changed);
  }
}

// A survey's samples (in time order at times_s) as a problem of their own, one candidate
// per sample, whitened by the slow error `slow` as the calibration whitens its readings.
bool SurveyProblem(const CableRobot& robot, const CalibrationSpec& spec, const DesignProblem& base,
                   const std::vector<Pose>& poses, const std::vector<JointValues>& joints,
                   const std::vector<double>& times_s, const SlowErrorProcess& slow,
                   DesignProblem* out, std::string* error) {
  *out = base;
  out->x_rows.resize(0, out->n);
  out->z_rows.resize(0, out->q);
  out->reading.resize(0);
  out->white_sigma.resize(0);
  if (!internal::AddPoseRows(robot, spec, poses, joints, out, error)) return false;
  internal::WhitenInTimeOrder(slow, times_s, out);
  return true;
}

// Sample n of a survey flown without travel at time n x interval.
std::vector<double> EvenTimes(size_t samples, double interval_s) {
  std::vector<double> times(samples);
  for (size_t n = 0; n < samples; ++n) times[n] = static_cast<double>(n) * interval_s;
  return times;
}

// The design's samples' times: each stop's samples an interval apart, the travel between
// stops at the cabin's speed (none without a speed: the slow error then correlates the
// stops' samples most).
std::vector<double> FlightTimes(const Design& d, const DesignOptions& o) {
  std::vector<double> times;
  double t = 0.0;
  for (size_t k = 0; k < d.stops.size(); ++k) {
    const Eigen::Vector3d& here = d.candidates[d.stops[k].candidate].pose.position_m;
    if (k > 0 && o.speed_m_per_s > 0.0) {
      t += (here - d.candidates[d.stops[k - 1].candidate].pose.position_m).norm() / o.speed_m_per_s;
    }
    t += d.stops[k].settle.wait_s;
    for (int n = 0; n < d.stops[k].samples; ++n, t += o.sample_interval_s) times.push_back(t);
  }
  return times;
}

// The comparison surveys' predictions (a failure is a note, not an error): flown evenly
// in time, the rotator by the focal law.
DesignPrediction PredictPoses(const CableRobot& robot, const CalibrationSpec& spec,
                              const DesignProblem& base, const std::vector<Pose>& poses,
                              const SlowErrorProcess& slow, double interval_s) {
  DesignProblem pr;
  std::string error;
  if (!SurveyProblem(robot, spec, base, poses, internal::ObservingJoints(robot, poses),
                     EvenTimes(poses.size(), interval_s), slow, &pr, &error)) {
    DesignPrediction p;
    p.note = error;
    return p;
  }
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(pr.candidates());
  return PredictWithParts(spec, pr, internal::SumsOf(pr, ones), static_cast<int>(poses.size()));
}

// Stage: the candidates that hold over the plausible range (design.h); the others are
// counted in rejected_off_nominal (and rejected_candidates).
bool KeepThoseThatHold(const internal::PlausibleRange& range, Design* d, std::string* error) {
  d->range = range.parameters();
  std::vector<DesignCandidate> kept;
  for (const DesignCandidate& c : d->candidates) {
    if (range.Holds(c.pose, c.joints, nullptr)) kept.push_back(c);
  }
  d->rejected_off_nominal = static_cast<int>(d->candidates.size() - kept.size());
  d->rejected_candidates += d->rejected_off_nominal;
  if (kept.empty()) {
    *error = "no candidate pose holds over the plausible range of the spec's parameters: " +
             std::to_string(d->rejected_off_nominal) +
             " are feasible at the initial values only (narrow the range: "
             "DesignOptions::range_*, or lower the tension margin)";
    return false;
  }
  d->candidates = std::move(kept);
  return true;
}

bool SetUp(const CableRobot& robot, const CalibrationSpec& spec, const DesignOptions& o,
           DesignProblem* pr, std::string* error) {
  if (!o.IsValid(error)) return false;
  if (!spec.IsValid(error)) return false;
  if (!internal::SetUpDesignProblem(spec, pr, error)) return false;
  if (o.samples < pr->n) {
    *error = std::to_string(o.samples) + " samples cannot determine the spec's " +
             std::to_string(pr->n) + " free parameters: ask for at least " + std::to_string(pr->n) +
             " (each sample's six readings are one pose's)";
    return false;
  }
  return ChooseWanted(spec, o, pr, error);
}

}  // namespace

namespace {

// Stage: the wait after each move (move_settle.h), into the stops and the duration. A move
// the dynamics cannot run (its straight path leaves the workspace, say) waits 0 and is
// named in settle_note; the design stands without.
void SettleAfterMoves(const CableRobot& robot, const DesignOptions& o, Design* d) {
  if (!o.settle_after_moves || !(o.speed_m_per_s > 0.0)) return;
  int failed = 0;
  std::string first;
  for (size_t k = 1; k < d->stops.size(); ++k) {
    const Pose& from = d->candidates[d->stops[k - 1].candidate].pose;
    const Pose& to = d->candidates[d->stops[k].candidate].pose;
    const double move_s = (to.position_m - from.position_m).norm() / o.speed_m_per_s;
    MoveSettle settle;
    std::string why;
    if (!MoveSettleTime(robot, from, to, move_s, o.settle, &settle, &why)) {
      if (failed++ == 0) first = "the move to stop " + std::to_string(k + 1) + ": " + why;
      continue;
    }
    d->stops[k].settle = settle;
    d->settle_s += settle.wait_s;
  }
  if (failed > 0) {
    d->settle_note = std::to_string(failed) + " of " + std::to_string(d->stops.size() - 1) +
                     " moves could not be run in time and wait 0 (" + first + ")";
  }
  d->duration_s += d->settle_s;
}

// Stage: the predictions of the design as flown (its samples' times, the slow error), of
// the paper's circle and of a random survey (a comparison that cannot be made is a note),
// and what limits the design.
bool PredictAll(const CableRobot& robot, const CalibrationSpec& spec, const DesignOptions& options,
                const DesignProblem& pr, Design* d, std::string* error) {
  d->slow_error = PredictionSlowError(spec, options);
  DesignProblem flown;
  if (!SurveyProblem(robot, spec, pr, d->poses, d->joints, FlightTimes(*d, options), d->slow_error,
                     &flown, error)) {
    return false;
  }
  const DesignSums s = internal::SumsOf(flown, Eigen::VectorXd::Ones(flown.candidates()));
  d->design = PredictWithParts(spec, flown, s, options.samples);
  ExplainLimits(spec, flown, s, d);
  std::vector<Pose> reference;
  std::string why;
  if (internal::CirclePoses(options, options.samples, &reference, &why)) {
    d->circle = PredictPoses(robot, spec, pr, reference, d->slow_error, options.sample_interval_s);
  } else {
    d->circle.note = why;
  }
  if (internal::RandomSurveyPoses(robot, options, options.samples, &reference, &why)) {
    d->random = PredictPoses(robot, spec, pr, reference, d->slow_error, options.sample_interval_s);
  } else {
    d->random.note = why;
  }
  return true;
}

}  // namespace

bool DesignSurvey(const CableRobot& robot, const CalibrationSpec& spec,
                  const DesignOptions& options, Design* design, std::string* error) {
  const auto say = [&options](const std::string& what) {
    if (options.progress) options.progress(what);
  };
  DesignProblem pr;
  if (!SetUp(robot, spec, options, &pr, error)) return false;
  Design d;
  d.options = options;
  for (int k = 0; k < pr.n; ++k) {
    const ParameterSpec& p = spec.parameters[pr.free_spec[k]];
    d.free_names.push_back(p.name);
    d.free_units.push_back(p.unit);
    d.free_to_si.push_back(p.to_si);
  }
  d.wanted = pr.wanted;
  say("candidate poses: solving the statics of the grid's nodes and attitudes");
  if (!internal::DesignCandidates(robot, options, &d.candidates, &d.rejected_candidates, error)) {
    return false;
  }
  d.joint_columns = robot.moving_parts.JointColumns();
  if (!internal::ExpandJointGrid(robot, options, &d.candidates, error)) return false;
  for (DesignCandidate& c : d.candidates) c.data_pose = robot.MeasuredPose(c.pose, c.joints);
  say(std::to_string(d.candidates.size()) + " feasible candidates (" +
      std::to_string(d.rejected_candidates) +
      " infeasible); those that hold over the parameters' plausible range");
  const internal::PlausibleRange range(robot, spec, options);
  if (!KeepThoseThatHold(range, &d, error)) return false;
  say(std::to_string(d.candidates.size()) + " candidates hold; their information (Jacobians)");
  std::vector<Pose> poses;
  std::vector<JointValues> joints;
  for (const DesignCandidate& c : d.candidates) {
    poses.push_back(c.pose);
    joints.push_back(c.joints);
  }
  if (!internal::AddPoseRows(robot, spec, poses, joints, &pr, error)) return false;
  NormaliseWeights(spec, options.samples, &pr);
  say("approximate design (" + std::to_string(options.approximate_iterations) +
      " Frank-Wolfe iterations at most)");
  const Eigen::VectorXd w = ApproximateDesign(pr, options.samples, options.approximate_iterations);
  std::vector<int> counts = RoundToSamples(w, options.samples);
  std::vector<int> all(pr.candidates());
  std::iota(all.begin(), all.end(), 0);
  say("exchange of single samples (" + std::to_string(options.exchange_iterations) +
      " swaps at most)");
  Exchange(pr, all, options.exchange_width, options.exchange_iterations, &counts);
  const DesignSums s0 = internal::SumsOf(pr, ToWeights(counts));
  if (!std::isfinite(internal::CriterionOf(pr, s0))) {
    *error = "no survey of " + std::to_string(options.samples) +
             " samples over the feasible poses determines the free parameters: fix some, add "
             "priors, or allow more attitudes (--max-extra-tilt-deg, --max-extra-yaw-deg)";
    return false;
  }
  say("path through the stops" +
      std::string(options.time_budget_s > 0.0 ? " within the time budget" : ""));
  if (!KeepWithinBudget(pr, d.candidates, options, &counts, &d, error)) return false;
  for (DesignStop& stop : d.stops) {
    const DesignCandidate& c = d.candidates[stop.candidate];
    range.Holds(c.pose, c.joints, &stop.binding);
  }
  if (options.settle_after_moves && options.speed_m_per_s > 0.0 && d.stops.size() > 1) {
    say("waits after the " + std::to_string(d.stops.size() - 1) +
        " moves: each run in time where it could leave a tension beyond " +
        Num(100 * options.settle.fraction) + "% of quasi-static");
    SettleAfterMoves(robot, options, &d);
  }
  say("predictions for the design, the paper's circle and a random survey");
  if (!PredictAll(robot, spec, options, pr, &d, error)) return false;
  *design = std::move(d);
  return true;
}

bool PredictSurvey(const CableRobot& robot, const CalibrationSpec& spec,
                   const DesignOptions& options, const std::vector<Pose>& poses,
                   DesignPrediction* prediction, std::string* error) {
  return PredictSurvey(robot, spec, options, poses, {}, prediction, error);
}

bool PredictSurvey(const CableRobot& robot, const CalibrationSpec& spec,
                   const DesignOptions& options, const std::vector<Pose>& poses,
                   const std::vector<JointValues>& joints, DesignPrediction* prediction,
                   std::string* error) {
  if (!joints.empty() && joints.size() != poses.size()) {
    *error = "joints: " + std::to_string(joints.size()) + " joint values for " +
             std::to_string(poses.size()) + " poses";
    return false;
  }
  DesignOptions o = options;
  o.samples = std::max<int>(1, static_cast<int>(poses.size()));
  DesignProblem pr;
  if (!SetUp(robot, spec, o, &pr, error)) return false;
  // The survey's poses are the data's: the cabin's follow through the measured frame.
  std::vector<Pose> cabin(poses.size());
  for (size_t n = 0; n < poses.size(); ++n) {
    cabin[n] = robot.CabinPose(poses[n], joints.empty() ? JointValues{} : joints[n]);
  }
  DesignProblem flown;
  if (!SurveyProblem(robot, spec, pr, cabin, joints, EvenTimes(poses.size(), o.sample_interval_s),
                     PredictionSlowError(spec, o), &flown, error)) {
    return false;
  }
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(flown.candidates());
  *prediction = PredictWithParts(spec, flown, internal::SumsOf(flown, ones), o.samples);
  return true;
}

}  // namespace fastcal
