#include "pneumid/identify/nonlinear/static_map_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"

namespace pneumid {

namespace {

inline constexpr EnumName<StaticMapSource> kSourceNames[] = {
    {StaticMapSource::kAuto, "auto"},
    {StaticMapSource::kStaircase, "staircase"},
    {StaticMapSource::kRamp, "ramp"}};

// One constant-input run [begin, end) of the data.
struct Run {
  Eigen::Index begin = 0, end = 0;
  double level = 0.0;
};

std::vector<Run> ConstantRuns(const Eigen::VectorXd& u, double tolerance) {
  std::vector<Run> runs;
  Eigen::Index b = 0;
  for (Eigen::Index k = 1; k <= u.size(); ++k) {
    if (k == u.size() || std::abs(u[k] - u[b]) > tolerance) {
      runs.push_back({b, k, u.segment(b, k - b).mean()});
      b = k;
    }
  }
  return runs;
}

// Levels sorted by u, merged within `tolerance` (weighted means).
struct Levels {
  std::vector<double> u, y, w;
};

Levels MergeLevels(std::vector<std::array<double, 3>> points, double tolerance) {
  std::sort(points.begin(), points.end());
  Levels out;
  for (const auto& [u, y, w] : points) {
    if (!out.u.empty() && u - out.u.back() <= tolerance) {
      const double wt = out.w.back() + w;
      out.u.back() = (out.u.back() * out.w.back() + u * w) / wt;
      out.y.back() = (out.y.back() * out.w.back() + y * w) / wt;
      out.w.back() = wt;
    } else {
      out.u.push_back(u);
      out.y.push_back(y);
      out.w.push_back(w);
    }
  }
  return out;
}

std::string Join(const std::vector<double>& v, std::size_t max_items = 12) {
  std::string s;
  for (std::size_t i = 0; i < v.size() && i < max_items; ++i)
    s += fmt::format("{}{:.4g}", i ? ", " : "", v[i]);
  if (v.size() > max_items) s += fmt::format(", ... ({} in all)", v.size());
  return s;
}

Levels StaircaseLevels(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double Ts,
                       const StaticMapFitOptions& o, StaticMapFitSummary* s) {
  std::vector<std::array<double, 3>> points;
  for (const Run& r : ConstantRuns(u, o.level_tolerance)) {
    const Eigen::Index n = r.end - r.begin;
    if (static_cast<double>(n) * Ts < o.min_segment_duration || n < 2) {
      ++s->segments_skipped;
      continue;
    }
    const auto m = std::max<Eigen::Index>(
        1, static_cast<Eigen::Index>(std::floor(o.settle_fraction * static_cast<double>(n))));
    points.push_back({r.level, y.segment(r.end - m, m).mean(), static_cast<double>(m)});
    ++s->segments_used;
  }
  return MergeLevels(std::move(points), o.level_tolerance);
}

Levels RampLevels(const Eigen::VectorXd& u, const Eigen::VectorXd& y, const StaticMapFitOptions& o,
                  StaticMapFitSummary* s) {
  const double lo = u.minCoeff(), hi = u.maxCoeff();
  std::vector<double> su(o.ramp_bins, 0.0), sy(o.ramp_bins, 0.0), n(o.ramp_bins, 0.0);
  for (Eigen::Index k = 0; k < u.size(); ++k) {
    const int b = std::min(o.ramp_bins - 1,
                           static_cast<int>(std::floor((u[k] - lo) / (hi - lo) * o.ramp_bins)));
    su[b] += u[k];
    sy[b] += y[k];
    n[b] += 1.0;
  }
  std::vector<std::array<double, 3>> points;
  for (int b = 0; b < o.ramp_bins; ++b) {
    if (n[b] == 0.0) continue;
    points.push_back({su[b] / n[b], sy[b] / n[b], n[b]});
    ++s->segments_used;
  }
  return MergeLevels(std::move(points), o.level_tolerance);
}

bool IsMonotoneSignal(const Eigen::VectorXd& u) {
  bool up = false, down = false;
  for (Eigen::Index k = 1; k < u.size(); ++k) {
    up = up || u[k] > u[k - 1];
    down = down || u[k] < u[k - 1];
  }
  return !(up && down);
}

}  // namespace

std::string ToString(StaticMapSource s) { return std::string(EnumToString(kSourceNames, s)); }

StaticMapSource StaticMapSourceFromString(const std::string& name) {
  return EnumFromString(kSourceNames, name, "static map source");
}

bool StaticMapFitOptions::IsValid(std::string* error) const {
  auto fail = [error](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (!(settle_fraction > 0.0 && settle_fraction <= 1.0))
    return fail(fmt::format("StaticMapFitOptions::settle_fraction must be in (0, 1], got {}",
                            settle_fraction));
  if (!(min_segment_duration >= 0.0 && std::isfinite(min_segment_duration)))
    return fail(fmt::format("StaticMapFitOptions::min_segment_duration must be >= 0, got {}",
                            min_segment_duration));
  if (!(level_tolerance >= 0.0 && std::isfinite(level_tolerance)))
    return fail(
        fmt::format("StaticMapFitOptions::level_tolerance must be >= 0, got {}", level_tolerance));
  if (smoothing_passes < 0)
    return fail(fmt::format("StaticMapFitOptions::smoothing_passes must be >= 0, got {}",
                            smoothing_passes));
  if (ramp_bins < 2)
    return fail(fmt::format("StaticMapFitOptions::ramp_bins must be >= 2, got {}", ramp_bins));
  return true;
}

std::string StaticMapFitSummary::BriefReport() const {
  return fmt::format("static-map {}: {}, {} level(s), {} skipped, {} pooled (max change {:.3g})",
                     ToString(termination), ToString(source), segments_used, segments_skipped,
                     levels_pooled, max_adjustment);
}

std::vector<double> PoolAdjacentViolators(const std::vector<double>& values,
                                          const std::vector<double>& weights, bool increasing) {
  PNEUMID_CHECK(values.size() == weights.size(), "PAVA: {} values but {} weights", values.size(),
                weights.size());
  const double sign = increasing ? 1.0 : -1.0;
  // Blocks of pooled values: mean (of sign * value), weight, count.
  std::vector<double> mean, weight;
  std::vector<std::size_t> count;
  for (std::size_t i = 0; i < values.size(); ++i) {
    PNEUMID_CHECK(weights[i] > 0.0, "PAVA: weight {} is {}, must be > 0", i, weights[i]);
    mean.push_back(sign * values[i]);
    weight.push_back(weights[i]);
    count.push_back(1);
    while (mean.size() > 1 && mean[mean.size() - 2] > mean.back()) {
      const std::size_t j = mean.size() - 2;
      const double w = weight[j] + weight.back();
      mean[j] = (mean[j] * weight[j] + mean.back() * weight.back()) / w;
      weight[j] = w;
      count[j] += count.back();
      mean.pop_back();
      weight.pop_back();
      count.pop_back();
    }
  }
  std::vector<double> out;
  out.reserve(values.size());
  for (std::size_t b = 0; b < mean.size(); ++b) out.insert(out.end(), count[b], sign * mean[b]);
  return out;
}

StaticMapFitResult FitStaticMap(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double Ts,
                                const StaticMapFitOptions& options) {
  std::string why;
  PNEUMID_CHECK(options.IsValid(&why), "{}", why);
  PNEUMID_CHECK(u.size() == y.size(), "static map: the input has {} samples, the output {}",
                u.size(), y.size());
  PNEUMID_CHECK(u.size() >= 2, "static map: needs at least 2 samples, got {}", u.size());
  PNEUMID_CHECK(Ts > 0.0 && std::isfinite(Ts), "sample time must be positive, got Ts = {}", Ts);
  PNEUMID_CHECK(u.allFinite() && y.allFinite(), "static map: the data hold non-finite values");
  const double lo = u.minCoeff(), hi = u.maxCoeff();
  PNEUMID_CHECK(hi - lo > options.level_tolerance,
                "static map: the input never leaves one operating point: u stays at {:g} "
                "(u in [{:g}, {:g}] over {} samples, level tolerance {:g}); a static map needs "
                "a staircase or a ramp over the input range",
                u[0], lo, hi, u.size(), options.level_tolerance);

  StaticMapFitResult r;
  StaticMapFitSummary& s = r.summary;
  Levels levels;
  if (options.source != StaticMapSource::kRamp) {
    levels = StaircaseLevels(u, y, Ts, options, &s);
    s.source = StaticMapSource::kStaircase;
  }
  if (options.source == StaticMapSource::kRamp ||
      (options.source == StaticMapSource::kAuto && levels.u.size() < 2 && IsMonotoneSignal(u))) {
    PNEUMID_CHECK(IsMonotoneSignal(u),
                  "static map: a ramp must be monotone, the input goes up and down within "
                  "[{:g}, {:g}]",
                  lo, hi);
    s = StaticMapFitSummary{};
    s.source = StaticMapSource::kRamp;
    levels = RampLevels(u, y, options, &s);
  }
  PNEUMID_CHECK(levels.u.size() >= 2,
                "static map: the data have {} settled level(s) ({}) of constant input lasting "
                ">= {:g} s ({} shorter run(s) skipped); a staircase needs at least 2",
                levels.u.size(), Join(levels.u), options.min_segment_duration, s.segments_skipped);

  r.level_u = levels.u;
  r.level_y = levels.y;
  r.weight = levels.w;
  std::vector<double> values = levels.y;
  if (options.monotone || options.smoothing_passes > 0) {
    // Direction: the sign of the weighted least-squares slope of y against u.
    const double sw = std::accumulate(levels.w.begin(), levels.w.end(), 0.0);
    double mu = 0.0, my = 0.0;
    for (std::size_t i = 0; i < values.size(); ++i) {
      mu += levels.w[i] * levels.u[i] / sw;
      my += levels.w[i] * levels.y[i] / sw;
    }
    double cov = 0.0;
    for (std::size_t i = 0; i < values.size(); ++i)
      cov += levels.w[i] * (levels.u[i] - mu) * (levels.y[i] - my);
    const bool increasing = cov >= 0.0;
    if (options.monotone) values = PoolAdjacentViolators(values, levels.w, increasing);
    for (int p = 0; p < options.smoothing_passes; ++p) {
      std::vector<double> next = values;
      for (std::size_t i = 1; i + 1 < values.size(); ++i)
        next[i] = 0.25 * values[i - 1] + 0.5 * values[i] + 0.25 * values[i + 1];
      values = std::move(next);
    }
    if (options.monotone && options.smoothing_passes > 0)
      values = PoolAdjacentViolators(values, levels.w, increasing);
  }
  for (std::size_t i = 0; i < values.size(); ++i) {
    s.max_adjustment = std::max(s.max_adjustment, std::abs(values[i] - levels.y[i]));
    if (i > 0 && values[i] == values[i - 1] && levels.y[i] != levels.y[i - 1]) ++s.levels_pooled;
  }
  r.map = StaticMap(levels.u, values, options.extrapolation);
  s.termination = Termination::kConvergence;
  s.message = fmt::format("{} knots from {} {}, {}", values.size(), s.segments_used,
                          s.source == StaticMapSource::kRamp ? "ramp bin(s)" : "settled segment(s)",
                          r.map.Describe());
  return r;
}

StaticMapFitResult FitStaticMap(const Dataset& data, int input, int output,
                                const StaticMapFitOptions& options) {
  PNEUMID_CHECK(
      input >= 0 && input < data.num_inputs() && output >= 0 && output < data.num_outputs(),
      "input column {} / output column {} do not exist (the data have {} input(s) and "
      "{} output(s))",
      input, output, data.num_inputs(), data.num_outputs());
  data.RequireUniform();
  return FitStaticMap(data.u(input), data.y(output), data.SampleTime(), options);
}

std::vector<double> PlaceMapKnots(const Eigen::VectorXd& u, int num_knots, int max_levels) {
  PNEUMID_CHECK(u.size() > 0 && u.allFinite(), "map knots need finite input samples, got {} {}",
                u.size(), u.size() ? "with non-finite values" : "samples");
  PNEUMID_CHECK(num_knots == 0 || num_knots >= 2, "num_knots must be 0 (automatic) or >= 2, got {}",
                num_knots);
  PNEUMID_CHECK(max_levels >= 2, "max_levels must be >= 2, got {}", max_levels);
  const double lo = u.minCoeff(), hi = u.maxCoeff();
  std::vector<double> knots;
  if (!(hi > lo)) return {lo, lo + std::max(1.0, std::abs(lo))};  // one level: callers refuse
  if (num_knots >= 2) {
    const Eigen::VectorXd k = Eigen::VectorXd::LinSpaced(num_knots, lo, hi);
    return {k.data(), k.data() + k.size()};
  }
  // Levels: values held for 3 or more consecutive samples, merged within
  // 1e-6 of the range.
  const double tol = 1e-6 * (hi - lo);
  std::vector<std::pair<double, Eigen::Index>> runs;  // (level, samples)
  for (Eigen::Index t = 0; t < u.size();) {
    Eigen::Index e = t + 1;
    while (e < u.size() && std::abs(u[e] - u[t]) <= tol) ++e;
    if (e - t >= 3) runs.emplace_back(u[t], e - t);
    t = e;
  }
  std::sort(runs.begin(), runs.end());
  std::vector<double> levels;
  Eigen::Index held = 0;
  for (const auto& [level, count] : runs) {
    if (levels.empty() || level - levels.back() > tol) levels.push_back(level);
    held += count;
  }
  const auto n = static_cast<double>(u.size());
  if (levels.size() >= 2 && static_cast<int>(levels.size()) <= max_levels &&
      static_cast<double>(held) >= 0.9 * n) {
    if (levels.front() - lo > tol) levels.insert(levels.begin(), lo);
    if (hi - levels.back() > tol) levels.push_back(hi);
    return levels;
  }
  std::vector<double> sorted(u.data(), u.data() + u.size());
  std::sort(sorted.begin(), sorted.end());
  const int m = 11;
  for (int i = 0; i < m; ++i) {
    const double q = sorted[static_cast<std::size_t>(
        std::lround(static_cast<double>(i) / (m - 1) * static_cast<double>(sorted.size() - 1)))];
    if (knots.empty() || q - knots.back() > 1e-3 * (hi - lo)) knots.push_back(q);
  }
  if (knots.back() < hi) knots.back() = hi;
  if (knots.size() < 2) knots = {lo, hi};
  return knots;
}

std::string MapGap::Describe() const {
  return fmt::format(
      "between u = {:g} and {:g} the map changes by {:.4g} with no data in between: the data "
      "leave it undetermined there (a step may lie anywhere inside); an experiment with levels "
      "between them would place it",
      u_lo, u_hi, change);
}

bool VisitsMapGap(double u, double lo, double hi) {
  const double margin = 0.01 * (hi - lo);
  return u > lo + margin && u < hi - margin;
}

std::vector<MapGap> FindMapGaps(const StaticMap& map, const Eigen::VectorXd& u) {
  const std::vector<double>& c = map.u();
  const std::vector<double>& f = map.y();
  const std::size_t m = c.size();
  std::vector<MapGap> gaps;
  if (m < 2) return gaps;
  const auto [fmin, fmax] = std::minmax_element(f.begin(), f.end());
  const double range = *fmax - *fmin;
  if (!(range > 0.0)) return gaps;
  std::vector<bool> inside(m - 1, false);
  for (Eigen::Index t = 0; t < u.size(); ++t) {
    const auto it = std::upper_bound(c.begin(), c.end(), u[t]);
    if (it == c.begin() || it == c.end()) continue;
    const auto j = static_cast<std::size_t>(it - c.begin()) - 1;
    if (VisitsMapGap(u[t], c[j], c[j + 1])) inside[j] = true;
  }
  const auto slope = [&](std::size_t j) { return (f[j + 1] - f[j]) / (c[j + 1] - c[j]); };
  std::vector<double> spacing(m - 1);
  for (std::size_t j = 0; j + 1 < m; ++j) spacing[j] = c[j + 1] - c[j];
  std::nth_element(spacing.begin(),
                   spacing.begin() + static_cast<std::ptrdiff_t>(spacing.size() / 2),
                   spacing.end());
  const double median_spacing = spacing[spacing.size() / 2];
  const double span = c.back() - c.front();
  for (std::size_t j = 0; j + 1 < m; ++j) {
    const double change = std::abs(f[j + 1] - f[j]);
    if (inside[j] || change < 0.05 * range) continue;
    double beside = 0.0;
    if (j > 0) beside = std::max(beside, std::abs(slope(j - 1)));
    if (j + 2 < m) beside = std::max(beside, std::abs(slope(j + 1)));
    // The flatter intervals beside it, extended to its middle, against the
    // chord (a steeper neighbour is itself the candidate for the jump).
    const double mid = 0.5 * (c[j] + c[j + 1]);
    const double chord = 0.5 * (f[j] + f[j + 1]);
    const double own = std::abs(slope(j));
    double spread = 0.0;
    if (j > 0 && std::abs(slope(j - 1)) <= own)
      spread = std::max(spread, std::abs(f[j] + slope(j - 1) * (mid - c[j]) - chord));
    if (j + 2 < m && std::abs(slope(j + 1)) <= own)
      spread = std::max(spread, std::abs(f[j + 1] - slope(j + 1) * (c[j + 1] - mid) - chord));
    // A wide interval: at least twice the knots' median spacing and 15 % of
    // their span, over which the map changes by 10 % of its range or more.
    const double width = c[j + 1] - c[j];
    const bool wide =
        width >= 2.0 * median_spacing && width >= 0.15 * span && change >= 0.1 * range;
    // A large change: a third of the map's range or more, twice as steep as
    // the steeper neighbour (the larger the change, the less steepness it
    // takes: levels 79 and 93 % hold the default twin's jump at 85-86 % and
    // 40 % of its range, only 2.3 times as steep as 66-79 %; a parabola
    // through equally spaced knots steepens by at most 5/3 from its second
    // interval on).
    const bool large = change >= range / 3.0 && own >= 2.0 * beside;
    if (own >= 2.5 * beside || spread >= 0.4 * change || wide || large)
      gaps.push_back({c[j], c[j + 1], f[j + 1] - f[j]});
  }
  return gaps;
}

}  // namespace pneumid
