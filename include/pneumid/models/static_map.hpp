// A static (memoryless) nonlinearity y = f(u) as a piecewise-linear function
// through knots (u_0, y_0), ..., (u_{n-1}, y_{n-1}), u_0 < u_1 < ... strictly:
//
//   f(u) = y_i + (y_{i+1} - y_i) (u - u_i) / (u_{i+1} - u_i),  u_i <= u <= u_{i+1}.
//
// It is the steady-state map of an actuator (force against PWM duty), the
// input map of a Hammerstein model and the output map of a Wiener model
// (identify/hammerstein.hpp).
//
// Outside [u_0, u_{n-1}] Evaluate either holds the end values (kClamp, the
// default: an input beyond the measured range is assumed saturated) or
// continues the first / last segment (kLinear).
//
// Inverse (for a monotone map, i.e. y non-decreasing or non-increasing in u;
// flat segments allowed, a constant map is not invertible). For a
// non-decreasing map, with y_lo = y_0 and y_hi = y_{n-1}:
//
//   Inverse(y) = max{u in [u_0, u_{n-1}] : f(u) = y_lo}   for y <= y_lo,
//                min{u in [u_0, u_{n-1}] : f(u) >= y}     for y > y_lo,
//
// i.e. the input nearest to where the output moves: for a dead zone at the
// low end (y_0 = y_1 = ... = y_k) the upper edge u_k of the dead zone, the
// smallest input that reaches a saturation level, and on an interior flat
// segment its lower edge. Requests beyond the output range are clamped to the
// input range (y < y_lo gives the dead zone's edge, y > y_hi the start of the
// saturation). A non-increasing map is inverted as the non-decreasing map
// -f, so the same rule holds with "low" and "high" of the output exchanged.
// f(Inverse(y)) = clamp(y, min y_i, max y_i) for every monotone map.
//
// Inverse and Evaluate are O(log n) binary searches and allocate nothing, so
// a controller may call them every sample (a dead-zone / saturation
// compensator in front of a linear controller, [1] sec. 2.3).
//
// JSON form: {"u": [...], "y": [...], "extrapolation": "clamp" | "linear"}.
//
// [1] G. Tao, P. V. Kokotovic, Adaptive Control of Systems with Actuator and
//     Sensor Nonlinearities, Wiley, 1996.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace pneumid {

/// What Evaluate returns beyond the first and last knot.
enum class StaticMapExtrapolation {
  kClamp,   ///< "clamp": the end values y_0, y_{n-1} (saturation)
  kLinear,  ///< "linear": the first / last segment continued
};
std::string ToString(StaticMapExtrapolation e);  ///< "clamp", "linear"
/// Inverse of ToString. @throws InvalidArgument listing the valid names.
StaticMapExtrapolation StaticMapExtrapolationFromString(const std::string& name);

/// Direction of a map: kIncreasing / kDecreasing allow flat segments (not
/// strictly monotone); kConstant: all values equal; kNone: not monotone.
enum class Monotonicity { kIncreasing, kDecreasing, kConstant, kNone };
/// "increasing", "decreasing", "constant", "not monotone".
std::string ToString(Monotonicity m);

/// A flat run of knots [u_from, u_to] on which the map is constant at y.
struct FlatSegment {
  double u_from = 0.0;  ///< first input of the run, input units
  double u_to = 0.0;    ///< last input of the run (u_from < u_to)
  double y = 0.0;       ///< output on the run: y_0 (dead zone) or y_{n-1} (saturation)
  bool operator==(const FlatSegment&) const = default;
};

/// Piecewise-linear static map y = f(u) through knots, with extrapolation and the
/// inverse of a monotone map (see above).
class StaticMap {
 public:
  /// The identity through (0, 0) and (1, 1) with linear extrapolation.
  StaticMap();
  /// Knots u (strictly increasing, finite) and values y (finite), >= 2 knots.
  /// @throws InvalidArgument naming the offending knots for sizes that differ,
  ///         fewer than 2 knots, non-finite values or u not strictly increasing.
  StaticMap(std::vector<double> u, std::vector<double> y,
            StaticMapExtrapolation extrapolation = StaticMapExtrapolation::kClamp);

