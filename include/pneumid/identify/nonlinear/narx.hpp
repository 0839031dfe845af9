// Polynomial NARX models (models/narx_model.hpp) with term selection by forward regression with
// orthogonal least squares (FROLS) and the error reduction ratio (ERR),
// method `narx` of `pneumid identify` (Billings [1] ch. 3, Chen, Billings and
// Luo [2]).
//
// Model ([1] eq. 2.58):
//   y(t) = sum_i theta_i p_i(t) + e(t),
// each term p_i a product of at most `degree` regressors from
//   y(t-1) .. y(t-ny),  u(t-nk) .. u(t-nk-nu+1),
// or the constant 1. The candidates are every such monomial: with
// n = ny + nu regressors and degree l there are C(n + l, l) of them.
// The signals enter normalised ([1] sec. 3.8 on conditioning): the input as
// (u - u_offset) / u_scale, mapping the input range of the data onto [-1, 1],
// the output as y / y_scale, y_scale = max |y| (a pure scaling, so that the
// model's terms are those of the raw output); terms and theta refer to the
// normalised signals, and the model multiplies its output by y_scale.
//
// FROLS ([1] sec. 3.5, Algorithm 1): at step s every remaining candidate p_m
// is orthogonalised against the terms chosen so far (modified Gram-Schmidt),
//   w_m = p_m - sum_{r<s} (q_r' p_m / q_r' q_r) q_r,
//   g_m = w_m' y / w_m' w_m,   ERR_m = g_m^2 w_m' w_m / y' y,
// and the one with the largest ERR becomes q_s. Selection stops when
// 1 - sum ERR < err_tolerance (the unexplained fraction of y'y, the ESR of
// [1]) or after max_terms terms. Candidates whose orthogonal part is below
// 1e-10 of their norm (linearly dependent on the chosen ones) are skipped.
// theta follows by least squares on the chosen terms (the one-step-ahead
// prediction error criterion, rows t = n0 .. N-1, n0 = max(ny, nk + nu - 1)).
//
// Focus (as the 'Focus' option of MATLAB's nlarx): kPrediction keeps theta
// of the one-step least squares above; kSimulation refines theta over the
// chosen terms by minimising the free-run simulation error from that start
// (Levenberg-Marquardt, narx_simulation_fit.hpp), which on data the one-step
// criterion fits but the free run does not (e.g. the cascaded tanks) gives a
// model that simulates better; the terms are those FROLS chose.
//
// Simulation (free run, the simulation-error check of [1] sec. 3.9): yhat(t)
// from the model with yhat in place of y; the first n0 outputs are taken from
// the measured output (the model's past before it can predict).
//
// JSON form: {"ny": 2, "nu": 2, "nk": 1, "degree": 2, "Ts": 0.01,
//   "terms": ["1", "y(t-1)", "y(t-2)^2", "u(t-1)*y(t-1)"], "theta": [...], "err": [...],
//   "u_offset": 50, "u_scale": 50, "y_scale": 193}  (the last three optional: 0, 1, 1).
//
// [1] S. A. Billings, Nonlinear System Identification: NARMAX Methods in the
//     Time, Frequency, and Spatio-Temporal Domains, Wiley, 2013.
// [2] S. Chen, S. A. Billings, W. Luo, Orthogonal least squares methods and
//     their application to non-linear system identification, Int. J. Control
//     50 (1989) 1873-1896.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "pneumid/identify/parametric/parametric_model.hpp"
#include "pneumid/models/narx_model.hpp"

namespace pneumid {

/// Criterion of the NARX coefficients (see above).
enum class NarxFocus {
  kPrediction,  ///< one-step prediction error (least squares), the default
  kSimulation,  ///< free-run simulation error, refined from the least-squares start
};

/// "prediction" or "simulation".
const char* ToString(NarxFocus focus);
/// Inverse of ToString(NarxFocus).
/// @throws InvalidArgument for another name (listing the valid ones).
NarxFocus NarxFocusFromString(const std::string& name);

/// Lags, degree and term-selection stop rule of the polynomial NARX estimate (FROLS).
struct NarxOptions {
  int ny = 2;      ///< output lags (>= 0)
  int nu = 2;      ///< input lags (>= 1)
  int nk = 1;      ///< input delay (>= 0)
  int degree = 2;  ///< polynomial degree, 1..3
  /// Stop when the unexplained fraction 1 - sum ERR drops below this; in
  /// (0, 1). ERR is a share of y'y (not centred): on slow dynamics sampled
  /// fast y(t-1) alone explains 99.9 % of it, so the default 1e-7 leaves the
  /// stop to max_terms unless the data are nearly noise-free.
  double err_tolerance = 1e-7;
  int max_terms = 10;  ///< at most this many terms (>= 1)
  /// Normalise the signals (see above); false: u_offset = 0, scales 1.
  bool normalise = true;
  /// Criterion of theta (see above); the terms are chosen by FROLS either way.
  NarxFocus focus = NarxFocus::kPrediction;
  /// kSimulation: most Levenberg-Marquardt iterations (>= 1).
  int max_iterations = 100;
  /// True when ny >= 0, nu >= 1, nk >= 0, degree is 1..3, err_tolerance is in (0, 1),
  /// max_terms >= 1 and max_iterations >= 1; otherwise false with the reason in *error
  /// (when error is not null).
  bool IsValid(std::string* error) const;
};

/// Every candidate monomial of the options (constant first, then by degree
/// and regressor index).
std::vector<NarxTerm> NarxCandidates(int ny, int nu, int degree);

/// Polynomial NARX model chosen by FROLS and its fits.
struct NarxResult {
  /// Selected terms with their coefficients theta and ERR, the lags, Ts and the
  /// normalisation (u_offset, u_scale, y_scale).
  NarxModel model;
  /// termination (kConvergence; kSimulation: that of the refinement, see
  /// narx_simulation_fit.hpp), num_parameters = terms chosen, loss = mean
  /// squared one-step error (kSimulation: simulation error), message naming
  /// the stopping rule (and the refinement).
  EstimationSummary summary;
  double one_step_fit_percent = 0.0;    ///< NRMSE fit of the one-step predictions
  double simulation_fit_percent = 0.0;  ///< NRMSE fit of the free-run simulation
};

/// NARX model of input u and output y sampled every Ts seconds.
/// @throws InvalidArgument for invalid options, lengths that differ,
///         non-finite values, an output that is zero throughout, a constant
///         input (with normalisation), or more candidate terms
///         than regression rows (naming both numbers and the orders).
NarxResult EstimateNarx(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double Ts,
                        const NarxOptions& options = {});

/// NRMSE fit (%) of the model's free run (Simulate(u, y)) over the last
/// `rows` samples of y; -infinity, with a warning added, when it diverges.
double NarxSimulationFit(const NarxModel& m, const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                         Eigen::Index rows, std::vector<std::string>* warnings);

}  // namespace pneumid
