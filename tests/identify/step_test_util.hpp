// Helpers shared by the step-response identification tests.
#pragma once

#include <random>
#include <string>

#include <Eigen/Core>

#include "pneumid/data/dataset.hpp"
#include "pneumid/data/load.hpp"
#include "pneumid/lti/response.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid::testing {

/// Step test of model g: `pre` samples at u0, then u1, N samples in all, output
/// = lsim(g, u - u0) + y0 + white noise of std `noise` (seeded).
inline Dataset MakeStepData(const TransferFunction& g, double Ts, int pre, int N, double u0,
                            double u1, double noise = 0.0, unsigned seed = 1, double y0 = 0.0) {
  Eigen::VectorXd u = Eigen::VectorXd::Constant(N, u0);
  u.tail(N - pre).setConstant(u1);
  Eigen::VectorXd y = Lsim(g, (u.array() - u0).matrix(), Ts);
  y.array() += y0;
  if (noise > 0.0) {
    std::mt19937 gen(seed);
    std::normal_distribution<double> dist(0.0, noise);
    for (Eigen::Index k = 0; k < N; ++k) y[k] += dist(gen);
  }
  return Dataset::FromUniform(Ts, u, y);
}

/// A recorded synthetic step test of tests/identify/data (gen_synthetic_steps.py).
inline Dataset LoadSynthetic(const std::string& name, bool noise_free = false) {
  LoadOptions o;
  o.output_columns = {noise_free ? "y_true" : "y"};
  return LoadDataset(std::string(PNEUMID_SOURCE_DIR) + "/tests/identify/data/" + name + ".csv", o);
}

}  // namespace pneumid::testing
