// Frequency response and stability margins (MATLAB bode/margin).
#pragma once

#include <Eigen/Core>

#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

struct BodeData {
  Eigen::VectorXd omega;          ///< rad/s
  Eigen::VectorXd magnitude;      ///< absolute (not dB)
  Eigen::VectorXd magnitude_db;   ///< 20 log10 |G|
  Eigen::VectorXd phase_deg;      ///< unwrapped, degrees
};

/// n points log-spaced from 10^lo to 10^hi.
Eigen::VectorXd LogSpace(double lo, double hi, int n);
/// Response at the given frequencies (rad/s); for a discrete model up to the
/// Nyquist frequency pi/Ts. An empty omega chooses a grid around the poles and zeros.
BodeData Bode(const TransferFunction& g, const Eigen::VectorXd& omega = Eigen::VectorXd());

struct Margins {
  double gain_margin = 0.0;       ///< absolute; +inf when the phase never crosses -180
  double gain_margin_db = 0.0;
  double phase_crossover = 0.0;   ///< rad/s where phase = -180 deg (NaN if none)
  double phase_margin = 0.0;      ///< degrees; +inf when |G| never crosses 1
  double gain_crossover = 0.0;    ///< rad/s where |G| = 1 (NaN if none)
};
/// Margins of the open loop g (delay included).
Margins ComputeMargins(const TransferFunction& g);

}  // namespace pneumid
