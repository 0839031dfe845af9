// Discrete-time polynomial (black-box) model of a multi-input single-output
// process, the general family of [1] sec. 4.2 (MATLAB idpoly):
//
//   A(q) y(t) = sum_i B_i(q) / F_i(q) u_i(t) + C(q) / D(q) e(t)
//
// with polynomials in the delay operator q^-1
//   A(q) = 1 + a1 q^-1 + ... + a_na q^-na
//   B_i(q) = b_i,nk q^-nk + ... + b_i,nk+nb-1 q^-(nk+nb-1)   (input delay nk_i)
//   C, D, F_i monic like A,
// and e white noise of variance `noise_variance`. Special cases:
//   ARX   C = D = F = 1        ARMAX  D = F = 1
//   OE    A = C = D = 1        BJ     A = 1
// Coefficient storage follows MATLAB: `b[i]` holds the whole B_i polynomial in
// ascending powers of q^-1 including its nk_i leading zeros, so the paper's
// Eq. 5 model is a = [1 -0.6087 -0.2702 -0.06021], b = [0 0.03938 0.04506 0.01286].
//
// The one-step-ahead predictor is [1] eq. 4.8
//   yhat(t|t-1) = (1 - D A / C) y(t) + (D / C) sum_i (B_i / F_i) u_i(t),
// its prediction errors eps = y - yhat = (D / C)(A y - sum_i B_i / F_i u_i).
// The k-step-ahead predictor [1] eq. 3.31 is yhat(t|t-k) = y(t) - Hk(q) eps(t),
// where Hk holds the first k impulse-response coefficients of H = C / (A D).
//
// [1] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "pneumid/common/termination.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

class ModelParams;  // identify/identified_model.hpp

// Termination here: How an estimator ended: kConvergence (solution found: least squares solved,
// or iterations converged), kNoConvergence (iteration limit; the last
// iterate), kRankDeficient (regressors not of full rank: minimum-norm
// solution) or kFailure (too few samples, numerical breakdown). The
// vocabulary and ToString are common/termination.hpp's.

/// Outcome of a parametric estimator (after Ceres' Solver::Summary).
struct EstimationSummary {
  Termination termination = Termination::kFailure;  ///< how it ended
  std::string message;     ///< human-readable reason for `termination`
  long long num_rows = 0;  ///< number of prediction errors in the criterion
  int num_parameters = 0;  ///< number of estimated parameters d
  int iterations = 0;         ///< solver iterations (0 for direct least squares)
  double loss = 0.0;          ///< mean squared prediction error, sum eps^2 / N
  double initial_loss = 0.0;  ///< loss of the initial model (iterative methods)
  /// 2-norm condition number of the regressor matrix (ratio of extreme singular values
  /// of R), and of the regressor with its columns scaled to unit norm (the excitation
  /// measure that does not depend on the units of the signals).
  double condition_number = 0.0;
  double scaled_condition_number = 0.0;  ///< condition number with unit-norm columns
  std::vector<std::string> warnings;  ///< poor excitation, unstable model, ...
  /// One line: "ARX: convergence, N = 999, 6 parameters, loss 1.2e-3, cond 45".
  std::string BriefReport() const;
  /// True unless termination is kFailure (a non-converged or rank-deficient estimate is usable).
  bool IsSolutionUsable() const { return termination != Termination::kFailure; }
};

/// Discrete polynomial model A y = B/F u + C/D e (q^-1 polynomials, the family of ARX,
/// ARMAX, OE, BJ), with its sample time, noise variance and parameter covariance.
struct PolynomialModel {
  double Ts = 1.0;                               ///< sample time, seconds
  Eigen::VectorXd a = Eigen::VectorXd::Ones(1);  ///< [1 a1 .. a_na]
  std::vector<Eigen::VectorXd> b;                ///< per input: B_i with nk_i leading zeros
  std::vector<int> nk;                           ///< per input delay (samples)
  Eigen::VectorXd c = Eigen::VectorXd::Ones(1);  ///< [1 c1 .. c_nc]
  Eigen::VectorXd d = Eigen::VectorXd::Ones(1);  ///< [1 d1 .. d_nd]
  std::vector<Eigen::VectorXd> f;                ///< per input: [1 f1 .. f_nf] (empty = 1)
  double noise_variance = 0.0;                   ///< variance of e (output units^2)
  /// Covariance of the free parameters, in the order of ParameterNames(); empty if unknown.
  Eigen::MatrixXd covariance;
  std::string structure = "ARX";  ///< "ARX", "ARMAX", "OE", "BJ", "IV4"

