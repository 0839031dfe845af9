#include "pneumid/control/inverse_map_controller.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"

namespace pneumid {

namespace {

void CheckMap(const StaticMap& map) {
  PNEUMID_CHECK(map.IsMonotone(),
                "the inverse of the static map is needed in front of the controller, but the "
                "map ({}) is not monotone",
                map.Describe());
}

}  // namespace

InputLimits InnerLimits(const StaticMap& map, const InputLimits& limits) {
  CheckMap(map);
  std::string error;
  PNEUMID_CHECK(limits.IsValid(&error), "invalid input limits: {}", error);
  const double lo = std::clamp(limits.u_min, map.u_min(), map.u_max());
  const double hi = std::clamp(limits.u_max, map.u_min(), map.u_max());
  const double f_lo = map.Evaluate(lo), f_hi = map.Evaluate(hi);
  InputLimits v;
  v.u_min = std::min(f_lo, f_hi);
  v.u_max = std::max(f_lo, f_hi);
  if (std::isfinite(limits.du_max)) {
    double slope = 0.0;
    for (std::size_t i = 0; i + 1 < map.size(); ++i)
      slope =
          std::max(slope, std::abs((map.y()[i + 1] - map.y()[i]) / (map.u()[i + 1] - map.u()[i])));
    v.du_max = slope > 0.0 ? limits.du_max * slope : std::numeric_limits<double>::infinity();
  }
  return v;
}

InverseMapController::InverseMapController(std::unique_ptr<Controller> inner, StaticMap map,
                                           const InputLimits& limits)
    : inner_(std::move(inner)), map_(std::move(map)), limits_(limits) {
  PNEUMID_CHECK(inner_ != nullptr, "InverseMapController needs a controller, got null");
  CheckMap(map_);
  std::string error;
  PNEUMID_CHECK(limits_.IsValid(&error), "invalid input limits: {}", error);
  Reset();
}

void InverseMapController::DoReset(double u0, double y0) {
  u_prev_ = u0;
  v_ = map_.Evaluate(u0);
  inner_->Reset(v_, y0);
}

double InverseMapController::DoUpdate(double setpoint, double measurement) {
  v_ = inner_->Update(setpoint, measurement);
  const double u_inv = std::isfinite(v_) ? map_.Inverse(v_) : u_prev_;
  const double u = limits_.Clip(u_inv, u_prev_);
  // The inner controller asked for v_; what reaches the plant is f(u). Tell
  // it when the two differ (a dead zone's edge, a saturation, a limit).
  const double v_applied = map_.Evaluate(u);
  if (v_applied != v_) inner_->Applied(v_applied);
  u_prev_ = u;
  return u;
}

void InverseMapController::DoApplied(double u) {
  if (u == u_prev_ || !std::isfinite(u)) return;
  u_prev_ = u;
  inner_->Applied(map_.Evaluate(u));
}

std::string InverseMapController::Describe() const {
  return fmt::format("{} with inverse map ({} knots, u in [{:g}, {:g}])", inner_->Describe(),
                     map_.size(), map_.u_min(), map_.u_max());
}

StaticMap InvertibleInputMap(const StaticMap& f, double tolerance) {
  if (f.IsMonotone()) return f;
  const auto [lo, hi] = std::minmax_element(f.y().begin(), f.y().end());
  double running = f.y().front(), drop = 0.0;
  for (double y : f.y()) {
    running = std::max(running, y);
    drop = std::max(drop, running - y);
  }
  PNEUMID_CHECK(
      drop <= tolerance * (*hi - *lo),
      "the inverse of the static map is needed in front of the controller, but the "
      "map ({}) is not monotone: it falls by {:.4g} after rising, more than {:g} % of its "
      "range",
      f.Describe(), drop, 100.0 * tolerance);
  return MonotoneEnvelope(f, "input map");
}

StaticMap MapThroughGaps(const StaticMap& f, const std::vector<InputGap>& gaps) {
  if (gaps.empty()) return f;
  auto inside = [&](double u) {
    return std::any_of(gaps.begin(), gaps.end(),
                       [&](const InputGap& g) { return u > g.lo && u < g.hi; });
  };
  std::vector<std::pair<double, double>> knots;
  for (std::size_t i = 0; i < f.size(); ++i)
    if (!inside(f.u()[i])) knots.emplace_back(f.u()[i], f.y()[i]);
  for (const InputGap& g : gaps)
    for (double e : {g.lo, g.hi})
      if (!inside(e)) knots.emplace_back(e, f.Evaluate(e));
  std::sort(knots.begin(), knots.end());
  std::vector<double> u, y;
  for (const auto& [ku, ky] : knots) {
    if (!u.empty() && ku <= u.back()) continue;  // a gap end on a knot
    u.push_back(ku);
    y.push_back(ky);
  }
  if (u.size() < 2) return f;
  return StaticMap(std::move(u), std::move(y), f.extrapolation());
}

StaticMap MonotoneEnvelope(const StaticMap& f, const std::string& what) {
  std::vector<double> y = f.y();
  for (std::size_t i = 1; i < y.size(); ++i) y[i] = std::max(y[i], y[i - 1]);
  PNEUMID_CHECK(y.back() > y.front(),
                "the {} ({}) does not increase anywhere, so no controller can invert it", what,
                f.Describe());
  return StaticMap(f.u(), y, StaticMapExtrapolation::kClamp);
}

OutputMapController::OutputMapController(std::unique_ptr<Controller> inner,
                                         const StaticMap& output_map)
    : inner_(std::move(inner)), map_(MonotoneEnvelope(output_map, "output map")) {
  PNEUMID_CHECK(inner_ != nullptr, "OutputMapController needs a controller, got null");
}

void OutputMapController::DoReset(double u0, double y0) { inner_->Reset(u0, map_.Inverse(y0)); }

double OutputMapController::DoUpdate(double setpoint, double measurement) {
  return inner_->Update(map_.Inverse(setpoint), map_.Inverse(measurement));
}

std::string OutputMapController::Describe() const {
  return fmt::format("{} on the inverse output map ({} knots)", inner_->Describe(), map_.size());
}

}  // namespace pneumid
