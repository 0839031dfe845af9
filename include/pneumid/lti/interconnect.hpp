// Block-diagram algebra and minimal realization (MATLAB series/parallel/feedback/minreal).
// Both operands must share the time domain and the sample time.
#pragma once

#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// g2 * g1 (g1 first). Delays add.
/// @throws InvalidArgument when the time domains or sample times differ.
TransferFunction Series(const TransferFunction& g1, const TransferFunction& g2);
/// g1 + g2. Discrete delays are absorbed as powers of z^-1 (result delay 0).
/// @throws InvalidArgument when continuous delays differ (the sum is not
///   rational) or the time domains / sample times differ.
TransferFunction Parallel(const TransferFunction& g1, const TransferFunction& g2);
/// g / (1 - sign g h) with negative feedback by default (sign = -1):
///   T = ng dh / (dg dh - sign ng nh).
/// Discrete delays are absorbed into the polynomials (result delay 0). The
/// default h (continuous unit gain) also serves a discrete g.
/// @throws InvalidArgument for a continuous delay in the loop (not rational),
///   sign not +-1, an ill-posed loop (1 - sign g h = 0 at infinite frequency),
///   or different time domains.
TransferFunction Feedback(const TransferFunction& g, const TransferFunction& h = TransferFunction(),
                          int sign = -1);
/// Removes pole-zero pairs closer than `tol` (relative to max(1, |pole|)),
/// like MATLAB minreal; the high-frequency gain is kept.
/// @throws InvalidArgument for tol < 0.
TransferFunction MinimalRealization(const TransferFunction& g, double tol = 1e-6);

}  // namespace pneumid
