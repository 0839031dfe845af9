// Frequency-response estimation without a model structure (MATLAB spa, etfe
// [1]; [2] sec. 6.3-6.4).
//
// Spectral analysis (Blackman-Tukey, spa): with sample covariances
// R_yu(tau) = 1/N sum_t y(t + tau) u(t) (means removed) and the Hann lag window
//   W_M(tau) = 0.5 (1 + cos(pi tau / M)),  |tau| <= M   ([2] Table 6.1),
//   Phi_yu(w) = sum_{|tau|<=M} W_M(tau) R_yu(tau) e^{-i w tau Ts}   (and Phi_u, Phi_y)
//   G(e^{i w Ts}) = Phi_yu(w) / Phi_u(w)                           ([2] eq. 6.51)
//   Phi_v(w) = Phi_y(w) - |Phi_yu(w)|^2 / Phi_u(w)                 ([2] eq. 6.52)
// on w_k = k pi / (K Ts), k = 1 .. K. M defaults to min(30, N / 10) as in MATLAB.
// The standard deviation of |G| is about sqrt(0.75 M / N * Phi_v / Phi_u) for
// the Hann window ([2] eq. 6.72, integral of W^2 = 0.75 M).
//
// Empirical transfer-function estimate (etfe): G(e^{i w_k Ts}) = Y_N(w_k) / U_N(w_k),
// the ratio of discrete Fourier transforms at w_k = 2 pi k / (N Ts) ([2] eq. 6.24);
// with `num_frequencies` > 0 the bins are grouped into that many bands and
// averaged with weights |U_N|^2 (sum Y U* / sum |U|^2, a frequency-smoothed ETFE,
// [2] eq. 6.46).
//
// [1] MathWorks, System Identification Toolbox, spa / etfe,
//     https://www.mathworks.com/help/ident/ref/spa.html
// [2] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999.
#pragma once

#include <complex>
#include <string>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "pneumid/data/dataset.hpp"

namespace pneumid {

/// Nonparametric frequency response G(e^{i w Ts}) on a grid of frequencies (spa, etfe).
struct FrequencyResponseEstimate {
  Eigen::VectorXd omega;           ///< rad/s
  Eigen::VectorXcd response;       ///< G(e^{i w Ts})
  Eigen::VectorXd magnitude;       ///< |G|
  Eigen::VectorXd phase_deg;       ///< arg G, degrees, unwrapped
  Eigen::VectorXd noise_spectrum;  ///< Phi_v (spa only; empty for etfe)
  Eigen::VectorXd magnitude_std;   ///< standard deviation of |G| (spa only)
  double Ts = 1.0;  ///< sample time of the data, seconds
  /// {omega, magnitude, phase_deg, Ts}, plus noise_spectrum and magnitude_std when present.
  nlohmann::json ToJson() const;
};

/// Lag window and frequency grid of the Blackman-Tukey estimate (Spa).
struct SpaOptions {
  int lag_window = 0;         ///< M (0 = min(30, N / 10)); must be < N
  int num_frequencies = 128;  ///< K
  /// True when lag_window >= 0 and num_frequencies >= 1; otherwise false with the reason in
  /// *error (when error is not null). M < N is checked against the data by Spa.
  bool IsValid(std::string* error) const;
};

/// Frequency resolution of the empirical transfer-function estimate (Etfe).
struct EtfeOptions {
  int num_frequencies = 0;  ///< 0 = every DFT bin 1 .. N/2; otherwise that many bands
  /// True when num_frequencies >= 0; otherwise false with the reason in *error (when error
  /// is not null).
  bool IsValid(std::string* error) const;
};

/// Blackman-Tukey spectral analysis of y against u (N samples each, Ts seconds).
/// @throws InvalidArgument for invalid options, sizes or a constant input.
FrequencyResponseEstimate Spa(const Eigen::VectorXd& y, const Eigen::VectorXd& u, double Ts,
                              const SpaOptions& options = {});
/// Spa of output column `output` against input column `input` of `data`, at its sample time.
/// @throws InvalidArgument for a column out of range, and as above; DataError for
///         non-uniform sampling.
FrequencyResponseEstimate Spa(const Dataset& data, const SpaOptions& options = {}, int input = 0,
                              int output = 0);

/// Empirical transfer-function estimate (FFT). Bins where |U| is zero are skipped.
/// @throws InvalidArgument for invalid options, sizes or a constant input.
FrequencyResponseEstimate Etfe(const Eigen::VectorXd& y, const Eigen::VectorXd& u, double Ts,
                               const EtfeOptions& options = {});
/// Etfe of output column `output` against input column `input` of `data`, at its sample
/// time. @throws InvalidArgument for a column out of range, and as above; DataError for
///         non-uniform sampling.
FrequencyResponseEstimate Etfe(const Dataset& data, const EtfeOptions& options = {}, int input = 0,
                               int output = 0);

}  // namespace pneumid
