// Residual analysis of an identified model (MATLAB resid [1], [2] sec. 16.6).
//
// With eps(t) the one-step-ahead prediction errors of the model on data
// (N samples) and u the input:
//   autocorrelation     r_e(tau)  = R_e(tau) / R_e(0),            tau = 0 .. M
//   cross-correlation   r_eu(tau) = R_eu(tau) / sqrt(R_e(0) R_u(0)), tau = -M .. M
// where R_xy(tau) = 1/N sum_t x(t + tau) y(t) after removing the means, so
// r_eu(tau) > 0 for tau > 0 relates the residual to past inputs.
// If the model is correct, eps is white and independent of u, and each
// normalized correlation is asymptotically N(0, 1/N) ([2] eq. 16.67), giving the
// 99 % confidence bound z_0.995 / sqrt(N) = 2.5758 / sqrt(N) drawn by resid.
// The verdict uses the portmanteau statistics ([2] eq. 16.65, 16.69)
//   whiteness     Q_e  = N sum_{tau=1..M} r_e(tau)^2   ~ chi2(M)
//   independence  Q_eu = N sum_{tau=-M..M} r_eu(tau)^2 ~ chi2(2M + 1)
// each test passing when its statistic is below the 99 % quantile.
//
// [1] MathWorks, System Identification Toolbox, resid,
//     https://www.mathworks.com/help/ident/ref/resid.html
// [2] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999.
#pragma once

#include <string>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/parametric/parametric_model.hpp"

namespace pneumid {

/// Largest lag and confidence level of the residual tests.
struct ResidualAnalysisOptions {
  int max_lag = 25;          ///< M (MATLAB's default); >= 1 and < N / 2
  double confidence = 0.99;  ///< in (0, 1)
  /// True when max_lag >= 1 and confidence is in (0, 1); otherwise false with the reason in
  /// *error (when error is not null). M < N / 2 is checked against the data.
  bool IsValid(std::string* error) const;
};

/// Correlation tests of model residuals: whiteness (autocorrelation) and independence from
/// the input (cross-correlation), with the portmanteau statistics.
struct ResidualAnalysis {
  Eigen::VectorXd residuals;            ///< eps(t), N samples
  Eigen::VectorXd lags_auto;            ///< 0 .. M
  Eigen::VectorXd autocorr;             ///< r_e at lags_auto (r_e(0) = 1)
  Eigen::VectorXd lags_cross;           ///< -M .. M
  Eigen::VectorXd crosscorr;            ///< r_eu at lags_cross
  double bound = 0.0;                   ///< confidence bound on each normalized correlation
  int auto_outside = 0;                 ///< lags 1..M with |r_e| > bound
  int cross_outside = 0;                ///< lags -M..M with |r_eu| > bound
  double whiteness_statistic = 0.0;     ///< Q_e
  double whiteness_threshold = 0.0;     ///< chi2 quantile, M degrees of freedom
  double independence_statistic = 0.0;  ///< Q_eu
  double independence_threshold = 0.0;  ///< chi2 quantile, 2M+1 degrees of freedom
  bool whiteness_passed = false;     ///< whiteness_statistic < whiteness_threshold
  bool independence_passed = false;  ///< independence_statistic < independence_threshold
  /// True when both the whiteness and the independence test passed.
  bool passed() const { return whiteness_passed && independence_passed; }
  /// e.g. "residuals white: pass (Q = 21.3 < 44.3), independent of input: fail (...)".
  std::string BriefReport() const;
  /// {bound, autocorrelation: {lags, values, outside}, crosscorrelation: {lags, values,
  /// outside}, whiteness and independence: {statistic, threshold, passed}, passed}.
  nlohmann::json ToJson() const;
};

/// Residual analysis of given residuals eps and input u (same length N).
/// @throws InvalidArgument for invalid options, sizes, or constant eps or u.
ResidualAnalysis AnalyzeResiduals(const Eigen::VectorXd& residuals, const Eigen::VectorXd& u,
                                  const ResidualAnalysisOptions& options = {});

/// Only the whiteness test of AnalyzeResiduals (autocorrelation at lags
/// 0..M, its bound and portmanteau statistic): the fields residuals,
/// lags_cross, crosscorr and the independence results stay empty/false. Costs
/// M + 1 inner products of the N residuals, a third of AnalyzeResiduals.
/// @throws InvalidArgument for invalid options, N <= 2M, non-finite or
///         constant residuals.
ResidualAnalysis AnalyzeWhiteness(const Eigen::VectorXd& residuals,
                                  const ResidualAnalysisOptions& options = {});

/// Residual analysis of a polynomial model's one-step prediction errors on
/// data (input column `input` for the correlation, output column `output`).
/// @throws InvalidArgument as AnalyzeResiduals, or on a model/data mismatch.
ResidualAnalysis AnalyzeResiduals(const PolynomialModel& model, const Dataset& data,
                                  const ResidualAnalysisOptions& options = {}, int input = 0,
                                  int output = 0);

/// Normalized sample cross-correlation r_xy(tau) = R_xy(tau) / sqrt(R_x(0) R_y(0)),
/// R_xy(tau) = 1/N sum_t x(t + tau) y(t) (means removed), tau = -max_lag .. max_lag.
/// @throws InvalidArgument when sizes differ or max_lag >= N.
Eigen::VectorXd NormalizedCrossCorrelation(const Eigen::VectorXd& x, const Eigen::VectorXd& y,
                                           int max_lag);

}  // namespace pneumid
