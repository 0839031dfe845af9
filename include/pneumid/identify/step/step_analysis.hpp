// Preparation shared by every step-response (graphical) identification
// method: locate the input step, read the baseline, the final value and the
// noise level off the recorded output, and provide interpolated crossing
// times of the normalized response.
//
// Definitions (k_s = first sample at the new input level, t_s = t[k_s]; the
// input is held constant between samples, so the step acts from t_s on):
//   u0, u1     mean input before / after the step,        du = u1 - u0
//   y0         mean output over the pre-step samples (baseline)
//   y_inf      mean output over the settled tail (last `tail_fraction` of the
//              record, at least `min_tail_samples`), with standard error
//              y_inf_std = s_tail / sqrt(n_tail)
//   dy         y_inf - y0,   K = dy / du  (static gain)
//   sigma      noise standard deviation: of the pre-step samples when there are
//              at least 5 of them, otherwise of the tail around its trend line
//   r(t)       normalized response (y(t) - y0) / dy, rising from 0 to 1
// Refusals (pneumid::DataError naming the data source):
//   * the input never changes (no step), or changes more than once by more
//     than `input_tolerance` of the step (use the fit-* methods for general
//     inputs);
//   * |dy| < min_snr * sigma (step too small against the noise);
//   * the tail still drifts: a line fitted to the tail changes by more than
//     max(settle_tolerance |dy|, 3 sigma sqrt(12 / n_tail)) over the tail
//     (the second term is three standard deviations of that change under
//     white noise);
//   * a non-finite sample.
//
// Dead time ("first significant departure from the baseline"): the first
// time t_b at which r leaves the noise band b = max(band_sigmas sigma / |dy|,
// band_min_fraction) and stays out of it for `band_hold_samples` samples; a
// straight line fitted by least squares to the samples with b <= r <=
// departure_fit_upper is extrapolated back to r = 0, and the departure time
// is where it meets the baseline (clipped to [0, t_b]). For a first-order lag
// this is unbiased to within 0.6 % of the time constant; on an S-shaped
// response it lies between the apparent dead time and the tangent delay.
//
// Crossing times: the level p is crossed where r first reaches p, linearly
// interpolated between the two samples around it; with noise, the times of the
// first and of the last upward crossing before r exceeds p + b are averaged.
#pragma once

#include <string>

#include <Eigen/Core>

#include "pneumid/data/dataset.hpp"
#include "pneumid/lti/fopdt.hpp"  // FopdtParams, the result of the FOPDT methods

namespace pneumid {

/// Thresholds by which AnalyzeStep finds the step, the settled tail and the noise band.
struct StepAnalysisOptions {
  /// Fraction of the record used as the settled tail (default 0.1).
  double tail_fraction = 0.1;
  /// Minimum number of tail samples (default 10).
  int min_tail_samples = 10;
  /// Largest allowed drift of the tail, as a fraction of |dy| (default 0.02).
  double settle_tolerance = 0.02;
  /// Minimum |dy| / sigma (default 10).
  double min_snr = 10.0;
  /// An input sample differing from u0 or u1 by more than this fraction of
  /// |du| counts as a second step (default 0.05).
  double input_tolerance = 0.05;
  /// Noise band half-width in noise standard deviations (default 3).
  double band_sigmas = 3.0;
  /// Minimum noise band, fraction of the step (default 0.01).
  double band_min_fraction = 0.01;
  /// Samples the response must stay outside the band (default 3).
  int band_hold_samples = 3;
  /// Upper end (fraction of the step) of the samples used to extrapolate the
  /// departure back to the baseline (default 0.3).
  double departure_fit_upper = 0.3;

  /// True when tail_fraction is in (0, 0.5), min_tail_samples >= 3, settle_tolerance > 0,
  /// min_snr >= 0, input_tolerance and band_min_fraction are in (0, 0.5), band_sigmas >= 0,
  /// band_hold_samples >= 1 and departure_fit_upper is in (band_min_fraction, 1);
  /// otherwise false with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// Result of AnalyzeStep. Times are in seconds relative to the step time t_s
/// unless named otherwise.
struct StepAnalysis {
  Eigen::Index step_index = 0;          ///< k_s, first sample at the new input level
  double step_time = 0.0;               ///< t_s, absolute (data time axis), s
  double Ts = 0.0;                      ///< mean sample interval, s
  /// Input level before the step (input units).
  double u0 = 0.0, u1 = 0.0, du = 0.0;  ///< input before / after, step size
  /// @var u1
  /// Input level after the step (input units); du = u1 - u0.
  double y0 = 0.0;                      ///< baseline (output units)
  double y_final = 0.0;                 ///< settled final value
  double y_final_std = 0.0;             ///< standard error of y_final
  double dy = 0.0;                      ///< y_final - y0
  double gain = 0.0;                    ///< dy / du
  double noise_std = 0.0;               ///< sigma (output units)
  double band = 0.0;                    ///< noise band, fraction of the step
  double departure_time = 0.0;          ///< dead time read off the response, s after t_s
  Eigen::VectorXd t;                    ///< times after the step, t[k] - t_s (k >= k_s)
  Eigen::VectorXd r;                    ///< normalized response (y - y0) / dy on t

  /// Time (s after the step) at which the normalized response reaches `level`
  /// (0 < level < 1.5), see the header comment. Throws DataError when the
  /// response never reaches it.
  double CrossingTime(double level) const;
  /// One-line description, e.g. "step at t = 1 s: u 10 -> 30, y 0 -> 50 ...".
  std::string BriefReport() const;
};

/// Analyzes the step response in `data` (input column `input`, output column
/// `output`). The data must be uniformly sampled.
/// @throws InvalidArgument for invalid options or columns,
///         DataError (naming data.source()) for the refusals listed above.
StepAnalysis AnalyzeStep(const Dataset& data, int input = 0, int output = 0,
                         const StepAnalysisOptions& options = {});

/// Second-order-plus-dead-time model K exp(-theta s) / ((tau1 s + 1)(tau2 s + 1)),
/// tau1 >= tau2 >= 0 (seconds).
struct SopdtParams {
  double K = 0.0;      ///< static gain, output units per input unit
  double tau1 = 0.0;   ///< larger time constant, s
  double tau2 = 0.0;   ///< smaller time constant, s (0: first order)
  double theta = 0.0;  ///< dead time, s
};

}  // namespace pneumid
