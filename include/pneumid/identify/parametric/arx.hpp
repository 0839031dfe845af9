// ARX estimation by linear least squares through a Householder QR
// factorization, never through the normal equations.
//
// Model ([1] eq. 4.7, MATLAB arx), several inputs u_i with delays nk_i:
//   y(t) + a1 y(t-1) + ... + a_na y(t-na)
//        = sum_i [ b_i,1 u_i(t-nk_i) + ... + b_i,nb_i u_i(t-nk_i-nb_i+1) ] + e(t)
// i.e. y(t) = phi(t)' theta + e(t) with the regressor
//   phi(t) = [-y(t-1) .. -y(t-na), u_1(t-nk_1) .. u_1(t-nk_1-nb_1+1), ...]'.
// Rows are formed for t = n0 .. N-1, n0 = max(na, max_i(nk_i + nb_i - 1)), within
// each experiment (no data are invented before the first sample), and the rows of
// all experiments are stacked into one criterion.
//
// Least squares by QR [2] sec. 5.3: the triangular factor R of the augmented
// matrix [Phi | Y] = Q R,
//   R = [R11 r12; 0 rho],  theta = R11^-1 r12,  sum eps^2 = rho^2,
// is accumulated block by block (tall-skinny QR, [3]): each block of rows is
// reduced together with the current R by Householder reflections, so memory is
// independent of N and the same code serves in-memory and streamed data.
// The condition number of Phi is that of R11 (SVD of the small factor); a
// rank-deficient problem gets the minimum-norm solution through that SVD.
// Covariance of theta [1] eq. 9.18: lambda (Phi' Phi)^-1 = lambda R11^-1 R11^-T,
// lambda = rho^2 / (N - d).
//
// [1] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999.
// [2] G. H. Golub, C. F. Van Loan, Matrix Computations, 4th ed., 2013.
// [3] J. Demmel, L. Grigori, M. Hoemmen, J. Langou, Communication-optimal
//     parallel and sequential QR and LU factorizations, SIAM J. Sci. Comput. 34 (2012).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/parametric/parametric_model.hpp"

namespace pneumid {

/// Orders, delays and numerical thresholds of an ARX least-squares fit.
struct ArxOptions {
  int na = 3;                 ///< number of A coefficients (>= 0)
  std::vector<int> nb = {3};  ///< B coefficients per input (>= 0; 0 drops the input)
  std::vector<int> nk = {1};  ///< delay per input in samples (>= 0)
  /// A warning "poor excitation" is issued when the scaled condition number of
  /// the regressors exceeds this value.
  double excitation_warning_condition = 1e4;
  /// Singular values of R11 below rank_tolerance * sigma_max count as zero.
  double rank_tolerance = 1e-13;
  /// True when na >= 0, nb and nk have one non-negative entry per input, na + sum nb > 0,
  /// excitation_warning_condition > 1 and rank_tolerance is in (0, 1); otherwise false with
  /// the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
  /// Total number of parameters na + sum nb.
  int NumParameters() const;
  /// First sample index with a complete regressor, max(na, max(nk_i + nb_i - 1)).
  int FirstRow() const;
};

/// Estimated ARX model and how the least-squares solve went.
struct ArxResult {
  /// Structure "ARX": a, b per input (nk leading zeros), Ts, noise variance rho^2 / (N - d)
  /// and the parameter covariance.
  PolynomialModel model;
  /// Termination (kFailure with fewer rows than parameters), rows, loss, condition
  /// numbers and warnings such as poor excitation.
  EstimationSummary summary;
};

/// Accumulates the triangular factor R of [Phi | Y] from data given in any
/// number of experiments and chunks (constant memory), then solves for theta.
class ArxAccumulator {
 public:
  /// @throws InvalidArgument when !options.IsValid().
  explicit ArxAccumulator(const ArxOptions& options);

  /// Starts a new experiment: the next samples do not continue the previous ones.
  void BeginExperiment();
  /// Appends samples of the current experiment: y has n entries, u is n x nu.
  /// Rows whose regressor reaches back into earlier chunks of the same
  /// experiment are formed from the kept history (the last FirstRow() samples).
  /// @throws InvalidArgument when sizes disagree or a value is not finite.
  void AddSamples(const Eigen::Ref<const Eigen::VectorXd>& y,
                  const Eigen::Ref<const Eigen::MatrixXd>& u);
  /// Appends complete rows [phi' y] (m x (d + 1)) to the factorization.
  void AddRows(const Eigen::Ref<const Eigen::MatrixXd>& rows);

  /// Number of regression rows so far.
  long long num_rows() const { return num_rows_; }
  /// Current (d+1) x (d+1) upper-triangular factor of [Phi | Y].
  const Eigen::MatrixXd& R() const { return R_; }
  /// Least-squares solution with sample time Ts (seconds). A problem with fewer
  /// rows than parameters ends with termination kFailure.
  ArxResult Solve(double Ts) const;

 private:
  void ReduceBlock(double* block, Eigen::Index rows);
  ArxOptions options_;
  int d_ = 0;   // number of parameters
  int n0_ = 0;  // history length
  Eigen::MatrixXd R_;
  long long num_rows_ = 0;
  long long seen_ = 0;  // samples of the current experiment
  Eigen::VectorXd hist_y_;
  Eigen::MatrixXd hist_u_;
  Eigen::MatrixXd block_;
};

/// ARX fit of output column `output` of each experiment (same sample time and
/// number of inputs in all of them).
/// @throws InvalidArgument for invalid options, no experiments, mismatching
///         experiments, or option vectors that do not match the number of inputs.
/// @throws DataError when the data are too short or not uniformly sampled.
ArxResult EstimateArx(const std::vector<Dataset>& experiments, const ArxOptions& options,
                      int output = 0);
/// Single experiment.
ArxResult EstimateArx(const Dataset& data, const ArxOptions& options, int output = 0);
/// Raw arrays: y (N), u (N x nu), sample time Ts (seconds).
ArxResult EstimateArx(const Eigen::VectorXd& y, const Eigen::MatrixXd& u, double Ts,
                      const ArxOptions& options);

/// The regressor matrix Phi (rows t = FirstRow() .. N-1) and the targets y(t),
/// exactly as the estimator forms them (for tests and for other estimators).
void ArxRegressors(const Eigen::VectorXd& y, const Eigen::MatrixXd& u, const ArxOptions& options,
                   Eigen::MatrixXd* phi, Eigen::VectorXd* target);

}  // namespace pneumid
