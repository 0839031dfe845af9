// Process-model fitting by output-error nonlinear least squares (MATLAB
// `procest` structures [1]) with Ceres Solver [2].
//
//   structure  model (delay theta >= 0 in seconds, a continuous parameter)
//   P1D        K (1 + Tz s) / (T1 s + 1)                         exp(-theta s)
//   P2D        K (1 + Tz s) / ((T1 s + 1)(T2 s + 1))             exp(-theta s)
//   P2DU       K (1 + Tz s) / (Tw^2 s^2 + 2 zeta Tw s + 1)       exp(-theta s)
//   P3D        K (1 + Tz s) / ((T1 s + 1)(T2 s + 1)(T3 s + 1))   exp(-theta s)
//   P1DI       K (1 + Tz s) / (s (T1 s + 1))                     exp(-theta s)
// The zero factor (1 + Tz s) is present only with `zero` (MATLAB's "Z" suffix).
//
// Data are taken in deviation variables around the initial steady state:
// u0 = the input before its first change, y0 = an output offset (estimated
// with the other parameters unless `estimate_offset` is false, then the mean
// output before the first input change). The model output
//   yhat[k] = y0 + lsim(G, u - u0)[k]
// is the exact response to the sampled input held between samples (lti
// Lsim; a fractional delay is exact), so any input can be used, not only a
// step. The fit minimizes sum_k rho((y[k] - yhat[k])^2) / 2 with rho the
// identity (least squares), Huber or Cauchy loss, under the bounds
//   T1, T2, T3, Tw > 1e-3 Ts,  0.001 <= zeta <= 1 (P2DU),  0 <= theta <= max_delay.
// Jacobians by finite differences that stay inside the bounds. The initial
// guess comes from the graphical methods when the data, or their first step
// (up to the next input change), are a clean settled step (reaction curve for
// P1D, three-point SOPDT for P2D/P2DU/P3D); for P1DI from the final ramp;
// otherwise from a grid search over 16 lags (2 Ts to a quarter of the record)
// and delays (0, 0.1, 0.3, 1 lag, and 0, 1, 2, 3 samples then 1.4 times
// apart up to a quarter of the record) with K and y0 by linear least
// squares. The model is y = y0 + G (u - u0) with u0 the input's rest before
// the record: the input before its first change; when the input changes
// within the first max(3, N/100) samples (white noise, a chirp, a PRBS
// from the start: no rest), also zero and the input's mean, each fitted
// from its best grid point, the lowest cost kept (P1DI then also from the
// grid, the ramp's lag and delay among its points).
// With a zero, the fit starts from the converged model without it, with Tz = 0
// and Tz = +-(second lag, at least T1/5); the lowest cost is kept.
// Parameter standard deviations: sigma^2 = 2 cost / (N - p) and
// cov = sigma^2 (J^T J)^-1 at the solution (Ceres Covariance [2]).
//
// [1] MathWorks, System Identification Toolbox, procest / idproc,
//     https://www.mathworks.com/help/ident/ref/procest.html
// [2] S. Agarwal, K. Mierle et al., Ceres Solver, http://ceres-solver.org
//     (Problem, Solver, Covariance).
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pneumid/common/termination.hpp"
#include "pneumid/data/dataset.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// Process model structure (table above): first, second (real or underdamped) or third
/// order lag with delay, or first-order lag plus integrator with delay.
enum class ProcessStructure { kP1D, kP2D, kP2DU, kP3D, kP1DI };

/// "P1D", "P2D", "P2DU", "P3D", "P1DI".
std::string ToString(ProcessStructure structure);
/// Inverse of ToString, case-insensitive; a trailing "Z" (e.g. "P2DZ") sets
/// *zero when zero is not null. Throws InvalidArgument listing the valid names.
ProcessStructure ProcessStructureFromString(const std::string& name, bool* zero = nullptr);

/// Loss rho applied to the squared output errors: least squares, or Huber / Cauchy to
/// reduce the weight of outliers beyond ProcessFitOptions::loss_scale.
enum class RobustLoss { kNone, kHuber, kCauchy };
/// "none", "huber", "cauchy".
std::string ToString(RobustLoss loss);
/// Inverse of ToString; throws InvalidArgument listing the valid names.
RobustLoss RobustLossFromString(const std::string& name);

/// Named parameters of a process model (unused ones stay 0). Times in seconds,
/// K in output units per input unit, y0 in output units.
struct ProcessParams {
  /// Static gain; P1DI: integrator gain (output units per input unit and second).
  double K = 0.0;
  double T1 = 0.0;    ///< first real lag (time constant), s (every structure but P2DU)
  double T2 = 0.0;    ///< second real lag, s (P2D, P3D)
  double T3 = 0.0;    ///< third real lag, s (P3D)
  double Tw = 0.0;    ///< P2DU natural period, s (1 / natural frequency)
  double zeta = 0.0;  ///< P2DU damping
  double Tz = 0.0;                      ///< zero time constant, s
  double theta = 0.0;                   ///< delay
  double y0 = 0.0;                      ///< output offset (initial steady state)
  /// Input of that steady state (not fitted): the model is
  /// y = y0 + G (u - u0). NaN in a guess: the input before its first change;
  /// FitProcessModel's result always gives the one it used.
  double u0 = std::numeric_limits<double>::quiet_NaN();

