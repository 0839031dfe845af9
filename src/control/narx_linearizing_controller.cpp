#include "pneumid/control/narx_linearizing_controller.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/control/inverse_map_controller.hpp"

namespace pneumid {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The input range the model's default time constant and the inner limits use.
bool InputRange(const std::optional<StaticMap>& map, const InputLimits& limits, double* lo,
                double* hi) {
  *lo = limits.u_min;
  *hi = limits.u_max;
  if (map) {
    *lo = std::isfinite(*lo) ? std::clamp(*lo, map->u_min(), map->u_max()) : map->u_min();
    *hi = std::isfinite(*hi) ? std::clamp(*hi, map->u_min(), map->u_max()) : map->u_max();
  }
  return std::isfinite(*lo) && std::isfinite(*hi) && *hi > *lo;
}

}  // namespace

InputAffineNarx::InputAffineNarx(const NarxModel& narx, std::optional<StaticMap> input_map)
    : y_scale_(narx.y_scale), Ts_(narx.Ts), map_(std::move(input_map)) {
  PNEUMID_CHECK(narx.ny == 1 && narx.nu == 1 && narx.nk == 1,
                "a controller on a NARX model needs a first-order input-affine model (ny = nu "
                "= nk = 1, as -m affine-narx identifies), got ny = {}, nu = {}, nk = {}",
                narx.ny, narx.nu, narx.nk);
  PNEUMID_CHECK(narx.terms.size() == narx.theta.size() && !narx.terms.empty(),
                "the NARX model has {} terms and {} coefficients", narx.terms.size(),
                narx.theta.size());
  PNEUMID_CHECK(
      narx.u_scale != 0.0 && narx.y_scale != 0.0 && std::isfinite(narx.Ts) && narx.Ts > 0.0,
      "the NARX model's scales and Ts must be nonzero, got u_scale {}, y_scale {}, "
      "Ts {}",
      narx.u_scale, narx.y_scale, narx.Ts);
  for (std::size_t i = 0; i < narx.terms.size(); ++i) {
    const NarxTerm& t = narx.terms[i];
    const auto k = static_cast<std::size_t>(std::count(t.begin(), t.end(), 0));
    const auto m = t.size() - k;
    PNEUMID_CHECK(m <= 1,
                  "a controller on a NARX model needs a model affine in the input; the term "
                  "'{}' holds the input {} times",
                  narx.TermName(t), m);
    if (drift_.size() <= k) drift_.resize(k + 1, 0.0);
    if (gain_.size() <= k) gain_.resize(k + 1, 0.0);
    // (u - u_offset) / u_scale: the offset part drifts, the rest scales u.
    if (m == 0) {
      drift_[k] += narx.theta[i];
    } else {
      drift_[k] -= narx.theta[i] * narx.u_offset / narx.u_scale;
      gain_[k] += narx.theta[i] / narx.u_scale;
    }
  }
  PNEUMID_CHECK(std::any_of(gain_.begin(), gain_.end(), [](double g) { return g != 0.0; }),
                "the NARX model has no input term: the input does not move its output");
  if (map_) envelope_ = MonotoneEnvelope(*map_, "NARX model's input map");
}

double InputAffineNarx::Poly(const std::vector<double>& c, double y) const {
  const double z = y / y_scale_;
  double s = 0.0;
  for (std::size_t k = c.size(); k-- > 0;) s = s * z + c[k];
  return y_scale_ * s;
}

double InputAffineNarx::Drift(double y) const { return Poly(drift_, y); }
double InputAffineNarx::Gain(double y) const { return Poly(gain_, y); }
double InputAffineNarx::Map(double u) const { return map_ ? map_->Evaluate(u) : u; }
double InputAffineNarx::InverseMap(double v) const { return envelope_ ? envelope_->Inverse(v) : v; }

