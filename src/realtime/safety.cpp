#include "pneumid/realtime/safety.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"

namespace pneumid {

namespace {
constexpr EnumName<SafeState> kSafeStateNames[] = {
    {SafeState::kHold, "hold"},
    {SafeState::kRelease, "release"},
};
}  // namespace

const char* ToString(SafeState v) { return EnumToString(kSafeStateNames, v).data(); }

SafeState SafeStateFromString(const std::string& name) {
  // The IPA's own names are accepted too: configurations and scripts for the rig use them.
  const Actuator ipa = IpaActuator();
  if (name == ipa.hold_name) return SafeState::kHold;
  if (name == ipa.release_name) return SafeState::kRelease;
  if (const std::optional<SafeState> s = EnumLookup(kSafeStateNames, name)) return *s;
  throw InvalidArgument(fmt::format("unknown safe state '{}' (valid: {}; the IPA's {}, {})",
                                    name.substr(0, 64), EnumNameList(kSafeStateNames),
                                    ipa.hold_name, ipa.release_name));
}

const std::string& SafeStateName(const Actuator& actuator, SafeState s) {
  return s == SafeState::kHold ? actuator.hold_name : actuator.release_name;
}

const std::string& SafeStateMeaning(const Actuator& actuator, SafeState s) {
  return s == SafeState::kHold ? actuator.hold_meaning : actuator.release_meaning;
}

namespace {
constexpr EnumName<Fault> kFaultNames[] = {
    {Fault::kNone, "none"},
    {Fault::kSensorNaN, "sensor-nan"},
    {Fault::kSensorOutOfRange, "sensor-out-of-range"},
    {Fault::kSensorFrozen, "sensor-frozen"},
    {Fault::kIoError, "io-error"},
    {Fault::kTimeout, "timeout"},
    {Fault::kDeadlineOverruns, "deadline-overruns"},
    {Fault::kControllerError, "controller-error"},
};
}  // namespace

const char* ToString(Fault v) { return EnumToString(kFaultNames, v).data(); }

Fault FaultFromString(const std::string& name) {
  return EnumFromString(kFaultNames, name, "fault");
}

namespace {
constexpr EnumName<IoStatus> kIoStatusNames[] = {
    {IoStatus::kOk, "ok"},
    {IoStatus::kStale, "stale"},
    {IoStatus::kOutOfRange, "out-of-range"},
    {IoStatus::kError, "error"},
    {IoStatus::kTimeout, "timeout"},
};
}  // namespace

const char* ToString(IoStatus v) { return EnumToString(kIoStatusNames, v).data(); }

bool SafetyOptions::IsValid(std::string* error) const {
  auto fail = [error](std::string msg) {
    if (error) *error = std::move(msg);
    return false;
  };
  if (!std::isfinite(u_min) || !std::isfinite(u_max) || !(u_min < u_max))
    return fail(fmt::format("output clamp needs finite u_min < u_max, got [{}, {}]", u_min, u_max));
  if (std::isnan(rate_max) || rate_max < 0.0)
    return fail(fmt::format("rate_max must be >= 0 (0 disables), got {}", rate_max));
  if (std::isnan(y_min) || std::isnan(y_max) || !(y_min < y_max))
    return fail(fmt::format("measurement range needs y_min < y_max, got [{}, {}]", y_min, y_max));
  if (frozen_samples < 0)
    return fail(fmt::format("frozen_samples must be >= 0 (0 disables), got {}", frozen_samples));
  if (std::isnan(frozen_tolerance) || frozen_tolerance < 0.0)
    return fail(fmt::format("frozen_tolerance must be >= 0, got {}", frozen_tolerance));
  return true;
}

SafetyMonitor::SafetyMonitor(const SafetyOptions& options) : options_(options) {
  std::string error;
  PNEUMID_CHECK(options_.IsValid(&error), "invalid safety options: {}", error);
}

void SafetyMonitor::Reset(double u0) noexcept {
  last_u_ = std::clamp(u0, options_.u_min, options_.u_max);
  frozen_count_ = 0;
  have_ref_ = false;
  overruns_ = 0;
}

Fault SafetyMonitor::CheckMeasurement(IoStatus status, double y) noexcept {
  switch (status) {
    case IoStatus::kOk:
    case IoStatus::kStale:
      break;
    case IoStatus::kOutOfRange:
      return Fault::kSensorOutOfRange;
    case IoStatus::kError:
      return Fault::kIoError;
    case IoStatus::kTimeout:
      return Fault::kTimeout;
  }
  if (!std::isfinite(y)) return Fault::kSensorNaN;
  if (y < options_.y_min || y > options_.y_max) return Fault::kSensorOutOfRange;
  if (options_.frozen_samples > 0 && status == IoStatus::kOk) {
    if (have_ref_ && std::abs(y - frozen_ref_) <= options_.frozen_tolerance) {
      if (++frozen_count_ >= options_.frozen_samples) return Fault::kSensorFrozen;
    } else {
      frozen_ref_ = y;
      have_ref_ = true;
      frozen_count_ = 1;
    }
  }
  return Fault::kNone;
}

double SafetyMonitor::LimitOutput(double u, double dt, unsigned* flags) noexcept {
  unsigned f = 0;
  if (!std::isfinite(u)) {
    if (flags) *flags = f;
    return u;
  }
  double v = u;
  if (v < options_.u_min || v > options_.u_max) {
    v = std::clamp(v, options_.u_min, options_.u_max);
    f |= 1u;
  }
  if (options_.rate_max > 0.0 && std::isfinite(options_.rate_max) && dt > 0.0) {
    const double step = options_.rate_max * dt;
    if (v > last_u_ + step) {
      v = last_u_ + step;
      f |= 2u;
    } else if (v < last_u_ - step) {
      v = last_u_ - step;
      f |= 2u;
    }
  }
  last_u_ = v;
  if (flags) *flags = f;
  return v;
}

Fault SafetyMonitor::OnOverrun() noexcept {
  ++overruns_;
  if (options_.max_overruns >= 0 && overruns_ > options_.max_overruns)
    return Fault::kDeadlineOverruns;
  return Fault::kNone;
}

}  // namespace pneumid
