// First-order-plus-dead-time (FOPDT) description of a plant, the model every
// step-response method of the identify area returns and the tuning rules of the
// control area start from:
//
//   G(s) = K exp(-theta s) / (tau s + 1)
//
// Smith's two-point method [1] (also [2, sec. 7.2]) reads it off the times t1
// and t2 after the step at which the response reaches 28.3 % and 63.2 % of its
// change (for a true FOPDT, t1 = theta + tau/3 and t2 = theta + tau):
//
//   tau = 1.5 (t2 - t1),   theta = t2 - tau   (clipped at 0).
//
// [1] C. L. Smith, Digital Computer Process Control, Intext 1972.
// [2] D. E. Seborg, T. F. Edgar, D. A. Mellichamp, Process Dynamics and
//     Control, 2nd ed., Wiley 2004.
#pragma once

#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// FOPDT parameters of K exp(-theta s) / (tau s + 1).
struct FopdtParams {
  double K = 0.0;      ///< static gain, output units per input unit
  double tau = 0.0;    ///< time constant, s
  double theta = 0.0;  ///< dead time, s

  /// The continuous transfer function K exp(-theta s) / (tau s + 1).
  TransferFunction ToTransferFunction() const;
};

/// The response fractions of Smith's method: 28.3 % and 63.2 % (1 - 1/e).
inline constexpr double kSmithLevel1 = 0.283;
inline constexpr double kSmithLevel2 = 0.632;  ///< 63.2 % crossing, at theta + tau

/// Smith's two-point FOPDT (see the file comment) from the gain K and the
/// times t1 < t2 (s after the step) of the 28.3 % and 63.2 % crossings.
/// The result has tau <= 0 when t2 <= t1; callers reject it.
FopdtParams SmithTwoPoint(double K, double t1, double t2);

}  // namespace pneumid
