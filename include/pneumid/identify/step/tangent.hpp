// Tangent at the inflection point (Ziegler and Nichols [1]; "tangent-line
// method" of Pavkovic, Polak and Zorc [2]).
//
// The slope of the normalized response r(t) is estimated at every sample by a
// Savitzky-Golay filter [3]: a least-squares polynomial of degree 2 over a
// window of 2m + 1 samples centred on the sample (value = constant term, slope
// = linear term / Ts). The inflection point is the sample of largest slope,
// refined to a fraction of a sample by a parabola through the slopes of its
// neighbours. With r_i, S the normalized value and slope there, the tangent
// r = r_i + S (t - t_i) meets the baseline r = 0 at
//   L = t_i - r_i / S          (delay time, paper's td, Strejc's Tu)
// and the final value r = 1 at L + T, with
//   T = 1 / S                  (time constant, paper's tTL, Strejc's Tn).
// FOPDT (Ziegler-Nichols): K = dy/du, theta = max(L, 0), tau = T.
// On the paper's ARX model: the continuous equivalent's tangent is
// L = 0.00512 s, T = 0.21877 s; the steepest segment of its step sampled at
// Ts = 0.01 s gives L = 0.0043 s, T = 0.2315 s (docs/paper.md, reference value 4).
//
// [1] J. G. Ziegler, N. B. Nichols, Optimum settings for automatic
//     controllers, Trans. ASME 64 (1942) 759-768.
// [2] D. Pavkovic, S. Polak, D. Zorc, PID controller auto-tuning based on
//     process step response and damping optimum criterion, ISA Transactions
//     53 (2014) 85-96.
// [3] A. Savitzky, M. J. E. Golay, Smoothing and differentiation of data by
//     simplified least squares procedures, Anal. Chem. 36 (1964) 1627-1639.
#pragma once

#include <string>

#include "pneumid/identify/step/step_analysis.hpp"

namespace pneumid {

/// Smoothing of the step response before its inflection tangent is drawn.
struct TangentOptions {
  /// Savitzky-Golay half-width m (window 2m + 1 samples); 0 chooses
  /// m = clamp(round(n63 / 8), 2, 50) with n63 the samples to 63.2 % (default 0).
  int half_width = 0;
  /// True when half_width >= 0; otherwise false with the reason in *error (when not null).
  bool IsValid(std::string* error) const;
};

/// Inflection point of the normalized step response and its tangent's delay and lag times.
struct TangentResult {
  double inflection_time = 0.0;   ///< t_i, s after the step
  double inflection_value = 0.0;  ///< r_i, fraction of the step
  double slope = 0.0;             ///< S, fraction of the step per second
  double L = 0.0;                 ///< delay time td / Tu, s (may be negative)
  double T = 0.0;                 ///< time constant tTL / Tn, s
  int half_width = 0;             ///< Savitzky-Golay half-width used
};

/// Tangent construction on an analyzed step.
/// @throws InvalidArgument for invalid options; DataError when the record is
///         shorter than the filter window or the slope is never positive.
TangentResult InflectionTangent(const StepAnalysis& step, const TangentOptions& options = {});

/// FOPDT from the tangent: K = step.gain, theta = max(L, 0), tau = T.
FopdtParams TangentFopdt(const StepAnalysis& step, const TangentResult& tangent);

}  // namespace pneumid
