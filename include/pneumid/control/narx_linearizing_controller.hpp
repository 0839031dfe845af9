// A linear controller behind the exact input-output linearization of an
// input-affine NARX model (identify/affine_narx.hpp): the nonlinear-model
// controller of the actuator across its whole range.
//
// Model (models/narx_model.hpp, with its input map f; without one f(u) = u):
//   y(t+1) = F(y(t)) + G(y(t)) v(t),   v = f(u),
// F and G polynomials in y read off the NARX terms (ny = nu = nk = 1, each
// term with at most one input factor; InputAffineNarx). The loop is shaped
// as the reference model
//   H(q) = (1 - p) q^-1 / (1 - p q^-1),   p = exp(-Ts / tau),
// i.e. the first-order lag of time constant tau with unit gain, on which the
// inner controller (DMC, GPC, PID or MPC, any tuning rule) is designed. At
// every sample, with the inner controller's request w_k,
//   v_k = (p y_k + (1 - p) w_k - F(y_k)) / G(y_k),   u_k = clip(f^-1(v_k)),
// so that on the model y_{k+1} = p y_k + (1 - p) w_k: the plant seen by the
// inner controller is H at every operating point (discrete-time input-output
// linearization, Henson and Seborg [1] ch. 4; Isidori [2] ch. 4 for the
// continuous-time theory). clip applies the input limits (u_min, u_max,
// |u_k - u_{k-1}| <= du_max); f^-1 is the inverse of f's monotone envelope
// (the running maximum of its knot values: a fitted map can dip where the
// valves do not move the output, e.g. in their dead band). The inner
// controller is told the w that the applied input gives on the model,
//   w = (F(y_k) + G(y_k) f(u_k) - p y_k) / (1 - p),
// when it differs from its request (anti-windup through the linearization),
// and its limits are the model's steady outputs at u_min and u_max.
//
// With --rule auto and no response time the inner design aims at tau (the
// factory, controller_factory.hpp). tau defaults to the median of the model's local time constants
// -Ts / ln(dy(t+1)/dy(t)) at its steady states for inputs spread over the
// input range: the linearized loop keeps the actuator's typical speed, and
// the inner design (e.g. --rule auto) decides how much faster to go.
//
// [1] M. A. Henson, D. E. Seborg (eds.), Nonlinear Process Control, Prentice
//     Hall, 1997, ch. 4 (feedback linearization, discrete time).
// [2] A. Isidori, Nonlinear Control Systems, 3rd ed., Springer, 1995.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "pneumid/control/controller.hpp"
#include "pneumid/models/narx_model.hpp"
#include "pneumid/models/static_map.hpp"

namespace pneumid {

/// An input-affine first-order NARX model with its input map, as polynomials
/// F(y) and G(y) in output units.
class InputAffineNarx {
 public:
  /// @throws InvalidArgument naming what is not first-order input-affine
  /// (ny, nu, nk other than 1, a term with two input factors), or a map
  /// that is not increasing anywhere.
  InputAffineNarx(const NarxModel& narx, std::optional<StaticMap> input_map);

  double Drift(double y) const;  ///< F(y)
  double Gain(double y) const;   ///< G(y)
  /// f(u) (u without a map).
  double Map(double u) const;
  /// The inverse of f's monotone envelope (v itself without a map).
  double InverseMap(double v) const;
  double Ts() const { return Ts_; }  ///< Sample time of the NARX model, s.
  /// The input map f as given (none: f(u) = u).
  const std::optional<StaticMap>& map() const { return map_; }
  /// The monotone envelope of the map that InverseMap inverts (none without a map).
  const std::optional<StaticMap>& envelope() const { return envelope_; }
  /// Coefficients of F and G in powers of z = y / y_scale (Drift(y) =
  /// y_scale sum_k drift_k z^k, evaluated by Horner's rule).
  const std::vector<double>& drift_coefficients() const { return drift_; }
  const std::vector<double>& gain_coefficients() const { return gain_; }  ///< G(y), as F(y)
  double y_scale() const { return y_scale_; }  ///< Output scale of z = y / y_scale.
  /// The steady output for a constant input u: the fixed point of
  /// y = F(y) + G(y) f(u) reached from y0 (NaN when the model does not settle).
  double SteadyOutput(double u, double y0 = 0.0) const;
  /// Median of the local time constants at the steady states for 21 inputs
  /// spread over [u_min, u_max] (those with a stable, non-oscillating local
  /// pole); NaN when there is none.
  double TypicalTimeConstant(double u_min, double u_max) const;
  /// "input-affine NARX (degree d, N knots)".
  std::string Describe() const;

 private:
  double Poly(const std::vector<double>& c, double y) const;
  std::vector<double> drift_, gain_;  ///< coefficients of z^k, z = y / y_scale
  double y_scale_ = 1.0, Ts_ = 1.0;
  std::optional<StaticMap> map_, envelope_;
};

/// Reference model of the NARX linearization.
struct NarxLinearizingOptions {
  /// Time constant of the reference model H, s; <= 0 or NaN: the model's
  /// TypicalTimeConstant over the input limits.
  double time_constant = 0.0;
  /// True unless time_constant is infinite (finite or NaN are accepted); otherwise false
  /// with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// The time constant the controller uses for `options` and `limits`.
/// @throws InvalidArgument when the model has no stable steady state in the
/// input range (no default can be formed).
double ReferenceTimeConstant(const InputAffineNarx& model, const InputLimits& limits,
                             const NarxLinearizingOptions& options = {});

/// The inner controller's limits: w between the model's steady outputs at
/// u_min and u_max (clipped to the map's input range), no rate limit.
InputLimits NarxInnerLimits(const InputAffineNarx& model, const InputLimits& limits);

/// A linear controller designed on the reference model H, driving the plant through the
/// exact linearization of an input-affine NARX model (file comment).
class NarxLinearizingController : public Controller {
 public:
  /// `inner` designed on H (unit gain, time constant `time_constant`, the
  /// model's Ts) with limits NarxInnerLimits(model, limits) or looser.
  /// @throws InvalidArgument for a null controller, a sample time other than
  /// the model's, a non-positive time constant or invalid limits.
  NarxLinearizingController(std::unique_ptr<Controller> inner, InputAffineNarx model,
                            double time_constant, const InputLimits& limits = {});

  double Ts() const override { return inner_->Ts(); }
  /// The inner controller's description + " behind a NARX linearization
  /// (tau = .. s)".
  std::string Describe() const override;
  /// Calls visitor.Visit(*this).
  void Accept(ControllerVisitor& visitor) const override { visitor.Visit(*this); }

  const Controller& inner() const { return *inner_; }      ///< The controller designed on H.
  double time_constant() const { return tau_; }            ///< tau of the reference model H, s.
  const InputAffineNarx& model() const { return model_; }  ///< The model linearized.
  /// The actuator's limits on u.
  const InputLimits& limits() const { return limits_; }
  /// w of the last Update() (the inner controller's request).
  double last_virtual_input() const { return w_; }

 protected:
  void DoReset(double u0, double y0) override;
  /// Allocates no memory.
  double DoUpdate(double setpoint, double measurement) override;
  /// The inner controller takes the w of the applied input. Allocates no memory.
  void DoApplied(double u) override;

 private:
  double AppliedW(double u) const;
  std::unique_ptr<Controller> inner_;
  InputAffineNarx model_;
  double tau_ = 0.0, p_ = 0.0;
  InputLimits limits_;
  double u_prev_ = 0.0, y_last_ = 0.0, w_ = 0.0;
};

}  // namespace pneumid
