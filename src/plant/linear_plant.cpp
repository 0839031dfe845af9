// Linear model as a plant (see include/pneumid/plant/linear_plant.hpp).
#include "pneumid/plant/linear_plant.hpp"

#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/lti/conversion.hpp"

namespace pneumid {

LinearPlant::LinearPlant(const TransferFunction& model, double Ts, double noise_sigma,
                         std::uint64_t seed, std::string name)
    : Ts_(Ts), noise_(noise_sigma, seed), name_(std::move(name)) {
  PNEUMID_CHECK(Ts > 0.0 && std::isfinite(Ts), "sample time must be positive, got Ts = {}", Ts);
  if (model.IsContinuous()) {
    model_ = C2D(model, Ts, DiscretizationMethod::kZoh);
  } else {
    PNEUMID_CHECK(std::abs(model.Ts() - Ts) <= 1e-9 * Ts,
                  "discrete model has Ts = {} s but the plant runs at Ts = {} s; resample the "
                  "model or pass --Ts {}",
                  model.Ts(), Ts, model.Ts());
    model_ = model;
  }
  b_.assign(model_.num().data(), model_.num().data() + model_.num().size());
  a_.assign(model_.den().data(), model_.den().data() + model_.den().size());
  while (a_.size() > 1 && a_.back() == 0.0) a_.pop_back();
  while (b_.size() > 1 && b_.back() == 0.0) b_.pop_back();
  PNEUMID_CHECK(!a_.empty() && a_[0] != 0.0,
                "model denominator must have a non-zero leading coefficient a0: {}",
                model_.ToString());
  delay_ = model_.DelaySamples();
  Reset();
}

void LinearPlant::Reset() {
  noise_.Reset();
  k_ = 0;
  load_disturbance_ = 0.0;
  u_.assign(b_.size() + static_cast<std::size_t>(delay_) + 1, 0.0);
  y_.assign(a_.size() + 1, 0.0);
}

double LinearPlant::Measure() { return y_.front() + load_disturbance_ + noise_.value(); }

void LinearPlant::Advance(double u) {
  PNEUMID_CHECK(std::isfinite(u), "plant input must be finite, got {}", u);
  // A direct feedthrough (no delay, b0 != 0): y_k was measured before u_k was
  // applied, with the input then held, u_{k-1} (the output's jump by b0
  // (u_k - u_{k-1}) comes after the sample); the model's own output at k,
  // which the recursion needs, holds u_k. The b0 term was once taken as
  // b0 u_k in y_{k+1} and never corrected: (s + 1)/(s + 2) ran as 0.09
  // z^-1 / (1 - 0.82 z^-1), a slow rise to 0.5 instead of a jump to 1.
  if (delay_ == 0 && b_[0] != 0.0) y_.front() += b_[0] / a_[0] * (u - u_.front());
  u_.push_front(u);  // now u_[m] = u_{k-m}, and y_{k+1} is computed
  u_.pop_back();
  double acc = 0.0;
  for (std::size_t i = 0; i < b_.size(); ++i) {
    // u_{k+1-i-d}: index i + d - 1 in u_; the not yet known u_{k+1} is held at u_k.
    const long long m = static_cast<long long>(i) + delay_ - 1;
    acc += b_[i] * u_[static_cast<std::size_t>(m < 0 ? 0 : m)];
  }
  for (std::size_t j = 1; j < a_.size(); ++j) acc -= a_[j] * y_[j - 1];
  y_.push_front(acc / a_[0]);
  y_.pop_back();
  ++k_;
  noise_.Next();
}

std::map<std::string, double> LinearPlant::Extras() const { return {{"y_true", y_.front()}}; }

std::string LinearPlant::Describe() const {
  return fmt::format(
      "{}linear model {} (Ts = {:g} s{})", name_.empty() ? "" : name_ + ": ", model_.ToString(5),
      Ts_,
      noise_.sigma() > 0.0 ? fmt::format(", output noise sigma {:g}", noise_.sigma()) : std::string());
}

}  // namespace pneumid
