// Conversions between representations and time domains.
//
// c2d methods after python-control `sample()` / scipy.signal.cont2discrete:
//   zoh            exact: expm([A B; 0 0] Ts) = [Ad Bd; 0 I]           (Drake
//                  discrete_time_approximation.cc)
//   foh            triangle hold (Franklin, Powell, Workman, Digital Control, 3rd ed., 6.3.2)
//   tustin         s = 2/Ts (z-1)/(z+1); with prewarp w: s = w/tan(w Ts/2) (z-1)/(z+1)
//   euler          s = (z-1)/Ts                    (forward difference)
//   backward_diff  s = (z-1)/(z Ts)
//   matched        poles and zeros mapped by z = exp(s Ts), DC gain matched
// d2c: zoh through the matrix logarithm of [Ad Bd; 0 I] (throws when Ad has an
// eigenvalue on the closed negative real axis, where no real logarithm
// exists), and tustin by the inverse substitution.
// Delays: a continuous delay theta becomes floor(theta/Ts) samples of z^-1 plus,
// for a fractional remainder under zoh, an extra state (modified z-transform);
// a discrete delay of d samples becomes exp(-d Ts s).
#pragma once

#include <string>

#include "pneumid/lti/state_space.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

enum class DiscretizationMethod { kZoh, kFoh, kTustin, kEuler, kBackwardDiff, kMatched };

/// "zoh", "foh", "tustin", "euler", "backward_diff", "matched".
std::string ToString(DiscretizationMethod method);
/// Inverse of ToString; also accepts "bilinear" (= tustin) and "forward_diff"
/// (= euler). Throws InvalidArgument listing the valid names.
DiscretizationMethod DiscretizationMethodFromString(const std::string& name);

/// Controllable canonical realization of a SISO transfer function.
StateSpace ToStateSpace(const TransferFunction& tf);
/// Transfer function from input `input` to output `output`.
TransferFunction ToTransferFunction(const StateSpace& ss, int input = 0, int output = 0);

/// Continuous -> discrete. `prewarp` (rad/s, tustin only; 0 = none).
/// Throws InvalidArgument when the model is already discrete or Ts <= 0.
TransferFunction C2D(const TransferFunction& g, double Ts,
                     DiscretizationMethod method = DiscretizationMethod::kZoh,
                     double prewarp = 0.0);
StateSpace C2D(const StateSpace& g, double Ts,
               DiscretizationMethod method = DiscretizationMethod::kZoh, double prewarp = 0.0);

/// Discrete -> continuous (zoh or tustin). Throws InvalidArgument for other
/// methods, for a continuous model, and (zoh) for a pole on the negative real axis.
TransferFunction D2C(const TransferFunction& g,
                     DiscretizationMethod method = DiscretizationMethod::kZoh,
                     double prewarp = 0.0);
StateSpace D2C(const StateSpace& g, DiscretizationMethod method = DiscretizationMethod::kZoh,
               double prewarp = 0.0);

}  // namespace pneumid
