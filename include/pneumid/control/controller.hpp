// Common interface of the feedback controllers (DMC, GPC, PID, MPC), so that the
// closed-loop evaluation and the real-time loop drive any of them.
//
// Protocol per sample k (period Ts), with the plant protocol of plant.hpp:
//   y_k = plant.Measure();
//   u_k = controller.Update(r_k, y_k);   // within the controller's limits
//   plant.Advance(u_k);
#pragma once

#include <limits>
#include <string>

namespace pneumid {

enum class ControllerType { kDmc, kGpc, kPid, kMpc };

/// "dmc", "gpc", "pid", "mpc".
std::string ToString(ControllerType type);
/// Inverse of ToString; throws InvalidArgument listing the valid names.
ControllerType ControllerTypeFromString(const std::string& name);

/// Actuator limits every controller respects: the input u in [u_min, u_max]
/// and its change per sample |u_k - u_{k-1}| <= du_max (input units; infinite
/// values switch a limit off).
struct InputLimits {
  double u_min = -std::numeric_limits<double>::infinity();
  double u_max = std::numeric_limits<double>::infinity();
  double du_max = std::numeric_limits<double>::infinity();
  /// True when u_min <= u_max, du_max > 0 and nothing is NaN.
  bool IsValid(std::string* error) const;
  /// u clipped to the limits given the previous input u_prev.
  double Clip(double u, double u_prev) const;
};

class Controller {
 public:
  virtual ~Controller() = default;
  /// Back to rest at an operating point: input u0 applied long enough for
  /// the output to settle at y0 (both in plant units).
  virtual void Reset(double u0 = 0.0, double y0 = 0.0) = 0;
  /// One control step: set-point r and measured output y at the current
  /// sample; returns the input u to hold over the next period (within the
  /// controller's limits). Allocates no memory.
  virtual double Update(double setpoint, double measurement) = 0;
  /// The input actually applied after the last Update(), when a layer after
  /// the controller changed it (the plant's input range, a safety layer, a
  /// saturating actuator). Controllers that remember their past inputs
  /// (DMC's prediction, GPC's filtered moves, PID's integral) take it as their
  /// own (anti-windup); the default does nothing. Allocates no memory.
  virtual void Applied(double /*u*/) {}
  /// Sample period in seconds.
  virtual double Ts() const = 0;
  /// Short description, e.g. "dmc P=126 M=5 lambda=2.25".
  virtual std::string Describe() const = 0;
};

}  // namespace pneumid