  int num_inputs() const { return static_cast<int>(b.size()); }  ///< Number of inputs (B's).
  int na() const { return static_cast<int>(a.size()) - 1; }  ///< Order of A.
  /// Number of estimated coefficients of B_i (without the leading zeros).
  int nb(int input = 0) const;
  int nc() const { return static_cast<int>(c.size()) - 1; }  ///< Order of C.
  int nd() const { return static_cast<int>(d.size()) - 1; }  ///< Order of D.
  /// Order of F_input (0 when f is empty, i.e. F = 1).
  int nf(int input = 0) const;

  /// Names of the free parameters: a1.., b1.. (b1_1.. for several inputs), c1.., d1.., f1..
  std::vector<std::string> ParameterNames() const;
  /// Values of the free parameters in the order of ParameterNames().
  Eigen::VectorXd Parameters() const;
  /// Standard deviations sqrt(diag(covariance)); empty when the covariance is unknown.
  Eigen::VectorXd ParameterStd() const;

  /// Throws InvalidArgument unless the polynomials are consistent (monic A, C, D,
  /// F; nk_i leading zeros in B_i; one B per input; Ts > 0).
  void Validate() const;

  /// Discrete transfer function B_i / (A F_i) from input `input` (Ts, and as many
  /// leading delays moved to the delay as needed to keep it proper).
  /// @throws InvalidArgument when input is out of range.
  TransferFunction ToTransferFunction(int input = 0) const;

  /// JSON form {"a", "b", "nk", "Ts", ["c", "d", "f"]} (b and nk as arrays when
  /// there are several inputs), the `params` of IdentifiedModel.
  nlohmann::json ParamsJson() const;
  /// Inverse of ParamsJson; throws InvalidArgument naming a missing/invalid key.
  static PolynomialModel FromParamsJson(const nlohmann::json& params,
                                        const std::string& structure = "ARX");
};

/// The `params` of an IdentifiedModel (identified_model.hpp) of `model`: the
/// keys and types of ParamsJson ("a", "b", "nk", "Ts", and "c", "d", "f" when
/// present; b, nk and f per input when there are several), converted directly.
ModelParams ToModelParams(const PolynomialModel& model);
/// Inverse of ToModelParams (coefficients given as integers are accepted).
/// @throws InvalidArgument naming a missing or mistyped key, or as Validate.
PolynomialModel PolynomialModelFromParams(const ModelParams& params,
                                          const std::string& structure = "ARX");

/// Noise-free simulated output sum_i B_i / (A F_i) u_i from zero initial
/// conditions. `u` is N x nu (nu = model.num_inputs()).
/// @throws InvalidArgument when the column count differs from the model's inputs.
Eigen::VectorXd Simulate(const PolynomialModel& model, const Eigen::MatrixXd& u);

/// One-step-ahead prediction errors eps(t) = y(t) - yhat(t|t-1) (see above),
/// zero initial conditions. @throws InvalidArgument on size mismatch.
Eigen::VectorXd PredictionErrors(const PolynomialModel& model, const Eigen::VectorXd& y,
                                 const Eigen::MatrixXd& u);

/// k-step-ahead prediction yhat(t|t-k); horizon <= 0 means infinity, i.e. the
/// simulation Simulate(model, u). @throws InvalidArgument on size mismatch.
Eigen::VectorXd Predict(const PolynomialModel& model, const Eigen::VectorXd& y,
                        const Eigen::MatrixXd& u, int horizon);

}  // namespace pneumid
