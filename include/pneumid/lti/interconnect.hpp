// Block-diagram algebra and minimal realization (MATLAB series/parallel/feedback/minreal).
// Both operands must share the time domain and the sample time.
#pragma once

#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// g2 * g1 (g1 first). Delays add.
TransferFunction Series(const TransferFunction& g1, const TransferFunction& g2);
/// g1 + g2; throws InvalidArgument when the delays differ (the sum is not rational).
TransferFunction Parallel(const TransferFunction& g1, const TransferFunction& g2);
/// g / (1 + sign' g h) with negative feedback by default (sign = -1). Delay in
/// the loop of a continuous model throws InvalidArgument (not rational).
TransferFunction Feedback(const TransferFunction& g, const TransferFunction& h = TransferFunction(),
                          int sign = -1);
/// Removes pole-zero pairs closer than `tol` (relative), like MATLAB minreal.
TransferFunction MinimalRealization(const TransferFunction& g, double tol = 1e-6);

}  // namespace pneumid
