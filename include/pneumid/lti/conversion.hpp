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
// for a fractional remainder f under zoh, an extra state (modified z-transform,
// exact for piecewise-constant input):
//   x[k+1] = Phi(Ts-f) Phi(f) x[k] + Phi(Ts-f) Gamma(f) v[k] + Gamma(Ts-f) u[k],
//   v[k+1] = u[k],  y[k] = C x[k] + D v[k],
// with Phi(t) = exp(A t), Gamma(t) = int_0^t exp(A s) ds B
// ([1] Franklin, Powell, Workman, Digital Control of Dynamic Systems, 3rd ed., 1998, ch. 4 and 6).
// The other methods have no exact fractional delay: they round theta/Ts to the
// nearest whole number of samples (an approximation with a phase error of at
// most Ts/2 times w). A ratio within 1e-9 of an integer counts as an integer.
// A discrete delay of d samples becomes exp(-d Ts s) (exact for zoh). In d2c,
// leading zeros of B(z^-1) beyond the first (b0 = ... = b_{k} = 0, k >= 1) are
// read as k - 1 further samples of delay, so that an ARX model with nk > 1
// maps to a rational model plus a dead time rather than to a pole at z = 0.
//
// Tustin with prewarp w is the bilinear substitution with the period
// T' = 2 tan(w Ts / 2) / w; matched maps the finite poles and zeros by
// z = exp(s Ts) (zeros at infinity are dropped, keeping the relative degree)
// and matches s^e G(s) at s = 0 with ((z - 1)/Ts)^e Gd(z) at z = 1, where e is
// the number of poles minus zeros at the origin (the DC gain when e = 0).
#pragma once

#include <string>

#include "pneumid/lti/state_space.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// Continuous <-> discrete mapping of C2D / D2C (the methods in the file comment).
enum class DiscretizationMethod { kZoh, kFoh, kTustin, kEuler, kBackwardDiff, kMatched };

/// "zoh", "foh", "tustin", "euler", "backward_diff", "matched".
std::string ToString(DiscretizationMethod method);
/// Inverse of ToString; also accepts "bilinear" (= tustin) and "forward_diff"
/// (= euler). Throws InvalidArgument listing the valid names.
DiscretizationMethod DiscretizationMethodFromString(const std::string& name);

/// Controllable canonical realization of a SISO transfer function (same Ts
/// and delay): A has -a1..-an in its first row, B = e1, C = b - b0 a, D = b0.
StateSpace ToStateSpace(const TransferFunction& tf);
/// Transfer function from input `input` to output `output`:
///   num = det(sI - A + b c) - det(sI - A) + d det(sI - A),  den = det(sI - A)
/// (characteristic polynomials from the eigenvalues).
/// @throws InvalidArgument for an input or output index out of range.
TransferFunction ToTransferFunction(const StateSpace& ss, int input = 0, int output = 0);

/// Continuous -> discrete with sample time Ts (s). `prewarp` (rad/s, tustin
/// only; 0 = none; below pi/Ts).
/// @throws InvalidArgument when the model is already discrete, Ts <= 0, a
///   prewarp is given for another method or is not below the Nyquist
///   frequency, or (euler/backward_diff/tustin) I - alpha Ts A is singular.
TransferFunction C2D(const TransferFunction& g, double Ts,
                     DiscretizationMethod method = DiscretizationMethod::kZoh,
                     double prewarp = 0.0);
/// State-space C2D with the same methods and checks; under zoh a fractional delay adds
/// the previous input as states. matched needs a SISO model (else InvalidArgument).
StateSpace C2D(const StateSpace& g, double Ts,
               DiscretizationMethod method = DiscretizationMethod::kZoh, double prewarp = 0.0);

/// Discrete -> continuous (zoh or tustin).
/// @throws InvalidArgument for other methods, for a continuous model, (zoh)
///   for a pole on the closed negative real axis (including z = 0), and
///   (tustin) for a pole at z = -1.
TransferFunction D2C(const TransferFunction& g,
                     DiscretizationMethod method = DiscretizationMethod::kZoh,
                     double prewarp = 0.0);
/// State-space D2C (zoh or tustin) with the same checks.
StateSpace D2C(const StateSpace& g, DiscretizationMethod method = DiscretizationMethod::kZoh,
               double prewarp = 0.0);

}  // namespace pneumid
