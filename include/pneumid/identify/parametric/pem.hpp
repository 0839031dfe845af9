// Prediction-error estimation of the polynomial family (parametric_model.hpp)
// with Ceres Solver: ARMAX, output-error (OE) and Box-Jenkins (BJ).
//
// Criterion [1] eq. 7.12 (MATLAB armax/oe/bj, pem):
//   theta* = argmin V(theta),  V = 1/N sum_t eps(t, theta)^2,
//   eps(t, theta) = D/C (A y(t) - B/F u(t))   (zero initial conditions)
// minimised by Levenberg-Marquardt with dense QR on the exact Jacobian
// (automatic differentiation through the filters).
// Stability of the predictor: the filters 1/C and 1/F must be stable. Every
// initial estimate has its unstable roots reflected into the unit disc, and
// any trial step that makes C or F unstable is rejected (the cost function
// reports failure, so Ceres shrinks the trust region) [1] sec. 10.1.
// Initial estimates:
//   ARMAX  Hannan-Rissanen: high-order ARX residuals e1, then least squares of
//          A y = B u + (C - 1) e1 [2]
//   OE     F, B from the IV4 estimate of the ARX structure (iv.hpp)
//   BJ     B, F as OE; C, D from a Hannan-Rissanen ARMA fit of the OE residuals
// Covariance [1] eq. 9.17: lambda (J' J)^-1 at the optimum, J = d eps / d theta,
// lambda = N V / (N - d).
//
// [1] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999.
// [2] E. J. Hannan, J. Rissanen, Recursive estimation of mixed autoregressive-
//     moving average order, Biometrika 69 (1982) 81-94.
#pragma once

#include <string>

#include <Eigen/Core>

#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/parametric/parametric_model.hpp"

namespace pneumid {

/// Member of the polynomial family to estimate: ARX (A y = B u + e), ARMAX (A y = B u + C e),
/// OE (y = B/F u + e) or BJ (y = B/F u + C/D e).
enum class PolynomialStructure { kArx, kArmax, kOe, kBj };
/// "arx", "armax", "oe", "bj".
std::string ToString(PolynomialStructure s);
/// Inverse of ToString; throws InvalidArgument listing the valid names.
PolynomialStructure PolynomialStructureFromString(const std::string& name);

/// SISO orders. Unused orders are ignored (e.g. nc, nd, nf for ARMAX's D, F).
struct PemOrders {
  int na = 3;  ///< A coefficients (ARX, ARMAX)
  int nb = 3;  ///< B coefficients (>= 1)
  int nc = 1;  ///< C coefficients (ARMAX, BJ)
  int nd = 1;  ///< D coefficients (BJ)
  int nf = 3;  ///< F coefficients (OE, BJ)
  int nk = 1;  ///< input delay, samples
};

/// Levenberg-Marquardt settings of the prediction-error refinement and its initialisation.
struct PemOptions {
  int max_iterations = 100;            ///< Levenberg-Marquardt iterations
  double function_tolerance = 1e-10;   ///< relative change of V to stop
  double gradient_tolerance = 1e-12;   ///< Ceres' gradient tolerance to stop (> 0)
  double parameter_tolerance = 1e-10;  ///< Ceres' relative parameter step to stop (> 0)
  /// Order of the high-order ARX model of the ARMAX / BJ initialisation
  /// (0 = automatic: max(20, 2 (na + nb + nc)), limited by the data length).
  int initial_arx_order = 0;
  /// True when max_iterations >= 0, the three tolerances are > 0 and initial_arx_order >= 0;
  /// otherwise false with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// Model estimated by EstimatePolynomial and how the minimisation went.
struct PemResult {
  /// Structure "ARMAX", "OE" or "BJ" (or "ARX"), with noise variance N V / (N - d) and the
  /// covariance lambda (J'J)^-1 (none when J is singular at the optimum).
  PolynomialModel model;
  /// termination (kFailure when N <= 2 d samples), iterations, loss V and
  /// initial_loss, condition number of J, warnings (initialisation, no convergence).
  EstimationSummary summary;
};

/// Estimates a model of the given structure from output y and input u
/// (N samples), sample time Ts seconds. kArx is solved by least squares.
/// @throws InvalidArgument for invalid orders, options or sizes.
PemResult EstimatePolynomial(PolynomialStructure structure, const PemOrders& orders,
                             const Eigen::VectorXd& y, const Eigen::VectorXd& u, double Ts,
                             const PemOptions& options = {});
/// Same from a data set (input/output columns given).
/// @throws DataError for too short or non-uniformly sampled data.
PemResult EstimatePolynomial(PolynomialStructure structure, const PemOrders& orders,
                             const Dataset& data, const PemOptions& options = {}, int input = 0,
                             int output = 0);

/// Refines `initial` (any structure; its polynomial lengths define the free
/// parameters) by minimising the prediction-error criterion on y, u.
/// @throws InvalidArgument for an invalid model, options or sizes.
PemResult RefinePem(const PolynomialModel& initial, const Eigen::VectorXd& y,
                    const Eigen::VectorXd& u, const PemOptions& options = {});

}  // namespace pneumid