  /// Every field equal (a NaN u0 equals nothing).
  bool operator==(const ProcessParams&) const = default;
};

/// Structure, loss and Levenberg-Marquardt settings of FitProcessModel.
struct ProcessFitOptions {
  ProcessStructure structure = ProcessStructure::kP1D;  ///< model to fit (default P1D)
  bool zero = false;            ///< include (1 + Tz s)
  bool estimate_offset = true;  ///< estimate y0 with the other parameters
  RobustLoss loss = RobustLoss::kNone;  ///< loss on the output errors (default least squares)
  /// Loss scale in output units; 0 = 1.345 (Huber) or 2.385 (Cauchy) times a
  /// robust noise estimate from the data (default 0).
  double loss_scale = 0.0;
  /// Upper bound of the delay in seconds; 0 = half the record (default 0).
  double max_delay = 0.0;
  int max_iterations = 200;            ///< Levenberg-Marquardt iterations (default 200)
  double function_tolerance = 1e-12;   ///< relative cost change to stop (default 1e-12)
  double parameter_tolerance = 1e-10;  ///< relative step to stop (default 1e-10)
  /// True when loss_scale and max_delay are finite and >= 0, max_iterations >= 1 and the
  /// tolerances > 0; otherwise false with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

// Termination here: kConvergence, kNoConvergence or kFailure, written "convergence",
// "no_convergence", "failure" (common/termination.hpp).

/// How the process-model fit went (after Ceres' Solver::Summary).
struct ProcessFitSummary {
  /// Ceres' termination; kFailure also when the fitted model cannot be simulated.
  Termination termination = Termination::kFailure;
  std::string message;  ///< Ceres' message on the termination
  std::string initial_guess;  ///< where the initial guess came from
  int iterations = 0;  ///< Levenberg-Marquardt iterations
  double initial_cost = 0.0;  ///< 0.5 sum rho(e^2) at the initial guess
  double final_cost = 0.0;    ///< 0.5 sum rho(e^2) at the solution (output units^2)
  double sigma = 0.0;          ///< residual standard deviation (output units)
  bool covariance_ok = false;  ///< standard deviations available
  /// One line: "process fit: convergence after 12 iterations, cost 3.2 -> 0.014, residual
  /// std 0.012, initial guess from ..." with Ceres' message in parentheses.
  std::string BriefReport() const;
};

/// Fitted process model: parameters, their uncertainty, transfer function and simulation.
struct ProcessFitResult {
  ProcessStructure structure = ProcessStructure::kP1D;  ///< structure that was fitted
  bool zero = false;     ///< the model has the zero (1 + Tz s)
  ProcessParams params;  ///< estimated parameters (those of other structures stay 0)
  ProcessParams param_std;  ///< standard deviations (NaN when not available)
  /// Covariance of the estimated parameters in physical units,
  /// sigma^2 (J^T J)^+ (empty when not available), rows and columns named by
  /// covariance_names (the names of NamedParams: K, tau or tau1.., Tw, zeta,
  /// Tz, theta, y0, for the parameters that were estimated).
  Eigen::MatrixXd covariance;
  std::vector<std::string> covariance_names;  ///< names of the rows/columns of `covariance`
  TransferFunction tf;   ///< the fitted model (continuous, with delay)
  Eigen::VectorXd yhat;  ///< simulated output on the data samples
  ProcessFitSummary summary;  ///< termination, costs, residual std and initial guess
};

/// Transfer function of a structure with given parameters.
/// @throws InvalidArgument for non-positive time constants or a negative delay.
TransferFunction ProcessTransferFunction(ProcessStructure structure, bool zero,
                                         const ProcessParams& p);

/// Names and values of the parameters a structure uses, in the order K,
/// time constants, Tz, theta, y0: e.g. P1D -> {"K", "tau", "theta", "y0"}
/// (FOPDT naming), P2D -> {"K", "tau1", "tau2", "theta", "y0"},
/// P2DU -> {"K", "Tw", "zeta", ...}, P3D -> tau1..tau3, P1DI -> {"K", "tau", ...}.
std::vector<std::pair<std::string, double>> NamedParams(ProcessStructure structure, bool zero,
                                                        const ProcessParams& p);

/// Initial guess for a structure from the data (see the header comment);
/// `source` (optional) receives a short description of where it came from.
ProcessParams InitialProcessGuess(const Dataset& data, int input, int output,
                                  ProcessStructure structure, bool zero,
                                  std::string* source = nullptr);

/// Fits a process model to input column `input` and output column `output`.
/// `initial` overrides the automatic initial guess when not null.
/// @throws InvalidArgument for invalid options or columns; DataError when the
///         data are not uniformly sampled, too short (fewer than 10 samples or
///         than parameters) or the input never changes. Numerical failure is
///         reported in result.summary.
ProcessFitResult FitProcessModel(const Dataset& data, int input, int output,
                                 const ProcessFitOptions& options,
                                 const ProcessParams* initial = nullptr);

}  // namespace pneumid
