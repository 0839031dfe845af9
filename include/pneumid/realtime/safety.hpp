// Safety layer of the real-time loop, independent of the controller.
//
// Every sample the loop
//   1. checks the measurement (I/O status, NaN, range, frozen sensor),
//   2. lets the controller compute u,
//   3. clamps u to [u_min, u_max] and limits its rate to |du/dt| <= rate_max,
//   4. counts deadline overruns.
// Any fault ends the run: the actuator goes to the configured safe state (hold
// or release, which the backend's plant names and explains, plant/actuator.hpp:
// for the IPA both valves closed, or the exhaust open), the reason is logged,
// the log is flushed and the program exits non-zero.
#pragma once

#include <cstdint>
#include <string>

#include "pneumid/plant/actuator.hpp"

namespace pneumid {

/// What the actuator is driven to on a fault or stop (plant/actuator.hpp).
enum class SafeState {
  kHold = 0,     ///< stop acting, keep the plant's state (IPA: valves closed, pressure held)
  kRelease = 1,  ///< drive the actuator to rest (IPA: exhaust open, the chamber vents)
};
/// "hold" / "release".
const char* ToString(SafeState s);
/// Inverse of ToString; the IPA's names "valves-closed" (hold) and
/// "exhaust-open" (release) are accepted too.
/// @throws InvalidArgument listing the accepted names.
SafeState SafeStateFromString(const std::string& name);
/// The actuator's name of a safe state, e.g. "valves-closed" for hold on the IPA.
const std::string& SafeStateName(const Actuator& actuator, SafeState s);
/// The actuator's explanation of a safe state.
const std::string& SafeStateMeaning(const Actuator& actuator, SafeState s);

/// Why a run ended abnormally (kNone: no fault).
enum class Fault : std::uint8_t {
  kNone = 0,
  kSensorNaN,         ///< measurement not finite
  kSensorOutOfRange,  ///< measurement outside [y_min, y_max] or ADC rail
  kSensorFrozen,      ///< measurement unchanged for frozen_samples samples
  kIoError,           ///< backend read/write failed
  kTimeout,           ///< backend (plant server) stopped answering
  kDeadlineOverruns,  ///< more than max_overruns deadline overruns
  kControllerError,   ///< controller returned a non-finite output
};
/// "none", "sensor-nan", "sensor-out-of-range", "sensor-frozen", "io-error", "timeout",
/// "deadline-overruns", "controller-error". Static strings, safe on the loop thread.
const char* ToString(Fault f);
/// Inverse of ToString. @throws InvalidArgument listing the accepted names.
Fault FaultFromString(const std::string& name);

/// Status of one backend read or write.
enum class IoStatus : std::uint8_t {
  kOk = 0,
  kStale,       ///< no new sample this period (e.g. a late UDP reply); last value repeated
  kOutOfRange,  ///< ADC at its rail / converter reported out of range
  kError,       ///< the call failed
  kTimeout,     ///< too many consecutive stale samples
};
const char* ToString(IoStatus s);  ///< "ok", "stale", "out-of-range", "error", "timeout"

/// Limits and fault detection of the SafetyMonitor (input and output in the actuator's
/// units: duty % and force N for the IPA).
struct SafetyOptions {
  /// Output clamp (input units of the actuator). Default 0..100, the range of
  /// a duty cycle in % (the IPA's input, IpaActuator()).
  double u_min = 0.0;
  double u_max = 100.0;  ///< upper end of the output clamp, > u_min (IPA: 100 % duty)
  /// Maximum output rate (input units per second; 0 or infinity disables). Default: disabled.
  double rate_max = 0.0;
  double y_min = -1e300;  ///< measurement range (output units, e.g. N); outside -> fault
  double y_max = 1e300;   ///< upper end of the measurement range, > y_min
  /// Fault when the measurement stays within frozen_tolerance of the same value for this
  /// many consecutive samples (0 disables; default 0 because a noise-free simulator
  /// legitimately settles to a constant).
  int frozen_samples = 0;
  double frozen_tolerance = 0.0;  ///< output units
  /// Fault when the number of deadline overruns exceeds this (negative: never). Default 10.
  int max_overruns = 10;
  SafeState safe_state = SafeState::kHold;  ///< default: hold (IPA: both valves closed)

  /// True for finite u_min < u_max, rate_max >= 0, y_min < y_max, frozen_samples >= 0 and
  /// frozen_tolerance >= 0; otherwise false with the reason in *error (when not null).
  bool IsValid(std::string* error) const;
};

/// Stateful checks; all methods are allocation-free and meant for the loop thread.
class SafetyMonitor {
 public:
  /// @throws InvalidArgument when options are invalid (message from IsValid).
  explicit SafetyMonitor(const SafetyOptions& options);
  const SafetyOptions& options() const { return options_; }  ///< as given at construction

  /// Back to the initial state; `u0` is the output the rate limiter starts from.
  void Reset(double u0 = 0.0) noexcept;
  /// Checks one measurement and its I/O status; returns the fault, or kNone.
  Fault CheckMeasurement(IoStatus status, double y) noexcept;
  /// Clamps and rate-limits a controller output for a period of `dt` seconds.
  /// Sets *flags bits: 1 = clamped, 2 = rate limited. A non-finite u is returned as is.
  double LimitOutput(double u, double dt, unsigned* flags) noexcept;
  /// Counts one deadline overrun; returns kDeadlineOverruns once the count exceeds
  /// max_overruns.
  Fault OnOverrun() noexcept;
  std::int64_t overruns() const { return overruns_; }  ///< overruns counted since Reset

 private:
  SafetyOptions options_;
  double last_u_ = 0.0;
  double frozen_ref_ = 0.0;
  int frozen_count_ = 0;
  bool have_ref_ = false;
  std::int64_t overruns_ = 0;
};

}  // namespace pneumid
