#include "pneumid/control/pid.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"

namespace pneumid {

namespace {
constexpr EnumName<PidTuningRule> kPidTuningRuleNames[] = {
    {PidTuningRule::kSimc, "simc"},
    {PidTuningRule::kImc, "imc"},
};
}  // namespace

std::string ToString(PidTuningRule v) { return std::string(EnumToString(kPidTuningRuleNames, v)); }

PidTuningRule PidTuningRuleFromString(const std::string& name) {
  return EnumFromString(kPidTuningRuleNames, name, "PID tuning rule");
}

PidGains TunePid(double K, double tau, double theta, double Ts, PidTuningRule rule, double tau_c) {
  PNEUMID_CHECK(std::isfinite(K) && K != 0.0, "the model gain must be finite and nonzero, got {}",
                K);
  PNEUMID_CHECK(tau > 0.0 && std::isfinite(tau), "tau must be positive, got {}", tau);
  PNEUMID_CHECK(theta >= 0.0 && std::isfinite(theta), "theta must be >= 0, got {}", theta);
  PNEUMID_CHECK(Ts > 0.0 && std::isfinite(Ts), "Ts must be positive, got {}", Ts);
  PidGains g;
  switch (rule) {
    case PidTuningRule::kSimc: {
      const double th = theta + Ts / 2.0;  // zoh adds half a sample of delay
      const double tc = tau_c > 0.0 ? tau_c : th;
      g.Kc = tau / (K * (tc + th));
      g.Ti = std::min(tau, 4.0 * (tc + th));
      g.Td = 0.0;
      break;
    }
    case PidTuningRule::kImc: {
      const double th = theta + Ts / 2.0;
      const double tc = tau_c > 0.0 ? tau_c : std::max(0.8 * th, tau / 10.0);
      g.Kc = (2.0 * tau + th) / (K * (2.0 * tc + th));
      g.Ti = tau + th / 2.0;
      g.Td = tau * th / (2.0 * tau + th);
      break;
    }
  }
  return g;
}

bool PidOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (!std::isfinite(gains.Kc)) return fail(fmt::format("Kc must be finite, got {}", gains.Kc));
  if (!(gains.Ti > 0.0))
    return fail(fmt::format("Ti must be positive (inf = no integral), got {}", gains.Ti));
  if (!(gains.Td >= 0.0) || !std::isfinite(gains.Td))
    return fail(fmt::format("Td must be >= 0, got {}", gains.Td));
  if (!(setpoint_weight >= 0.0 && setpoint_weight <= 1.0))
    return fail(fmt::format("setpoint_weight must be in [0, 1], got {}", setpoint_weight));
  if (!(derivative_filter > 0.0))
    return fail(fmt::format("derivative_filter must be positive, got {}", derivative_filter));
  if (!(tracking_time >= 0.0))
    return fail(fmt::format("tracking_time must be >= 0, got {}", tracking_time));
  if (!std::isfinite(velocity_feedforward))
    return fail(fmt::format("velocity_feedforward must be finite, got {}", velocity_feedforward));
  std::string e;
  if (!limits.IsValid(&e)) return fail(e);
  return true;
}

PidController::PidController(double Ts, const PidOptions& options) : options_(options), Ts_(Ts) {
  std::string error;
  PNEUMID_CHECK(options_.IsValid(&error), "invalid PID options: {}", error);
  PNEUMID_CHECK(Ts > 0.0 && std::isfinite(Ts), "sample time must be positive, got Ts = {}", Ts);
  const PidGains& g = options_.gains;
  if (options_.tracking_time > 0.0) {
    Tt_ = options_.tracking_time;
  } else if (std::isfinite(g.Ti)) {
    Tt_ = g.Td > 0.0 ? std::sqrt(g.Ti * g.Td) : g.Ti / 2.0;
  } else {
    Tt_ = 0.0;
  }
  Tt_ = Tt_ > 0.0 ? std::max(Tt_, Ts_) : 0.0;  // Ts/Tt <= 1 keeps the correction stable
  Reset();
}

void PidController::DoReset(double u0, double y0) {
  // Bumpless start at rest: integral holds u0 with e = 0.
  integral_ = u0 - options_.gains.Kc * (options_.setpoint_weight - 1.0) * y0;
  derivative_ = 0.0;
  y_prev_ = y0;
  r_prev_ = y0;  // at rest on the set-point
  u_prev_ = u0;
}

double PidController::DoUpdate(double setpoint, double measurement) {
  const PidGains& g = options_.gains;
  const double e = setpoint - measurement;
  const double p = g.Kc * (options_.setpoint_weight * setpoint - measurement);
  if (g.Td > 0.0) {
    const double nts = options_.derivative_filter * Ts_;
    derivative_ = g.Td / (g.Td + nts) * derivative_ -
                  g.Kc * g.Td * options_.derivative_filter / (g.Td + nts) * (measurement - y_prev_);
  }
  const double v =
      p + integral_ + derivative_ + options_.velocity_feedforward * (setpoint - r_prev_) / Ts_;
  if (!std::isfinite(v)) return v;  // an overflow: a fault (Controller::Update)
  const double u = options_.limits.Clip(v, u_prev_);
  if (std::isfinite(g.Ti)) {
    integral_ += g.Kc * Ts_ / g.Ti * e + (Tt_ > 0.0 ? Ts_ / Tt_ * (u - v) : 0.0);
  }
  y_prev_ = measurement;
  r_prev_ = setpoint;
  u_prev_ = u;
  return u;
}

void PidController::DoApplied(double u) {
  const double delta = u - u_prev_;
  if (delta == 0.0 || !std::isfinite(delta)) return;
  // Back-calculation as for the controller's own limits: the integral
  // follows the input the actuator applied.
  if (std::isfinite(options_.gains.Ti) && Tt_ > 0.0) integral_ += Ts_ / Tt_ * delta;
  u_prev_ = u;
}

std::string PidController::Describe() const {
  std::string ff = options_.velocity_feedforward != 0.0
                       ? fmt::format(" Kff={:.4g}", options_.velocity_feedforward)
                       : "";
  if (options_.setpoint_weight != 1.0) ff += fmt::format(" b={:.4g}", options_.setpoint_weight);
  return fmt::format("pid Kc={:.4g} Ti={:.4g} Td={:.4g}{}", options_.gains.Kc, options_.gains.Ti,
                     options_.gains.Td, ff);
}

}  // namespace pneumid