double InputAffineNarx::SteadyOutput(double u, double y0) const {
  const double v = Map(u);
  double y = y0;
  for (int i = 0; i < 100000; ++i) {
    const double next = Drift(y) + Gain(y) * v;
    if (!std::isfinite(next)) return std::numeric_limits<double>::quiet_NaN();
    if (std::abs(next - y) <= 1e-10 * (1.0 + std::abs(y))) return next;
    y = next;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

double InputAffineNarx::TypicalTimeConstant(double u_min, double u_max) const {
  std::vector<double> taus;
  double y = 0.0;
  for (int i = 0; i <= 20; ++i) {
    const double u = u_min + (u_max - u_min) * i / 20.0;
    const double ys = SteadyOutput(u, y);
    if (!std::isfinite(ys)) continue;
    y = ys;
    const double v = Map(u), h = 1e-6 * std::max(1.0, std::abs(ys));
    const double pole =
        (Drift(ys + h) + Gain(ys + h) * v - Drift(ys - h) - Gain(ys - h) * v) / (2.0 * h);
    if (pole > 0.0 && pole < 1.0) taus.push_back(-Ts_ / std::log(pole));
  }
  if (taus.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(taus.begin(), taus.end());
  const std::size_t n = taus.size();
  return n % 2 ? taus[n / 2] : 0.5 * (taus[n / 2 - 1] + taus[n / 2]);
}

std::string InputAffineNarx::Describe() const {
  return fmt::format("input-affine NARX (degree {}{})", drift_.size() - 1,
                     map_ ? fmt::format(", input map of {} knots", map_->size()) : std::string());
}

bool NarxLinearizingOptions::IsValid(std::string* error) const {
  if (std::isfinite(time_constant) || std::isnan(time_constant)) return true;
  if (error) *error = fmt::format("time_constant must be finite, got {}", time_constant);
  return false;
}

double ReferenceTimeConstant(const InputAffineNarx& model, const InputLimits& limits,
                             const NarxLinearizingOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "{}", error);
  if (options.time_constant > 0.0) return options.time_constant;
  double lo = 0.0, hi = 0.0;
  PNEUMID_CHECK(InputRange(model.map(), limits, &lo, &hi),
                "the time constant of the linearized loop follows from the input range, but "
                "the input limits [{}, {}] are not a finite range",
                limits.u_min, limits.u_max);
  const double tau = model.TypicalTimeConstant(lo, hi);
  PNEUMID_CHECK(std::isfinite(tau) && tau > 0.0,
                "the {} has no stable steady state for inputs in [{:g}, {:g}]: no time constant "
                "for the linearized loop",
                model.Describe(), lo, hi);
  return tau;
}

InputLimits NarxInnerLimits(const InputAffineNarx& model, const InputLimits& limits) {
  std::string error;
  PNEUMID_CHECK(limits.IsValid(&error), "invalid input limits: {}", error);
  InputLimits w;
  double lo = 0.0, hi = 0.0;
  if (!InputRange(model.map(), limits, &lo, &hi)) return w;
  const double a = model.SteadyOutput(lo), b = model.SteadyOutput(hi, a);
  if (std::isfinite(a) && std::isfinite(b) && a != b) {
    w.u_min = std::min(a, b);
    w.u_max = std::max(a, b);
  }
  return w;
}

NarxLinearizingController::NarxLinearizingController(std::unique_ptr<Controller> inner,
                                                     InputAffineNarx model, double time_constant,
                                                     const InputLimits& limits)
    : inner_(std::move(inner)), model_(std::move(model)), tau_(time_constant), limits_(limits) {
  PNEUMID_CHECK(inner_ != nullptr, "NarxLinearizingController needs a controller, got null");
  PNEUMID_CHECK(std::abs(inner_->Ts() - model_.Ts()) <= 1e-9 * model_.Ts(),
                "the controller's sample time {} s differs from the NARX model's {} s",
                inner_->Ts(), model_.Ts());
  PNEUMID_CHECK(std::isfinite(tau_) && tau_ > 0.0,
                "the time constant of the linearized loop must be positive, got {}", tau_);
  std::string error;
  PNEUMID_CHECK(limits_.IsValid(&error), "invalid input limits: {}", error);
  p_ = std::exp(-model_.Ts() / tau_);
  Reset();
}

void NarxLinearizingController::DoReset(double u0, double y0) {
  u_prev_ = u0;
  y_last_ = y0;
  w_ = y0;  // at rest the reference model's input equals its output
  inner_->Reset(w_, y0);
}

double NarxLinearizingController::AppliedW(double u) const {
  return (model_.Drift(y_last_) + model_.Gain(y_last_) * model_.Map(u) - p_ * y_last_) / (1.0 - p_);
}

double NarxLinearizingController::DoUpdate(double setpoint, double measurement) {
  y_last_ = measurement;
  w_ = inner_->Update(setpoint, measurement);
  double u_target = u_prev_;
  if (std::isfinite(w_) && std::isfinite(measurement)) {
    const double target = p_ * measurement + (1.0 - p_) * w_;
    const double drift = model_.Drift(measurement), gain = model_.Gain(measurement);
    if (std::abs(gain) > 1e-12 * (1.0 + std::abs(drift))) {
      u_target = model_.InverseMap((target - drift) / gain);
    } else {  // the input does not act here: push towards the target
      u_target = target > drift ? limits_.u_max : limits_.u_min;
      if (!std::isfinite(u_target)) u_target = u_prev_;
    }
  }
  const double u = limits_.Clip(u_target, u_prev_);
  const double w_applied = AppliedW(u);
  if (std::isfinite(w_applied) && std::abs(w_applied - w_) > 1e-12 * (1.0 + std::abs(w_)))
    inner_->Applied(w_applied);
  u_prev_ = u;
  return u;
}

void NarxLinearizingController::DoApplied(double u) {
  if (u == u_prev_ || !std::isfinite(u)) return;
  u_prev_ = u;
  const double w = AppliedW(u);
  if (std::isfinite(w)) inner_->Applied(w);
}

std::string NarxLinearizingController::Describe() const {
  return fmt::format("{} behind a NARX linearization (tau = {:.4g} s)", inner_->Describe(), tau_);
}

}  // namespace pneumid
