// Goodness-of-fit measures of a simulated model response against measured data.
//
//   NRMSE fit [%]   fit = 100 (1 - ||y - yhat||_2 / ||y - mean(y)||_2)
//                   as MATLAB's `compare` defines it [1]: 100 is a perfect fit,
//                   0 is no better than the mean, negative is worse.
//   IAE             integral of |y(t) - yhat(t)| dt over the data, trapezoidal
//                   rule on the sample times (output units * seconds) [2].
//   RMSE            sqrt(mean((y - yhat)^2)) (output units).
//
// [1] MathWorks, System Identification Toolbox, `compare` and `goodnessOfFit`
//     (cost function 'NRMSE'),
//     https://www.mathworks.com/help/ident/ref/dynamicsystem.compare.html
// [2] K. J. Astrom, T. Hagglund, Advanced PID Control, ISA 2006, sec. 4.2
//     (integrated absolute error).
#pragma once

#include <Eigen/Core>

namespace pneumid {

/// NRMSE fit in percent, 100 (1 - ||y - yhat|| / ||y - mean(y)||).
/// @param y     measured output (N samples)
/// @param yhat  model output on the same samples
/// @throws InvalidArgument when the sizes differ, N < 2, a value is not finite,
///         or y is constant (the fit is undefined).
double NrmseFit(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat);

/// Integrated absolute error, trapezoidal rule on the sample times t (seconds).
/// Result in output units * seconds.
/// @throws InvalidArgument when the sizes differ, N < 2, a value is not finite
///         or t is not strictly increasing.
double Iae(const Eigen::VectorXd& t, const Eigen::VectorXd& y, const Eigen::VectorXd& yhat);

/// Integrated absolute error for uniform sampling with interval dt (seconds),
/// trapezoidal rule: dt (sum |e_k| - (|e_0| + |e_N-1|) / 2).
/// @throws InvalidArgument when the sizes differ, N < 2, dt <= 0 or a value is
///         not finite.
double Iae(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat, double dt);

/// Root mean square error (output units).
/// @throws InvalidArgument when the sizes differ, N < 1 or a value is not finite.
double Rmse(const Eigen::VectorXd& y, const Eigen::VectorXd& yhat);

/// All measures at once.
struct FitMetrics {
  double fit_percent = 0.0;    ///< NRMSE fit, percent
  double iae = 0.0;            ///< output units * s
  double rmse = 0.0;           ///< output units
  double max_abs_error = 0.0;  ///< output units
};

/// Computes FitMetrics of yhat against y on sample times t (seconds).
/// @throws InvalidArgument as NrmseFit and Iae.
FitMetrics ComputeFitMetrics(const Eigen::VectorXd& t, const Eigen::VectorXd& y,
                             const Eigen::VectorXd& yhat);

}  // namespace pneumid
