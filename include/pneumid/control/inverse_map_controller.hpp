// A linear controller behind the inverse of the actuator's static map: the
// linearizing input transformation of a Hammerstein plant [1, sec. 2.3; 2].
//
// Plant (Hammerstein): y = G(q) v with v = f(u), f the static map of the
// actuator (models/static_map.hpp; for the IPA the steady force in N at duty u
// in %), G the linear dynamics (unit static gain when f is the steady-state
// map). The inner controller is designed on G: its input is v, in f's output
// units. At every sample
//   v_k = inner.Update(r_k, y_k),   u_k = clip(f^-1(v_k)),
// with f^-1 the map's inverse (StaticMap::Inverse: on a dead zone its edge
// where the output starts to move, beyond the output range the end of the
// input range) and clip the input limits of the actuator (u_min, u_max, and
// |u_k - u_{k-1}| <= du_max). When the clipped input differs from the
// inverse the inner controller is told v = f(u_k) (Controller::Applied),
// as it is for an input a later layer changes: anti-windup through the map.
// The inner controller's own limits are the image of the input range,
// v in [f(u_min), f(u_max)] (InnerLimits).
//
// [1] G. Tao, P. V. Kokotovic, Adaptive Control of Systems with Actuator and
//     Sensor Nonlinearities, Wiley, 1996.
// [2] E.-W. Bai, "An optimal two-stage identification algorithm for
//     Hammerstein-Wiener nonlinear systems", Automatica 34 (1998) 333-338
//     (the plant structure).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "pneumid/control/controller.hpp"
#include "pneumid/models/static_map.hpp"
#include "pneumid/plant/actuator.hpp"

namespace pneumid {

/// The limits of the inner controller's input v = f(u) for input limits
/// `limits` on u: v in [min, max] of f over [u_min, u_max] (clipped to the
/// map's input range), and a change per sample of du_max times the map's
/// steepest slope (so that the u-rate limit, applied after the inverse, is
/// never looser than this one). @throws InvalidArgument for a map that is
/// not monotone or invalid limits.
InputLimits InnerLimits(const StaticMap& map, const InputLimits& limits);

/// A linear controller designed on G driving a Hammerstein plant through f^-1 (file comment).
class InverseMapController : public Controller {
 public:
  /// `inner` designed on the linear part G, with limits InnerLimits(map,
  /// limits) or looser; `limits` the actuator's limits on u.
  /// @throws InvalidArgument for a null controller, a map that is not
  /// monotone (naming where it turns) or constant, or invalid limits.
  InverseMapController(std::unique_ptr<Controller> inner, StaticMap map,
                       const InputLimits& limits = {});

  double Ts() const override { return inner_->Ts(); }
  /// The inner controller's description + " with inverse map (N knots, u in
  /// [a, b])".
  std::string Describe() const override;
  /// Calls visitor.Visit(*this).
  void Accept(ControllerVisitor& visitor) const override { visitor.Visit(*this); }

  const Controller& inner() const { return *inner_; }  ///< The controller designed on G.
  const StaticMap& map() const { return map_; }        ///< The actuator's static map f (u -> v).
  /// The actuator's limits on u.
  const InputLimits& limits() const { return limits_; }
  /// v of the last Update() (the inner controller's request).
  double last_virtual_input() const { return v_; }

 protected:
  /// The inner controller at rest at v0 = f(u0), y0.
  void DoReset(double u0, double y0) override;
  /// u = clip(f^-1(inner.Update(r, y))). Allocates no memory.
  double DoUpdate(double setpoint, double measurement) override;
  /// The input applied after the last Update(): the inner controller takes
  /// f(u). Allocates no memory.
  void DoApplied(double u) override;

 private:
  std::unique_ptr<Controller> inner_;
  StaticMap map_;
  InputLimits limits_;
  double u_prev_ = 0.0;
  double v_ = 0.0;
};

/// A linear controller on the linear part of a Wiener plant y = g(x),
/// x = G u (an identified Wiener or Hammerstein-Wiener model): the set point
/// and the measurement go through the inverse of the output map g,
///   u_k = inner.Update(g^-1(r_k), g^-1(y_k)),
/// so that the inner controller, designed on G, sees x. g^-1 inverts the
/// monotone envelope of g (the running maximum of its knot values: a fitted
/// map can dip where the output hardly moves); beyond g's range the inverse
/// holds the end of its input range. The input and its limits are the
/// inner controller's.
class OutputMapController : public Controller {
 public:
  /// @throws InvalidArgument for a null controller or a map that does not
  /// increase anywhere.
  OutputMapController(std::unique_ptr<Controller> inner, const StaticMap& output_map);

  double Ts() const override { return inner_->Ts(); }
  /// The inner controller's description + " on the inverse output map (N knots)".
  std::string Describe() const override;
  /// Calls visitor.Visit(*this).
  void Accept(ControllerVisitor& visitor) const override { visitor.Visit(*this); }

  const Controller& inner() const { return *inner_; }  ///< The controller designed on G.
  /// The monotone envelope of the output map that is inverted.
  const StaticMap& map() const { return map_; }

 protected:
  void DoReset(double u0, double y0) override;
  /// Allocates no memory.
  double DoUpdate(double setpoint, double measurement) override;
  void DoApplied(double u) override { inner_->Applied(u); }

 private:
  std::unique_ptr<Controller> inner_;
  StaticMap map_;
};

/// The map a controller inverts: `f` itself when it is monotone; else, when
/// it dips by at most `tolerance` of its range after rising (a fitted map in
/// a dead band or a saturation, where the output hardly moves, or between
/// closely spaced knots, where it wiggles by its noise), its monotone
/// envelope (MonotoneEnvelope).
/// @throws InvalidArgument for a map that falls by more (the message gives
/// the drop).
StaticMap InvertibleInputMap(const StaticMap& f, double tolerance = 0.05);

/// The map an actuator with input gaps realises on average: inside each gap
/// (lo, hi) the input is modulated between lo and hi (DutyModulator), so the
/// mean of f over a modulation cycle is the chord (1 - a) f(lo) + a f(hi)
/// at the mean input (1 - a) lo + a hi. The knots strictly inside a gap are
/// replaced by knots at its ends (f there by its extrapolation when an end
/// lies beyond the knots). `f` itself without gaps.
StaticMap MapThroughGaps(const StaticMap& f, const std::vector<InputGap>& gaps);

/// The running maximum of a map's knot values (non-decreasing), as the
/// inverses of fitted maps use it.
/// @throws InvalidArgument naming `what` when the envelope is constant.
StaticMap MonotoneEnvelope(const StaticMap& f, const std::string& what);

}  // namespace pneumid
