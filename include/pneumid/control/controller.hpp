// Common interface of the feedback controllers (DMC, GPC, PID, MPC), so that the
// closed-loop evaluation and the real-time loop drive any of them.
//
// Protocol per sample k (period Ts), with the plant protocol of plant.hpp:
//   y_k = plant.Measure();
//   u_k = controller.Update(r_k, y_k);   // within the controller's limits
//   plant.Advance(u_k);
#pragma once

#include <cstdint>
#include <limits>
#include <string>

namespace pneumid {

/// The feedback controllers of the toolkit: dynamic matrix control, generalized predictive
/// control, PID, and state-space MPC with an estimator.
enum class ControllerType { kDmc, kGpc, kPid, kMpc };

/// "dmc", "gpc", "pid", "mpc".
std::string ToString(ControllerType type);
/// Inverse of ToString; throws InvalidArgument listing the valid names.
ControllerType ControllerTypeFromString(const std::string& name);

/// Actuator limits every controller respects: the input u in [u_min, u_max]
/// and its change per sample |u_k - u_{k-1}| <= du_max (input units; infinite
/// values switch a limit off).
struct InputLimits {
  double u_min = -std::numeric_limits<double>::infinity();  ///< lowest input (default: none)
  double u_max = std::numeric_limits<double>::infinity();   ///< highest input (default: none)
  /// Largest change of the input per sample, > 0 (default: none).
  double du_max = std::numeric_limits<double>::infinity();
  /// True when u_min <= u_max, du_max > 0 and nothing is NaN.
  bool IsValid(std::string* error) const;
  /// u clipped to the limits given the previous input u_prev.
  double Clip(double u, double u_prev) const;
};

/// What Controller::Update() found wrong with a sample (Controller::last_fault()).
enum class ControllerFault {
  kNone,                   ///< the sample was valid
  kMeasurementNotFinite,   ///< y is NaN or infinite
  kMeasurementOutOfRange,  ///< y outside MeasurementGuard's [y_min, y_max]
  kSetpointNotFinite,      ///< r is NaN or infinite
  kOutputNotFinite,        ///< the control law returned a non-finite input
};

/// "none", "measurement-not-finite", "measurement-out-of-range",
/// "setpoint-not-finite", "output-not-finite".
std::string ToString(ControllerFault fault);
/// Inverse of ToString; throws InvalidArgument listing the valid names.
ControllerFault ControllerFaultFromString(const std::string& name);

/// Which samples a controller accepts, and what it applies on the others.
///
/// A sample whose measurement is not finite or outside [y_min, y_max], or
/// whose set-point is not finite, is a fault: the controller's state is not
/// updated with it, Update() returns the last valid input (or safe_input when
/// it is set) and counts the fault, and the next valid sample resumes the
/// control law from the state before the fault.
///
/// A valid sample whose control law gives no finite input (before the
/// limits: a finite measurement so large that the law overflows, e.g. 1.7e308
/// into a PID's proportional term, or 3e37 in float) is a fault too
/// (kOutputNotFinite). The law's state may then hold the overflow, so it is
/// restarted at rest at the held input and the last valid measurement
/// (DoReset), and the next valid sample resumes control from there. A value
/// huge but not overflowing still drives a model's observer far away, from
/// which it returns only as fast as the model forgets: give the sensor's
/// range (y_min, y_max) for a deployed loop. The generated C modules do the
/// same (c_codegen.hpp).
struct MeasurementGuard {
  /// The range of measurements a working sensor gives (plant units); the
  /// default accepts every finite value.
  double y_min = -std::numeric_limits<double>::infinity();
  double y_max = std::numeric_limits<double>::infinity();  ///< upper end of that range
  /// The input applied while the samples are faulty (e.g. the valves'
  /// vented state); NaN holds the last valid input. It is applied as is,
  /// outside the controller's limits, and the controller takes it as its own
  /// (Applied), so that it resumes from it.
  double safe_input = std::numeric_limits<double>::quiet_NaN();
  /// True when y_min <= y_max, neither is NaN and safe_input is NaN or finite.
  bool IsValid(std::string* error) const;
  /// The fault of a sample (kNone for a valid one), in the order of the enum.
  ControllerFault Check(double setpoint, double measurement) const;
};

class Controller;
class PidController;
class DmcController;
class GpcController;
class MpcController;
class InverseMapController;
class OutputMapController;
class ModulatedController;
class NarxLinearizingController;

/// Double dispatch over the toolkit's controller classes (after the visitor
/// pattern): Controller::Accept calls the Visit of the controller's own class,
/// so that code generation and analyses handle each class without a chain of
/// casts. A class the visitor does not know (a user's own Controller) arrives
/// at VisitOther.
class ControllerVisitor {
 public:
  virtual ~ControllerVisitor() = default;
  virtual void Visit(const PidController& controller) = 0;         ///< pid.hpp
  virtual void Visit(const DmcController& controller) = 0;         ///< dmc.hpp (DMC, QDMC)
  virtual void Visit(const GpcController& controller) = 0;         ///< gpc.hpp
  virtual void Visit(const MpcController& controller) = 0;         ///< mpc.hpp
  virtual void Visit(const InverseMapController& controller) = 0;  ///< inverse_map_controller.hpp
  virtual void Visit(const OutputMapController& controller) = 0;   ///< inverse_map_controller.hpp
  virtual void Visit(const ModulatedController& controller) = 0;   ///< duty_modulator.hpp
  virtual void Visit(
      const NarxLinearizingController& controller) = 0;  ///< narx_linearizing_controller.hpp
  /// Any other Controller.
  virtual void VisitOther(const Controller& controller) = 0;
};

/// The feedback controllers' interface. Update(), Reset() and Applied() are
/// the guarded entry points (non-virtual); a controller implements DoReset(),
/// DoUpdate() and DoApplied(), which see only valid samples.
class Controller {
 public:
  virtual ~Controller() = default;
  /// Back to rest at an operating point: input u0 applied long enough for
  /// the output to settle at y0 (both in plant units). Clears the fault
  /// state and count.
  void Reset(double u0 = 0.0, double y0 = 0.0);
  /// One control step: set-point r and measured output y at the current
  /// sample; returns the input u to hold over the next period (within the
  /// controller's limits). A faulty sample (MeasurementGuard) leaves the
  /// state untouched and returns the last valid input, or the guard's safe
  /// input; a law that gives no finite input is restarted (see
  /// MeasurementGuard). Allocates no memory.
  double Update(double setpoint, double measurement);
  /// The input actually applied after the last Update(), when a layer after
  /// the controller changed it (the plant's input range, a safety layer, a
  /// saturating actuator). Controllers that remember their past inputs
  /// (DMC's prediction, GPC's filtered moves, PID's integral) take it as their
  /// own (anti-windup). A non-finite u is ignored. Allocates no memory.
  void Applied(double u);
  /// Sample period in seconds.
  virtual double Ts() const = 0;
  /// Short description, e.g. "dmc P=126 M=5 lambda=2.25".
  virtual std::string Describe() const = 0;
  /// Calls the visitor's Visit for this controller's class (VisitOther for
  /// a class the visitor does not list).
  virtual void Accept(ControllerVisitor& visitor) const { visitor.VisitOther(*this); }

