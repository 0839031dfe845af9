// Recursive least squares with exponential forgetting, for online estimation
// in the real-time loop ([1] sec. 11.2, eq. 11.12; MATLAB recursiveARX).
//
//   e(t)     = y(t) - phi(t)' theta(t-1)                    (a-priori error)
//   K(t)     = P(t-1) phi(t) / (lambda + phi(t)' P(t-1) phi(t))
//   theta(t) = theta(t-1) + K(t) e(t)
//   P(t)     = (P(t-1) - K(t) phi(t)' P(t-1)) / lambda
// minimises sum_k lambda^(t-k) (y(k) - phi(k)' theta)^2 (+ the initial term
// lambda^t (theta - theta0)' P0^-1 (theta - theta0)). lambda = 1 is ordinary
// recursive least squares; lambda < 1 forgets with time constant about
// 1 / (1 - lambda) samples. P is kept symmetric after each update. Update()
// does not allocate (all storage is sized at construction), so it can run
// in a fixed-period loop.
//
// [1] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999.
#pragma once

#include <string>

#include <Eigen/Core>

#include "pneumid/identify/parametric/arx.hpp"
#include "pneumid/identify/parametric/parametric_model.hpp"

namespace pneumid {

/// Forgetting factor and initial covariance of recursive least squares.
struct RlsOptions {
  double forgetting_factor = 0.99;  ///< lambda in (0, 1]
  double initial_covariance = 1e4;  ///< P0 = initial_covariance * I (> 0)
  /// True when forgetting_factor is in (0, 1] and initial_covariance > 0; otherwise false
  /// with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// Recursive least squares with exponential forgetting for y(t) = phi(t)' theta + e(t)
/// (update equations above); allocation-free per update.
class RecursiveLeastSquares {
 public:
  /// @throws InvalidArgument for num_parameters < 1 or invalid options.
  RecursiveLeastSquares(int num_parameters, const RlsOptions& options = {});
  /// Back to theta0 (zero when empty) and P0.
  void Reset(const Eigen::VectorXd& theta0 = Eigen::VectorXd());
  /// One update with regressor phi and measurement y; returns the a-priori error.
  /// phi must have num_parameters() entries (checked only in debug builds).
  double Update(const Eigen::Ref<const Eigen::VectorXd>& phi, double y);
  const Eigen::VectorXd& theta() const { return theta_; }  ///< Current estimate theta(t).
  /// Current matrix P(t), symmetric; times the noise variance it approximates cov(theta).
  const Eigen::MatrixXd& P() const { return P_; }
  /// Number of parameters (size of theta and phi).
  int num_parameters() const { return static_cast<int>(theta_.size()); }
  long long num_updates() const { return updates_; }  ///< Updates since construction or Reset.

 private:
  RlsOptions options_;
  Eigen::VectorXd theta_, k_, pphi_;
  Eigen::MatrixXd P_;
  long long updates_ = 0;
};

/// Online SISO ARX(na, nb, nk) estimator: keeps the past samples and forms the
/// regressor of arx.hpp itself. Allocation-free per sample.
class RecursiveArx {
 public:
  /// options.nb / nk must have one entry (SISO). @throws InvalidArgument otherwise.
  RecursiveArx(const ArxOptions& orders, const RlsOptions& options = {});
  /// Feeds the sample pair (u(t), y(t)) and returns the a-priori prediction
  /// error (0 while fewer than FirstRow() samples have been seen).
  double Update(double u, double y);
  /// Current estimate as a polynomial model with sample time Ts seconds.
  PolynomialModel Model(double Ts) const;
  /// The underlying estimator; theta is [a1 .. a_na, b1 .. b_nb].
  const RecursiveLeastSquares& rls() const { return rls_; }

 private:
  ArxOptions orders_;
  RecursiveLeastSquares rls_;
  Eigen::VectorXd ypast_, upast_, phi_;  // ring-free shift registers (small)
  long long seen_ = 0;
};

}  // namespace pneumid
