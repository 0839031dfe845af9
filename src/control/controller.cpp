#include "pneumid/control/controller.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"

namespace pneumid {

namespace {
constexpr EnumName<ControllerType> kControllerTypeNames[] = {
    {ControllerType::kDmc, "dmc"},
    {ControllerType::kGpc, "gpc"},
    {ControllerType::kPid, "pid"},
    {ControllerType::kMpc, "mpc"},
};

constexpr EnumName<ControllerFault> kControllerFaultNames[] = {
    {ControllerFault::kNone, "none"},
    {ControllerFault::kMeasurementNotFinite, "measurement-not-finite"},
    {ControllerFault::kMeasurementOutOfRange, "measurement-out-of-range"},
    {ControllerFault::kSetpointNotFinite, "setpoint-not-finite"},
    {ControllerFault::kOutputNotFinite, "output-not-finite"},
};
}  // namespace

std::string ToString(ControllerType v) {
  return std::string(EnumToString(kControllerTypeNames, v));
}

ControllerType ControllerTypeFromString(const std::string& name) {
  return EnumFromString(kControllerTypeNames, name, "controller");
}

std::string ToString(ControllerFault v) {
  return std::string(EnumToString(kControllerFaultNames, v));
}

ControllerFault ControllerFaultFromString(const std::string& name) {
  return EnumFromString(kControllerFaultNames, name, "controller fault");
}

bool MeasurementGuard::IsValid(std::string* error) const {
  auto fail = [&](std::string message) {
    if (error) *error = std::move(message);
    return false;
  };
  if (std::isnan(y_min) || std::isnan(y_max))
    return fail(
        fmt::format("the valid measurement range must not be NaN, got [{}, {}]", y_min, y_max));
  if (y_min > y_max)
    return fail(fmt::format("the valid measurement range needs y_min <= y_max, got [{}, {}]", y_min,
                            y_max));
  if (std::isinf(safe_input))
    return fail(fmt::format("the safe input must be finite (or NaN: hold), got {}", safe_input));
  return true;
}

ControllerFault MeasurementGuard::Check(double setpoint, double measurement) const {
  if (!std::isfinite(measurement)) return ControllerFault::kMeasurementNotFinite;
  if (measurement < y_min || measurement > y_max) return ControllerFault::kMeasurementOutOfRange;
  if (!std::isfinite(setpoint)) return ControllerFault::kSetpointNotFinite;
  return ControllerFault::kNone;
}

void Controller::Reset(double u0, double y0) {
  last_u_ = u0;
  last_y_ = y0;
  last_fault_ = ControllerFault::kNone;
  fault_count_ = 0;
  DoReset(u0, y0);
}

double Controller::Update(double setpoint, double measurement) {
  ControllerFault fault = guard_.Check(setpoint, measurement);
  if (fault == ControllerFault::kNone) {
    const double u = DoUpdate(setpoint, measurement);
    if (std::isfinite(u)) {
      last_u_ = u;
      last_y_ = measurement;
      last_fault_ = ControllerFault::kNone;
      return u;
    }
    // The law overflowed (a finite but huge measurement): its state may hold
    // the overflow, so it restarts at rest at the held input.
    fault = ControllerFault::kOutputNotFinite;
    DoReset(last_u_, last_y_);
  }
  last_fault_ = fault;
  ++fault_count_;
  if (!std::isnan(guard_.safe_input) && guard_.safe_input != last_u_) {
    last_u_ = guard_.safe_input;
    DoApplied(last_u_);
  }
  return last_u_;
}

void Controller::Applied(double u) {
  if (!std::isfinite(u)) return;
  last_u_ = u;
  DoApplied(u);
}

void Controller::SetMeasurementGuard(const MeasurementGuard& guard) {
  std::string error;
  PNEUMID_CHECK(guard.IsValid(&error), "invalid measurement guard: {}", error);
  guard_ = guard;
}

bool InputLimits::IsValid(std::string* error) const {
  if (std::isnan(u_min) || std::isnan(u_max) || std::isnan(du_max)) {
    if (error) *error = "input limits must not be NaN";
    return false;
  }
  if (u_min > u_max) {
    if (error)
      *error = fmt::format("need u_min <= u_max, got u_min = {}, u_max = {}", u_min, u_max);
    return false;
  }
  if (!(du_max > 0.0)) {
    if (error) *error = fmt::format("du_max must be positive, got {}", du_max);
    return false;
  }
  return true;
}

double InputLimits::Clip(double u, double u_prev) const {
  if (std::isfinite(du_max)) u = std::clamp(u, u_prev - du_max, u_prev + du_max);
  return std::clamp(u, u_min, u_max);
}

}  // namespace pneumid
