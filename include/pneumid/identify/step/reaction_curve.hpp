// FOPDT by the process reaction curve, the method of the paper [1, Eq. 2]
// after Ziegler and Nichols [2]:
//   K     = dy / du                   (settled output change over input step)
//   theta = departure time: where the response leaves the baseline, read off
//           the data as described in step_analysis.hpp (noise-band crossing,
//           extrapolated back to the baseline along the initial rise)
//   tau   = t63 - theta,  t63 = time (after the step) at which the response
//           reaches 63.2 % of dy, linearly interpolated between samples.
// The paper reads tau = 0.245 s off its measured force and sets theta to
// 0.001 s; on the paper's ARX model the 63.2 % time is 0.2306 s.
//
// [1] A. A. M. Emhemed, R. Mamat, A. A. M. Faudzi, Non-parametric
//     identification techniques for intelligent pneumatic actuator, Jurnal
//     Teknologi 77:20 (2015) 115-119, Eq. 2.
// [2] D. E. Seborg, T. F. Edgar, D. A. Mellichamp, Process Dynamics and
//     Control, 2nd ed., Wiley 2004, sec. 7.2 (process reaction curve).
#pragma once

#include "pneumid/identify/step/step_analysis.hpp"

namespace pneumid {

/// FOPDT parameters by the reaction-curve method from an analyzed step.
/// @throws DataError when the response never reaches 63.2 % or the resulting
///         time constant is not positive.
FopdtParams ReactionCurve(const StepAnalysis& step);

}  // namespace pneumid