  /// @throws InvalidArgument for an invalid guard (the message names the field).
  void SetMeasurementGuard(const MeasurementGuard& guard);
  /// The guard in use (the default accepts every finite sample).
  const MeasurementGuard& measurement_guard() const { return guard_; }
  /// The fault of the last Update() (kNone after a valid sample).
  ControllerFault last_fault() const { return last_fault_; }
  /// Faulty samples since the last Reset().
  std::int64_t fault_count() const { return fault_count_; }
  /// The input of the last Update() or Applied() (the held input on a fault).
  double last_input() const { return last_u_; }

 protected:
  /// The control law's Reset, Update and Applied: called with finite values
  /// (and, for DoUpdate, a measurement within the guard's range) only.
  /// DoUpdate returns a non-finite value, never a clipped one, when its law
  /// gives no finite input (the base class then restarts it).
  virtual void DoReset(double u0, double y0) = 0;
  virtual double DoUpdate(double setpoint, double measurement) = 0;
  /// The default does nothing (a controller without memory of its inputs).
  virtual void DoApplied(double /*u*/) {}

 private:
  MeasurementGuard guard_;
  ControllerFault last_fault_ = ControllerFault::kNone;
  std::int64_t fault_count_ = 0;
  double last_u_ = 0.0;
  double last_y_ = 0.0;  // the last valid measurement (or Reset's y0)
};

}  // namespace pneumid
