// Measurement noise repeatable by seed (see
// include/pneumid/plant/seeded_noise.hpp).
#include "pneumid/plant/seeded_noise.hpp"

#include <cmath>

#include "pneumid/common/check.hpp"

namespace pneumid {

SeededNoise::SeededNoise(double sigma, std::uint64_t seed) : sigma_(sigma), seed_(seed) {
  PNEUMID_CHECK(sigma >= 0.0 && std::isfinite(sigma),
                "output noise standard deviation must be >= 0, got {}", sigma);
  Reset();
}

double SeededNoise::Draw() { return sigma_ > 0.0 ? sigma_ * normal_(rng_) : 0.0; }

void SeededNoise::Reset() {
  rng_.seed(seed_);
  normal_.reset();
  value_ = Draw();
}

void SeededNoise::Next() { value_ = Draw(); }

}  // namespace pneumid
