// Plant: anything the toolkit can drive with an input and read an output from,
// sampled at a fixed period. The nonlinear IPA simulator, linear models used as
// digital twins and (in the real-time area) hardware backends share it, so that
// identification experiments, closed-loop evaluation and the real-time loop run
// against any of them.
//
// Protocol per sample k (period Ts):
//   y_k = plant.Measure();        // what the sensor reads now
//   plant.Advance(u_k);           // apply u_k (zero-order hold) for one period
#pragma once

#include <map>
#include <memory>
#include <string>

namespace pneumid {

struct Actuator;  // plant/actuator.hpp

/// A sampled plant: Measure() the output, then Advance(u) one period (protocol above).
class Plant {
 public:
  virtual ~Plant() = default;

  /// Back to the initial state (and the noise generators to their seed).
  virtual void Reset() = 0;
  /// Whether Reset() returns the plant to its initial state: true for
  /// simulated plants; false for a real one behind a backend, whose Reset()
  /// only restarts the clock (realtime/io_plant.hpp).
  virtual bool can_reset() const { return true; }
  /// Measured output at the current time (sensor model included: noise,
  /// quantization, transport delay).
  virtual double Measure() = 0;
  /// Holds input u for one sample period and advances time by Ts().
  virtual void Advance(double u) = 0;
  /// Adds a load disturbance acting on the output (in output units), held until changed.
  virtual void SetLoadDisturbance(double d) { load_disturbance_ = d; }
  /// Sample period in seconds.
  virtual double Ts() const = 0;
  /// Current time in seconds since Reset().
  virtual double time() const = 0;
  /// Extra signals worth logging (e.g. chamber pressures), by name with unit in brackets,
  /// e.g. {"p_b [Pa]": 3.1e5}. Empty by default.
  virtual std::map<std::string, double> Extras() const { return {}; }
  /// Short description for logs, e.g. "ipa (force mode, pwm 50 Hz)".
  virtual std::string Describe() const = 0;
  /// What drives the plant: its input and output signals and ranges, the
  /// inputs it cannot hold, whether its output integrates its input, and its
  /// safe states (plant/actuator.hpp). The generic description (u, y without
  /// units, unbounded, hold/release) unless the plant knows better.
  virtual Actuator actuator() const;

 protected:
  double load_disturbance_ = 0.0;
};

}  // namespace pneumid