  const std::vector<double>& u() const { return u_; }  ///< knot inputs, strictly increasing
  const std::vector<double>& y() const { return y_; }  ///< knot outputs f(u_i)
  std::size_t size() const { return u_.size(); }       ///< number of knots n (>= 2)
  /// Behaviour of Evaluate outside [u_min(), u_max()].
  StaticMapExtrapolation extrapolation() const { return extrapolation_; }
  double u_min() const { return u_.front(); }  ///< first knot u_0
  double u_max() const { return u_.back(); }   ///< last knot u_{n-1}

  /// f(u) (see above); NaN gives NaN.
  double Evaluate(double u) const;
  /// f applied to each element.
  Eigen::VectorXd Evaluate(const Eigen::VectorXd& u) const;
  /// df/du at u: the slope of the segment holding u (the right one at a knot;
  /// beyond the range 0 when clamping, the end slope when extrapolating).
  double Slope(double u) const;

  /// Monotonicity of the knot values (computed at construction).
  Monotonicity Direction() const { return direction_; }
  /// Non-decreasing or non-increasing and not constant: Inverse is defined.
  bool IsMonotone() const {
    return direction_ == Monotonicity::kIncreasing || direction_ == Monotonicity::kDecreasing;
  }
  /// The input that gives output y (see above), within [u_min(), u_max()].
  /// @throws InvalidArgument for a map that is not monotone (naming the knots
  ///         where it turns) or constant, or a NaN y.
  double Inverse(double y) const;
  /// The input nearest to u_near among those in [u_min(), u_max()] at which
  /// f takes the value y: on a segment from (u_i, y_i) to (u_i+1, y_i+1) with
  /// y between y_i and y_i+1, u = u_i + (u_i+1 - u_i) (y - y_i) / (y_i+1 - y_i)
  /// (on a flat segment at y, u_near clamped to it). Defined for every map,
  /// monotone or not (a map that turns can reach y on several segments);
  /// std::nullopt when y lies outside [min y_i, max y_i].
  /// @throws InvalidArgument for a NaN y or u_near.
  std::optional<double> NearestPreimage(double y, double u_near) const;
  /// NearestPreimage, and for a y outside [min y_i, max y_i] the knot whose
  /// value is nearest y (of two such knots, the one nearer u_near): the
  /// state a model with this output map starts from to show the first
  /// measured output y, also when the measurement lies a little beyond the
  /// map's values (noise at the rest the map's lowest knot holds).
  /// @throws InvalidArgument for a NaN y or u_near.
  double NearestPreimageOrEnd(double y, double u_near) const;

  /// The flat run at the low-input end (the knots whose values differ from
  /// y_0 by at most `tolerance`, output units, >= 0), when it spans at least
  /// one segment: the dead zone. std::nullopt otherwise.
  std::optional<FlatSegment> DeadZone(double tolerance = 0.0) const;
  /// The flat run at the high-input end, as DeadZone: the saturation.
  std::optional<FlatSegment> Saturation(double tolerance = 0.0) const;
  /// One line: "monotone increasing, 8 knots on u in [0, 100], y in [0, 193.2],
  /// dead zone u in [0, 10] (y = 0), saturation from u = 88 (y = 193.2)".
  std::string Describe(double tolerance = 0.0) const;

  bool operator==(const StaticMap&) const = default;

 private:
  void CheckInvertible() const;
  std::vector<double> u_;
  std::vector<double> y_;
  StaticMapExtrapolation extrapolation_ = StaticMapExtrapolation::kLinear;
  Monotonicity direction_ = Monotonicity::kIncreasing;
  // Inverse: sign * y (non-decreasing), the index of the last knot of the
  // low-end flat run and of the first knot of the high-end flat run.
  double sign_ = 1.0;
  std::vector<double> ys_;
  std::size_t low_end_ = 0;
  std::size_t high_start_ = 1;
  std::size_t turn_ = 0;  // a knot where a non-monotone map turns (for messages)
};

/// The JSON form above.
nlohmann::json ToJson(const StaticMap& map);
/// Inverse of ToJson(const StaticMap&) ("extrapolation" optional, default clamp).
/// @throws InvalidArgument naming the missing or malformed key.
StaticMap StaticMapFromJson(const nlohmann::json& j);

}  // namespace pneumid
