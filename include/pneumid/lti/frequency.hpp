// Frequency response and stability margins (MATLAB bode/margin).
#pragma once

#include <Eigen/Core>

#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// Frequency response of a transfer function at the frequencies `omega` (Bode).
struct BodeData {
  Eigen::VectorXd omega;         ///< rad/s
  Eigen::VectorXd magnitude;     ///< absolute (not dB)
  Eigen::VectorXd magnitude_db;  ///< 20 log10 |G|
  Eigen::VectorXd phase_deg;     ///< unwrapped, degrees
};

/// n points log-spaced from 10^lo to 10^hi.
/// @throws InvalidArgument for lo > hi, non-finite bounds or n < 1.
Eigen::VectorXd LogSpace(double lo, double hi, int n);
/// Response at the given frequencies (rad/s); for a discrete model up to the
/// Nyquist frequency pi/Ts. An empty omega chooses a grid around the poles and zeros.
/// The phase is the sum of the angles of the factors (x - zero)/(x - pole) plus
/// -w delay, so it is continuous without unwrapping heuristics; it starts in
/// (-180, 180] at the first frequency.
/// @throws InvalidArgument for negative or non-finite frequencies, or above
///   pi/Ts for a discrete model.
BodeData Bode(const TransferFunction& g, const Eigen::VectorXd& omega = Eigen::VectorXd());

/// Gain and phase margins of an open loop and their crossover frequencies.
struct Margins {
  double gain_margin = 0.0;      ///< absolute; +inf when the phase never crosses -180
  double gain_margin_db = 0.0;   ///< 20 log10 gain_margin, dB
  double phase_crossover = 0.0;  ///< rad/s where phase = -180 deg (NaN if none)
  double phase_margin = 0.0;     ///< degrees; +inf when |G| never crosses 1
  double gain_crossover = 0.0;   ///< rad/s where |G| = 1 (NaN if none)
};
/// Margins of the open loop g (delay included). Crossings are bracketed on a
/// dense log grid (100 points per decade, extended to 100/delay for a delay)
/// and refined by bisection; with several crossings the margin closest to
/// instability is reported (smallest |log gain margin|, smallest |phase margin|),
/// as MATLAB's margin does.
Margins ComputeMargins(const TransferFunction& g);

}  // namespace pneumid
