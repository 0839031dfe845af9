// A linear model used as a plant (digital twin): any TransferFunction, run as
// a difference equation at the plant's sample time, with optional white output
// noise (seeded) and the load disturbance of the Plant interface.
//
// Continuous models are discretized exactly for a zero-order-hold input
// (C2D zoh, delay included, see pneumid/lti/conversion.hpp); discrete models
// must have the plant's sample time. With A(q) y = B(q) q^-d u:
//   y_k = (sum_i b_i u_{k-i-d} - sum_{j>=1} a_j y_{k-j}) / a_0,   starting at rest,
//   y_meas,k = y_k + load disturbance + e_k,   e_k ~ N(0, sigma^2).
// Per the Plant protocol y_k is measured before u_k is applied; a direct
// feedthrough term b_0 u_k (d = 0) therefore uses the input held at that time,
// u_{k-1}, in the measurement (the jump b_0 (u_k - u_{k-1}) comes after the
// sample), while the recursion runs on the model's own y_k with u_k.
// Strictly proper models (all of the paper's) are exact and equal Lsim
// (pneumid/lti/response.hpp).
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "pneumid/lti/transfer_function.hpp"
#include "pneumid/plant/plant.hpp"
#include "pneumid/plant/seeded_noise.hpp"

namespace pneumid {

/// A TransferFunction run as a sampled plant with seeded output noise (see above).
class LinearPlant final : public Plant {
 public:
  /// `noise_sigma`: standard deviation of the output noise in output units.
  /// @throws InvalidArgument when Ts <= 0, a discrete model's Ts differs from
  ///         Ts, or noise_sigma < 0.
  LinearPlant(const TransferFunction& model, double Ts, double noise_sigma = 0.0,
              std::uint64_t seed = 1, std::string name = "");

  void Reset() override;
  double Measure() override;
  void Advance(double u) override;
  double Ts() const override { return Ts_; }
  double time() const override { return static_cast<double>(k_) * Ts_; }
  /// "y_true" (noise-free output, same unit as the output).
  std::map<std::string, double> Extras() const override;
  std::string Describe() const override;

  /// The discrete model at Ts that is simulated.
  const TransferFunction& model() const { return model_; }
  /// Noise-free output now.
  double output() const { return y_.front(); }

 private:
  TransferFunction model_;
  double Ts_;
  SeededNoise noise_;  ///< the measurement noise, drawn per sample
  std::string name_;
  std::vector<double> b_, a_;  // ascending powers of z^-1, a_[0] != 0
  int delay_ = 0;
  std::deque<double> u_;  // u_[m] = u_{k-1-m}
  std::deque<double> y_;  // y_[m] = y_{k-m}
  long long k_ = 0;
};

}  // namespace pneumid
