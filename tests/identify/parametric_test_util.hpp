// Shared helpers of the parametric identification tests: deterministic PRBS and
// Gaussian noise, and the paper's ARX(3,3,1) model as a PolynomialModel.
#pragma once

#include <cstdint>
#include <random>

#include <Eigen/Core>

#include "pneumid/identify/parametric/parametric_model.hpp"
#include "pneumid/models/model_file.hpp"

namespace pneumid::testing {

/// Maximum-length PRBS of a 10-bit LFSR (x^10 + x^7 + 1), one bit held for
/// `clock` samples, levels low/high.
inline Eigen::VectorXd Prbs(Eigen::Index n, double low, double high, int clock = 1,
                            std::uint32_t seed = 1) {
  Eigen::VectorXd u(n);
  std::uint32_t reg = (seed & 0x3FF) ? (seed & 0x3FF) : 1;
  for (Eigen::Index k = 0; k < n; ++k) {
    if (k % clock == 0) {
      const std::uint32_t bit = ((reg >> 9) ^ (reg >> 6)) & 1u;
      reg = ((reg << 1) | bit) & 0x3FF;
    }
    u[k] = (reg & 1u) ? high : low;
  }
  return u;
}

inline Eigen::VectorXd WhiteNoise(Eigen::Index n, double sigma, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::normal_distribution<double> dist(0.0, sigma);
  Eigen::VectorXd e(n);
  for (Eigen::Index k = 0; k < n; ++k) e[k] = dist(gen);
  return e;
}

/// The paper's Eq. 5 ARX model (PaperArxModel()) as a polynomial model.
inline PolynomialModel PaperArx() {
  const TransferFunction g = PaperArxModel();
  PolynomialModel m;
  m.Ts = g.Ts();
  m.a = g.den() / g.den()[0];
  Eigen::VectorXd b = g.num() / g.den()[0];
  // Trim trailing zeros of the padded numerator, then add the delay samples.
  Eigen::Index len = b.size();
  while (len > 1 && b[len - 1] == 0.0) --len;
  const int delay = g.DelaySamples();
  Eigen::VectorXd full = Eigen::VectorXd::Zero(delay + len);
  full.tail(len) = b.head(len);
  int nk = 0;
  while (nk < full.size() && full[nk] == 0.0) ++nk;
  m.b = {full};
  m.nk = {nk};
  return m;
}

/// y = B/A u + 1/A e (equation noise, the ARX structure).
inline Eigen::VectorXd SimulateArx(const PolynomialModel& m, const Eigen::VectorXd& u,
                                   const Eigen::VectorXd& e) {
  PolynomialModel noise = m;
  noise.b = {Eigen::VectorXd::Ones(1)};
  noise.nk = {0};
  noise.f.clear();
  return Simulate(m, u) + Simulate(noise, e);
}

}  // namespace pneumid::testing
