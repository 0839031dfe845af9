// Sigma-delta modulation of an actuator's input across its dead bands.
//
// A PWM valve cannot hold every duty: a command pulse shorter than the
// valve's minimum width does not open it, so on the IPA (300 Hz PWM, 0.5 ms
// minimum pulse) duties in (0, 15) % act as 0 % (the inlet stays closed) and
// duties in (85, 100) % as 100 % (the exhaust stays closed). Forces between
// the map's values at 85 % and 100 % then have no steady duty, and a loop
// asked for one cycles around it (a limit cycle of several newtons).
//
// The modulator makes those inputs available on average: each sample it
// adds the carried error e to the requested input v, w = v + e; when w lies
// inside a gap (lo, hi) it applies the nearer end a (lo or hi), otherwise
// a = w; and it carries e = w - a (first-order sigma-delta, error feedback;
// Norsworthy, Schreier and Temes, "Delta-Sigma Data Converters", 1997,
// ch. 1). The mean of the applied inputs follows the mean of the requests
// with an error bounded by the widest gap, and the alternation (at up to
// half the sample rate) is filtered by the chamber and the sensor.
//
// ModulatedController puts the modulator behind any controller: the inner
// controller is designed and updated as if its request v were applied.
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "pneumid/control/controller.hpp"
#include "pneumid/plant/actuator.hpp"

namespace pneumid {

/// "0:15,85:100" for the gaps (0, 15) and (85, 100); "" for none.
std::string InputGapsToString(const std::vector<InputGap>& gaps);
/// The gaps of "LO:HI[,LO:HI...]" (empty text or "none": none).
/// @throws InvalidArgument naming the item that is not LO:HI with finite LO < HI,
/// or gaps that overlap.
std::vector<InputGap> ParseInputGaps(const std::string& text);

/// First-order sigma-delta modulator over input gaps (file comment).
class DutyModulator {
 public:
  /// @throws InvalidArgument for a gap with lo >= hi, a non-finite end, or
  /// overlapping gaps.
  explicit DutyModulator(std::vector<InputGap> gaps,
                         double u_min = -std::numeric_limits<double>::infinity(),
                         double u_max = std::numeric_limits<double>::infinity());
  /// The input to apply for the request v (finite): at or beyond an end of
  /// [u_min, u_max] that end, with nothing carried; else w = v + e, then the
  /// nearer end of a gap that holds w, else w clipped to the range, and the
  /// error w - a is carried. v outside every gap and with no carried error
  /// passes unchanged.
  double Next(double v);
  /// Clears the carried error.
  void Reset() { error_ = 0.0; }
  /// The gaps, sorted by lo.
  const std::vector<InputGap>& gaps() const { return gaps_; }
  double u_min() const { return u_min_; }  ///< lowest input applied
  double u_max() const { return u_max_; }  ///< highest input applied
  /// The carried error e (input units).
  double error() const { return error_; }
  /// The widest gap: the bound on |e| and on the applied input's distance from the request.
  double max_error() const { return max_error_; }

 private:
  std::vector<InputGap> gaps_;
  double error_ = 0.0;
  double max_error_ = 0.0;  ///< the widest gap: bounds e
  double u_min_, u_max_;
};

/// A controller whose input goes through a DutyModulator (file comment).
class ModulatedController : public Controller {
 public:
  /// @throws InvalidArgument for a null controller or invalid gaps.
  /// `limits`: the actuator's input range, which the modulated input keeps.
  ModulatedController(std::unique_ptr<Controller> inner, std::vector<InputGap> gaps,
                      const InputLimits& limits = {});

  double Ts() const override { return inner_->Ts(); }
  /// The inner controller's description + " with sigma-delta modulation over
  /// the input gaps 0:15,85:100".
  std::string Describe() const override;
  void Accept(ControllerVisitor& visitor) const override {
    visitor.Visit(*this);
  }                                                    ///< Visit(*this)
  const Controller& inner() const { return *inner_; }  ///< The controller behind the modulator.
  const DutyModulator& modulator() const { return modulator_; }  ///< Its modulator.
  /// The inner controller's request of the last Update() (before modulation).
  double last_request() const { return v_; }

 protected:
  /// The inner controller and the modulator at rest (no carried error).
  void DoReset(double u0, double y0) override;
  /// u = modulator.Next(inner.Update(r, y)). Allocates no memory.
  double DoUpdate(double setpoint, double measurement) override;
  /// An input changed by the actuator's limits: the inner controller is told
  /// when it lies farther from its request than the widest gap (more than
  /// modulation explains).
  void DoApplied(double u) override;

 private:
  std::unique_ptr<Controller> inner_;
  DutyModulator modulator_;
  double v_ = 0.0;
};

}  // namespace pneumid
