// Discrete PID controller with anti-windup, tuned from a first-order plus
// dead-time (FOPDT) model K exp(-theta s) / (tau s + 1): the baseline the
// predictive controllers are compared against.
//
// Tuning rules (tau_c is the desired closed-loop time constant, seconds):
//  * SIMC [1, eqs. (18)-(19)]: PI with
//      Kc = tau / (K (tau_c + theta)),  Ti = min(tau, 4 (tau_c + theta)),  Td = 0,
//    where for a digital loop theta includes half the sample time (the zero-
//    order hold's average delay, [1, sec. 3.2]); default tau_c = theta ("tight
//    control", [1]).
//  * IMC [2, Table 1, FOPDT with a first-order Pade approximation]: PID with
//      Kc = (2 tau + theta) / (K (2 tau_c + theta)),  Ti = tau + theta / 2,
//      Td = tau theta / (2 tau + theta),
//    default tau_c = max(0.8 theta, tau / 10) ([2] advises tau_c > 0.8 theta).
//
// Discrete law (ideal form, backward differences) at sample k with e = r - y:
//   P = Kc (b r - y),
//   D = Td/(Td + N Ts) D_prev - Kc Td N/(Td + N Ts) (y - y_prev)  (filtered, on y),
//   v = P + I + D,  u = sat(v),
//   I += Kc Ts/Ti e + Ts/Tt (u - v)      (back-calculation anti-windup [3]),
// with tracking time Tt = sqrt(Ti Td) for PID and Ti/2 for PI [3, sec. 3.5].
// With a velocity feed-forward gain Kv (PidOptions::velocity_feedforward), v
// also holds Kv (r - r_prev)/Ts: the set-point's rate times the input that
// holds that rate. On an integrating plant dy/dt = Ki u, with the derivative
// on y, a ramp r = a t is tracked without lag when Kv = 1/Ki + Kc Td (the
// derivative term's share of the ramp, -Kc Td a, is fed forward too); a PD
// alone lags it by a (1/Ki) / Kc [3, ch. 5]. A set-point step gives one
// sample of Kv (step)/Ts, which the limits clip.
//
// [1] S. Skogestad, "Simple analytic rules for model reduction and PID
//     controller tuning", J. Process Control 13 (2003) 291-309.
// [2] D. E. Rivera, M. Morari, S. Skogestad, "Internal model control. 4. PID
//     controller design", Ind. Eng. Chem. Process Des. Dev. 25 (1986) 252-265.
// [3] K. J. Astrom, T. Hagglund, Advanced PID Control, ISA, 2006, ch. 3.
#pragma once

#include <limits>
#include <string>

#include "pneumid/control/controller.hpp"

namespace pneumid {

/// PID tuning rule from an FOPDT model: Skogestad's SIMC (PI) or IMC (PID), file comment.
enum class PidTuningRule { kSimc, kImc };
/// "simc", "imc".
std::string ToString(PidTuningRule rule);
/// Inverse of ToString; throws InvalidArgument listing the valid names.
PidTuningRule PidTuningRuleFromString(const std::string& name);

/// Gains of the ideal PID form Kc (e + 1/Ti int e dt + Td de/dt); the discrete law (file
/// comment) weights the set-point in P and differentiates y only.
struct PidGains {
  double Kc = 1.0;  ///< proportional gain (input units per output unit)
  double Ti = std::numeric_limits<double>::infinity();  ///< integral time (s); inf = none
  double Td = 0.0;                                      ///< derivative time (s)
};

/// Gains from an FOPDT model (K, tau, theta in output/input units and
/// seconds) by `rule` for a loop sampled at Ts. tau_c <= 0 selects the rule's
/// default (see the file comment).
/// @throws InvalidArgument for K == 0, tau <= 0, theta < 0 or Ts <= 0.
PidGains TunePid(double K, double tau, double theta, double Ts, PidTuningRule rule,
                 double tau_c = 0.0);

/// Gains, set-point weight, derivative filter, anti-windup and limits of the discrete PID.
struct PidOptions {
  PidGains gains;                   ///< Kc, Ti, Td (default P-only with Kc = 1)
  double setpoint_weight = 1.0;     ///< b in P = Kc (b r - y), in [0, 1]
  double derivative_filter = 10.0;  ///< N: derivative filter time Td / N
  double tracking_time = 0.0;       ///< Tt (s) for anti-windup; 0 = automatic (file comment)
  /// Kv: input per unit rate of the set-point (input units per output unit per second),
  /// added as Kv (r - r_prev)/Ts (file comment); 0 = none.
  double velocity_feedforward = 0.0;
  InputLimits limits;  ///< saturation and rate limit of u (sat in the file comment)
  /// True when Kc is finite, Ti > 0 (inf allowed), Td finite and >= 0, setpoint_weight in
  /// [0, 1], derivative_filter > 0, tracking_time >= 0, velocity_feedforward finite and limits are
  /// valid; otherwise false with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// Discrete PID with set-point weighting, filtered derivative on y and back-calculation
/// anti-windup (file comment).
class PidController : public Controller {
 public:
  /// @throws InvalidArgument for invalid options or Ts <= 0.
  PidController(double Ts, const PidOptions& options);

  double Ts() const override { return Ts_; }
  std::string Describe() const override;
  void Accept(ControllerVisitor& visitor) const override {
    visitor.Visit(*this);
  }                                                       ///< Visit(*this)
  const PidOptions& options() const { return options_; }  ///< The options as designed.
  /// Tracking time Tt (s) of the back-calculation actually used (0: none).
  double tracking_time() const { return Tt_; }

 protected:
  void DoReset(double u0, double y0) override;
  double DoUpdate(double setpoint, double measurement) override;
  void DoApplied(double u) override;

 private:
  PidOptions options_;
  double Ts_ = 0.0;
  double Tt_ = 0.0;
  double integral_ = 0.0;
  double derivative_ = 0.0;
  double y_prev_ = 0.0;
  double r_prev_ = 0.0;
  double u_prev_ = 0.0;
};

}  // namespace pneumid
