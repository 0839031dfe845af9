// Impulse response by correlation analysis with prewhitening (MATLAB cra [1],
// [2] sec. 6.1).
//
// With means removed, an AR model L(q) u(t) = w(t) of order n is fitted to the
// input by least squares, and both signals are filtered by L:
//   uf = L(q) u (nearly white),  yf = L(q) y.
// Since y = G u + v implies yf = G uf + L v, the impulse response follows from
// the cross-covariance with the white uf ([2] eq. 6.7):
//   g(k) = R_yf,uf(k) / R_uf(0),   k = 0 .. M,   R_xy(k) = 1/N sum_t x(t) y(t - k).
// Under g(k) = 0 the estimate has standard deviation about
// sqrt(R_yf(0) / (N R_uf(0))), giving the confidence bound z sqrt(R_yf(0) / (N R_uf(0)))
// (z = 2.5758 for 99 %). The step response is the cumulative sum of g.
//
// [1] MathWorks, System Identification Toolbox, cra,
//     https://www.mathworks.com/help/ident/ref/cra.html
// [2] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999.
#pragma once

#include <string>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "pneumid/data/dataset.hpp"

namespace pneumid {

/// Lags, prewhitening and confidence level of the correlation analysis.
struct CraOptions {
  int num_lags = 50;            ///< M, impulse-response length - 1 (>= 1, < N / 4)
  int prewhitening_order = 10;  ///< n of the AR input model (0 = no prewhitening)
  double confidence = 0.99;     ///< of the bound, in (0, 1)
  /// True when num_lags >= 1, prewhitening_order >= 0 and confidence is in (0, 1); otherwise
  /// false with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// Impulse and step response estimated by correlation analysis, with the confidence bound.
struct CraResult {
  Eigen::VectorXd lags;     ///< 0 .. M (samples)
  Eigen::VectorXd t;        ///< lags * Ts, seconds
  Eigen::VectorXd impulse;  ///< g(k), output units per (input unit * sample)
  Eigen::VectorXd step;     ///< cumulative sum of g: response to a unit step
  double bound = 0.0;       ///< confidence bound on each g(k)
  double Ts = 1.0;          ///< seconds
  /// {t, impulse, step, bound, Ts} (the lags are not written; t = lags * Ts).
  nlohmann::json ToJson() const;
};

/// Correlation analysis of y (N) against u (N) sampled at Ts seconds.
/// @throws InvalidArgument for invalid options, sizes or a constant input.
CraResult Cra(const Eigen::VectorXd& y, const Eigen::VectorXd& u, double Ts,
              const CraOptions& options = {});
/// From a data set (input/output columns given).
/// @throws DataError for non-uniform sampling or too few samples.
CraResult Cra(const Dataset& data, const CraOptions& options = {}, int input = 0, int output = 0);

}  // namespace pneumid
