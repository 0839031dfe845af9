#include "pneumid/models/static_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"

namespace pneumid {

namespace {

inline constexpr EnumName<StaticMapExtrapolation> kExtrapolationNames[] = {
    {StaticMapExtrapolation::kClamp, "clamp"}, {StaticMapExtrapolation::kLinear, "linear"}};

inline constexpr EnumName<Monotonicity> kMonotonicityNames[] = {
    {Monotonicity::kIncreasing, "increasing"},
    {Monotonicity::kDecreasing, "decreasing"},
    {Monotonicity::kConstant, "constant"},
    {Monotonicity::kNone, "not monotone"}};

}  // namespace

std::string ToString(StaticMapExtrapolation e) {
  return std::string(EnumToString(kExtrapolationNames, e));
}

StaticMapExtrapolation StaticMapExtrapolationFromString(const std::string& name) {
  return EnumFromString(kExtrapolationNames, name, "static map extrapolation");
}

std::string ToString(Monotonicity m) { return std::string(EnumToString(kMonotonicityNames, m)); }

StaticMap::StaticMap() : StaticMap({0.0, 1.0}, {0.0, 1.0}, StaticMapExtrapolation::kLinear) {}

StaticMap::StaticMap(std::vector<double> u, std::vector<double> y,
                     StaticMapExtrapolation extrapolation)
    : u_(std::move(u)), y_(std::move(y)), extrapolation_(extrapolation) {
  PNEUMID_CHECK(u_.size() == y_.size(), "a static map needs as many values as knots, got {} and {}",
                u_.size(), y_.size());
  PNEUMID_CHECK(u_.size() >= 2, "a static map needs at least 2 knots, got {}", u_.size());
  for (std::size_t i = 0; i < u_.size(); ++i) {
    PNEUMID_CHECK(std::isfinite(u_[i]) && std::isfinite(y_[i]),
                  "static map knot {} is not finite: (u, y) = ({}, {})", i, u_[i], y_[i]);
    PNEUMID_CHECK(i == 0 || u_[i] > u_[i - 1],
                  "static map knots must be strictly increasing in u, got u[{}] = {} after "
                  "u[{}] = {}",
                  i, u_[i], i - 1, u_[i - 1]);
  }
  bool up = false, down = false;
  for (std::size_t i = 1; i < y_.size(); ++i) {
    if (y_[i] > y_[i - 1]) up = true;
    if (y_[i] < y_[i - 1]) down = true;
    if (up && down && turn_ == 0) turn_ = i - 1;
  }
  direction_ = up && down ? Monotonicity::kNone
               : up       ? Monotonicity::kIncreasing
               : down     ? Monotonicity::kDecreasing
                          : Monotonicity::kConstant;
  if (!IsMonotone()) return;
  sign_ = direction_ == Monotonicity::kIncreasing ? 1.0 : -1.0;
  ys_.resize(y_.size());
  for (std::size_t i = 0; i < y_.size(); ++i) ys_[i] = sign_ * y_[i];
  low_end_ = 0;
  while (low_end_ + 1 < ys_.size() && ys_[low_end_ + 1] == ys_.front()) ++low_end_;
  high_start_ = ys_.size() - 1;
  while (high_start_ > 0 && ys_[high_start_ - 1] == ys_.back()) --high_start_;
}

double StaticMap::Evaluate(double u) const {
  if (std::isnan(u)) return u;
  const std::size_t n = u_.size();
  if (u <= u_.front() || u >= u_.back()) {
    const bool low = u <= u_.front();
    if (extrapolation_ == StaticMapExtrapolation::kClamp) return low ? y_.front() : y_.back();
    const std::size_t i = low ? 0 : n - 2;
    if (y_[i + 1] == y_[i]) return y_[i];  // also for u = +-inf
    return y_[i] + (y_[i + 1] - y_[i]) * (u - u_[i]) / (u_[i + 1] - u_[i]);
  }
  // u_0 < u < u_{n-1}: the segment [u_i, u_{i+1}] with u_i <= u < u_{i+1}.
  const std::size_t i =
      static_cast<std::size_t>(std::upper_bound(u_.begin(), u_.end(), u) - u_.begin()) - 1;
  return y_[i] + (y_[i + 1] - y_[i]) * (u - u_[i]) / (u_[i + 1] - u_[i]);
}

Eigen::VectorXd StaticMap::Evaluate(const Eigen::VectorXd& u) const {
  Eigen::VectorXd out(u.size());
  for (Eigen::Index k = 0; k < u.size(); ++k) out[k] = Evaluate(u[k]);
  return out;
}

double StaticMap::Slope(double u) const {
  const std::size_t n = u_.size();
  if (u < u_.front() || u >= u_.back()) {
    if (extrapolation_ == StaticMapExtrapolation::kClamp) return 0.0;
    const std::size_t i = u < u_.front() ? 0 : n - 2;
    return (y_[i + 1] - y_[i]) / (u_[i + 1] - u_[i]);
  }
  const std::size_t i =
      static_cast<std::size_t>(std::upper_bound(u_.begin(), u_.end(), u) - u_.begin()) - 1;
  return (y_[i + 1] - y_[i]) / (u_[i + 1] - u_[i]);
}

void StaticMap::CheckInvertible() const {
  PNEUMID_CHECK(direction_ != Monotonicity::kConstant,
                "a constant static map (y = {} for u in [{}, {}]) has no inverse", y_.front(),
                u_.front(), u_.back());
  PNEUMID_CHECK(direction_ != Monotonicity::kNone,
                "the static map is not monotone, so it has no inverse: y = {}, {}, {} at "
                "u = {}, {}, {} (knots {}..{})",
                y_[turn_ - 1], y_[turn_], y_[turn_ + 1], u_[turn_ - 1], u_[turn_], u_[turn_ + 1],
                turn_ - 1, turn_ + 1);
}

double StaticMap::Inverse(double y) const {
  if (!IsMonotone()) CheckInvertible();
  PNEUMID_CHECK(!std::isnan(y), "StaticMap::Inverse: the output value is NaN");
  const double v = sign_ * y;
  if (v <= ys_.front()) return u_[low_end_];
  if (v >= ys_.back()) return u_[high_start_];
  // ys_0 < v < ys_{n-1}: the first knot i with ys_i >= v, i >= 1.
  const std::size_t i =
      static_cast<std::size_t>(std::lower_bound(ys_.begin(), ys_.end(), v) - ys_.begin());
  const double y0 = ys_[i - 1], y1 = ys_[i];
  return u_[i - 1] + (u_[i] - u_[i - 1]) * (v - y0) / (y1 - y0);
}

std::optional<double> StaticMap::NearestPreimage(double y, double u_near) const {
  PNEUMID_CHECK(!std::isnan(y) && !std::isnan(u_near),
                "StaticMap::NearestPreimage: NaN output value ({}) or input ({})", y, u_near);
  std::optional<double> best;
  for (std::size_t i = 0; i + 1 < u_.size(); ++i) {
    const double y0 = y_[i], y1 = y_[i + 1];
    if (std::min(y0, y1) > y || std::max(y0, y1) < y) continue;
    const double u = y0 == y1 ? std::clamp(u_near, u_[i], u_[i + 1])
                              : u_[i] + (u_[i + 1] - u_[i]) * (y - y0) / (y1 - y0);
    if (!best || std::abs(u - u_near) < std::abs(*best - u_near)) best = u;
  }
  return best;
}

double StaticMap::NearestPreimageOrEnd(double y, double u_near) const {
  if (const std::optional<double> u = NearestPreimage(y, u_near)) return *u;
  std::size_t best = 0;
  for (std::size_t i = 1; i < u_.size(); ++i) {
    const double d = std::abs(y_[i] - y), d_best = std::abs(y_[best] - y);
    if (d < d_best || (d == d_best && std::abs(u_[i] - u_near) < std::abs(u_[best] - u_near)))
      best = i;
  }
  return u_[best];
}

std::optional<FlatSegment> StaticMap::DeadZone(double tolerance) const {
  PNEUMID_CHECK(tolerance >= 0.0, "the flat-segment tolerance must be >= 0, got {}", tolerance);
  std::size_t k = 0;
  while (k + 1 < y_.size() && std::abs(y_[k + 1] - y_.front()) <= tolerance) ++k;
  if (k == 0) return std::nullopt;
  return FlatSegment{u_.front(), u_[k], y_.front()};
}

std::optional<FlatSegment> StaticMap::Saturation(double tolerance) const {
  PNEUMID_CHECK(tolerance >= 0.0, "the flat-segment tolerance must be >= 0, got {}", tolerance);
  std::size_t k = y_.size() - 1;
  while (k > 0 && std::abs(y_[k - 1] - y_.back()) <= tolerance) --k;
  if (k == y_.size() - 1) return std::nullopt;
  return FlatSegment{u_[k], u_.back(), y_.back()};
}

std::string StaticMap::Describe(double tolerance) const {
  const auto [lo, hi] = std::minmax_element(y_.begin(), y_.end());
  std::string s = fmt::format("{}{}, {} knots on u in [{:g}, {:g}], y in [{:.4g}, {:.4g}]",
                              IsMonotone() ? "monotone " : "", ToString(direction_), size(),
                              u_min(), u_max(), *lo, *hi);
  if (const auto dz = DeadZone(tolerance))
    s += fmt::format(", dead zone u in [{:g}, {:g}] (y = {:.4g})", dz->u_from, dz->u_to, dz->y);
  if (const auto sat = Saturation(tolerance))
    s += fmt::format(", saturation from u = {:g} (y = {:.4g})", sat->u_from, sat->y);
  return s;
}

nlohmann::json ToJson(const StaticMap& map) {
  return {{"u", map.u()}, {"y", map.y()}, {"extrapolation", ToString(map.extrapolation())}};
}

StaticMap StaticMapFromJson(const nlohmann::json& j) {
  PNEUMID_CHECK(j.is_object(), "a static map must be a JSON object with 'u' and 'y', got a JSON {}",
                j.type_name());
  std::vector<double> values[2];
  const char* keys[2] = {"u", "y"};
  for (int k = 0; k < 2; ++k) {
    PNEUMID_CHECK(j.contains(keys[k]) && j.at(keys[k]).is_array(),
                  "static map: '{}' must be an array of numbers", keys[k]);
    for (const nlohmann::json& x : j.at(keys[k])) {
      PNEUMID_CHECK(x.is_number(), "static map: '{}' must hold numbers, got {}", keys[k],
                    Excerpt(x.dump()));
      values[k].push_back(x.get<double>());
    }
  }
  StaticMapExtrapolation e = StaticMapExtrapolation::kClamp;
  if (j.contains("extrapolation")) {
    PNEUMID_CHECK(j.at("extrapolation").is_string(),
                  "static map: 'extrapolation' must be a string, got {}",
                  Excerpt(j.at("extrapolation").dump()));
    e = StaticMapExtrapolationFromString(j.at("extrapolation").get<std::string>());
  }
  return StaticMap(std::move(values[0]), std::move(values[1]), e);
}

}  // namespace pneumid
