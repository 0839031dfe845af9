// Measurement noise of a simulated plant, repeatable by its seed.
//
// Each sample's noise is sigma * w_k, w_k ~ N(0, 1) drawn from a
// std::mt19937_64 seeded with `seed`: w_0 at Reset, w_{k+1} at each Next. The
// same seed gives the same sequence after every Reset, so a closed loop run
// twice on one plant sees the same noise (LinearPlant, MappedPlant).
#pragma once

#include <cstdint>
#include <random>

namespace pneumid {

/// Gaussian noise, one draw per sample, repeatable by seed.
class SeededNoise {
 public:
  /// `sigma`: standard deviation (0: no noise, no draws); `seed` of the draws.
  /// @throws InvalidArgument unless sigma is finite and >= 0.
  explicit SeededNoise(double sigma = 0.0, std::uint64_t seed = 1);

  /// Restarts the sequence: value() is then sigma * w_0.
  void Reset();
  /// The next sample: value() becomes sigma * w_{k+1}.
  void Next();
  /// This sample's noise.
  double value() const { return value_; }
  /// The standard deviation it was made with.
  double sigma() const { return sigma_; }

 private:
  double Draw();

  double sigma_;
  std::uint64_t seed_;
  double value_ = 0.0;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace pneumid
