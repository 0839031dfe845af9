// Instrumental-variable estimation of the ARX structure
//   A(q) y(t) = B(q) u(t) + v(t)
// that stays consistent when v is coloured (where least squares is biased).
//
// Basic IV [1] eq. 7.118:  theta = (sum zeta(t) phi(t)')^-1 sum zeta(t) y(t),
// instruments zeta(t) = [-x(t-1) .. -x(t-na), u(t-nk) .. u(t-nk-nb+1)]' built from
// the noise-free simulation x = B/A u of a previous estimate.
// Four-stage IV4 [1] sec. 15.3, eq. 15.21-15.26 (MATLAB iv4):
//   1. ARX least squares (arx.hpp)                      -> A1, B1
//   2. IV with instruments from x1 = B1/A1 u             -> A2, B2
//   3. AR model L(q) w = e of order na + nb for the equation error
//      w = A2 y - B2 u, by least squares
//   4. IV on the data and instruments prefiltered by L, instruments from
//      x2 = B2/A2 u                                       -> A, B
// The linear systems are solved by column-pivoted QR; the covariance is
// lambda R^-1 (Zf' Zf) R^-T with R = Zf' Phif ([1] eq. 9.54 for the optimal IV).
// Unstable instrument models are stabilised by reflecting their poles into the
// unit disc before simulation.
//
// [1] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999.
#pragma once

#include <string>

#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/parametric/parametric_model.hpp"

namespace pneumid {

/// Orders of the IV4 estimate (the ARX structure A y = B u + e).
struct IvOptions {
  int na = 3;  ///< A order (>= 0)
  int nb = 3;  ///< B coefficients (>= 1)
  int nk = 1;  ///< input delay, samples (>= 0)
  /// True when na >= 0, nb >= 1 and nk >= 0; otherwise false with the reason in *error
  /// (when error is not null).
  bool IsValid(std::string* error) const;
};

/// IV4 model and how the four stages went.
struct IvResult {
  PolynomialModel model;  ///< structure "ARX" estimated by IV4
  /// kConvergence, or kFailure when the least-squares start or an instrument matrix is
  /// singular (then `model` is the default or the stage-2 IV estimate); loss, initial_loss (the
  /// least-squares loss), warnings.
  EstimationSummary summary;
};

/// IV4 estimate from output y and input u (N samples), sample time Ts seconds.
/// @throws InvalidArgument for invalid options or sizes.
IvResult EstimateIv4(const Eigen::VectorXd& y, const Eigen::VectorXd& u, double Ts,
                     const IvOptions& options);
/// IV4 from a data set, input/output columns given.
/// @throws DataError for too short or non-uniformly sampled data.
IvResult EstimateIv4(const Dataset& data, const IvOptions& options, int input = 0, int output = 0);

/// Monic polynomial [1 p1 .. pn] in q^-1 with every root z (of z^n + p1 z^(n-1) +
/// ... + pn) outside the unit circle replaced by 1 / conj(z) ([1] sec. 10.1): the
/// stable spectral-factor equivalent used to keep predictors stable.
Eigen::VectorXd ReflectUnstableRoots(const Eigen::VectorXd& monic);

}  // namespace pneumid
