// Evaluating identified models on data: one simulation convention, one fit
// definition, quality flags and the ranking of candidate models, shared by
// `pneumid identify`, `validate`, `report`, `paper` and the Python API.
//
// Simulation (MATLAB compare with zero initial conditions [1]):
//   yhat(t) = y0 + G(q) (u(t) - u0),  G started at rest,
// with (u0, y0) the model's operating point (IdentifiedModel::u0, y0) and G
// its discrete form when it has one (polynomial, state-space and FIR models),
// otherwise its continuous transfer function under a zero-order hold.
// Nonlinear models (static map, Hammerstein, Wiener, NARX) are simulated by
// SimulateNonlinear (nonlinear.hpp): the linear part at rest at the first
// input sample, a NARX model from its first measured outputs (output column 0
// in the three-argument SimulateModel, `output` elsewhere).
// SimulateModel is the toolkit's one simulation of a model on data: the step
// methods' SimulateOnData (step_methods.hpp) and Compare of a transfer
// function (validation.hpp) go through it.
// Fit: fit = 100 (1 - ||y - yhat|| / ||y - mean(y)||) (fit_metrics.hpp) over
// the scored samples; with held-out data that continue the estimation record
// (a split), the model is simulated over the whole record and scored on the
// held-out tail only, so that its state carries over.
//
// Flags ([2] sec. 16.5-16.6):
//   not_finite           the simulated output is not finite;
//   unstable             a discrete pole with |z| > 1 or a continuous pole with
//                        Re(s) > 0 (integrators, |z| = 1 or s = 0, are allowed);
//   nyquist_pole         a discrete pole within `nyquist_distance` of z = -1: a
//                        real plant sampled fast enough has none; it models a
//                        ripple aliased onto the Nyquist frequency (e.g. PWM);
//   no_convergence       the iterative estimator stopped before converging;
//   residuals_not_white  the whiteness test of resid at `confidence` fails on
//                        the model's simulation errors (every class; for ARX,
//                        ARMAX and BJ the note adds the test of the one-step
//                        prediction errors).
// Ranking by evidence: within each group by the held-out simulation fit when
// held-out data were given (by the fit on the held-out samples the estimation
// data determine, IdentifiedModel::determined_fit_percent, when the held-out
// data visit input intervals the estimation data leave undetermined), else
// by the estimation fit; the groups are
// 0 (no flag, or only no_convergence / residuals_not_white: flagged, but
// its fit is what it is), 1 (nyquist_pole), 2 (unstable, not_finite). So a
// model whose estimator stopped early but validates best is ranked best,
// with its flag and RankReason saying so.
//
// [1] MathWorks, System Identification Toolbox, compare,
//     https://www.mathworks.com/help/ident/ref/dynamicsystem.compare.html
// [2] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/identified_model.hpp"

namespace pneumid {

/// yhat = y0 + G (u - u0) on input column `input` of `data` (see above).
/// @throws InvalidArgument when the input column does not exist, or a discrete
///         model's sample time differs from the data's.
Eigen::VectorXd SimulateModel(const IdentifiedModel& model, const Dataset& data, int input = 0);

/// How a simulation on data starts (MATLAB compare's 'InitialCondition').
enum class InitialCondition {
  kZero,      ///< "zero": at rest at the operating point (the default everywhere)
  kEstimate,  ///< "estimate": the state that best explains the measured output
};
/// "zero" or "estimate".
std::string ToString(InitialCondition c);
/// Parses "zero" or "estimate"; @throws InvalidArgument listing them.
InitialCondition InitialConditionFromString(const std::string& name);

/// As SimulateModel, started from the least-squares initial state of the
/// model's discrete state-space form (EstimateInitialState, initial_state.hpp;
/// a continuous model is first sampled at the data's Ts with a zero-order
/// hold) fitted to output column `output`, as MATLAB's compare(..., 'e').
/// Block-oriented models estimate the initial state of their linear part
/// (least squares for Hammerstein; through the output map of a Wiener or
/// Hammerstein-Wiener model by Gauss-Newton from the state at rest at the
/// first input); a NARX starts from the measured outputs with either choice.
/// @throws InvalidArgument as SimulateModel or for a bad output column.
Eigen::VectorXd SimulateModel(const IdentifiedModel& model, const Dataset& data, int input,
                              int output, InitialCondition initial);

/// Fit measures of the model simulated on `data`, over samples [score_from, N).
/// A model whose simulation is not finite gets fit -inf and IAE/RMSE inf.
/// @throws InvalidArgument as SimulateModel, for a bad output column, or
///         score_from outside [0, N - 2].
FitMetrics EvaluateModel(const IdentifiedModel& model, const Dataset& data, int input = 0,
                         int output = 0, Eigen::Index score_from = 0);

/// Fit measures of a simulated output `yhat` (N samples) against output
/// column `output` over samples [score_from, N): EvaluateModel's scoring, for
/// a simulation made otherwise (e.g. from an estimated initial state).
/// A non-finite yhat there gives fit -inf and IAE/RMSE inf.
/// @throws InvalidArgument for a bad output column, a size mismatch or
///         score_from outside [0, N - 2].
FitMetrics ScoreSimulation(const Dataset& data, int output, const Eigen::VectorXd& yhat,
                           Eigen::Index score_from = 0);

/// Sets model->fit_percent and model->iae from EvaluateModel on all samples.
void ScoreModel(const Dataset& data, int input, int output, IdentifiedModel* model);

/// Thresholds of the checks AssessModel flags a model by (pole near z = -1, whiteness
/// of the residuals).
struct ModelQualityOptions {
  /// A discrete pole p with |p + 1| <= nyquist_distance is flagged. Default
  /// 0.05; 0 disables the test. In [0, 1).
  double nyquist_distance = 0.05;
  /// Level of the residual whiteness test, in (0, 1). Default 0.99.
  double confidence = 0.99;
  /// Largest lag M of the whiteness test (MATLAB's default 25), >= 1.
  int max_lag = 25;
  /// Parsimony of the ranking (RankModels): models of one group whose
  /// simulation errors (100 - RankScore, the normalised RMSE in %) lie within
  /// this fraction of the best remaining model's count as tied, and the one
  /// with the fewest parameters (ParameterCount) ranks first, as the
  /// one-standard-error rule of cross-validation prefers the simplest model
  /// the evidence cannot tell from the best (Hastie, Tibshirani and Friedman,
  /// "The Elements of Statistical Learning", 2nd ed., 2009, sec. 7.10).
  /// Default 0.05 (errors within 5 %); 0 ranks by the score alone. In [0, 1).
  double parsimony_tolerance = 0.05;
  /// True when nyquist_distance is in [0, 1), confidence in (0, 1), max_lag >= 1
  /// and parsimony_tolerance in [0, 1);
  /// otherwise false with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// The flags above of `model` on the data it was identified from (the residual
/// test needs the data; the pole tests only the model). The whiteness test
/// runs on the simulation errors y - yhat of every model class; for a model
/// with a noise model (ARX, ARMAX, BJ) the note adds the test of its one-step
/// prediction errors as extra information.
/// @throws InvalidArgument for invalid options or channels.
std::vector<ModelFlagNote> AssessModel(const IdentifiedModel& model, const Dataset& data,
                                       int input = 0, int output = 0,
                                       const ModelQualityOptions& options = {});

/// The ranking group of a model: 2 when its simulation cannot be trusted
/// (flags not_finite or unstable), 1 for a pole near z = -1 (nyquist_pole),
/// 0 otherwise. no_convergence and residuals_not_white do not move a model to
/// a later group: the fit is the evidence (an estimator that stopped on its
/// iteration limit may still hold the best model; simulation errors of a
/// good model of a noisy plant are rarely white).
int RankGroup(const IdentifiedModel& model);

/// The score that ranks a model within its group: validation_fit_percent when
/// finite, otherwise fit_percent.
double RankScore(const IdentifiedModel& model);

/// One line on why the model stands where it does, e.g. "held-out simulation
/// fit 97.01 %; flagged no_convergence, ranked by its fit all the same", with
/// "its structure was chosen on the same held-out data" for a model whose
/// structure search scored on them (its fit includes that choice) and the
/// model's rank_note when parsimony placed it (RankModels).
std::string RankReason(const IdentifiedModel& model);

/// The free parameters of a model: the coefficients of its linear part (the
/// discrete form when it has one: denominator after its leading 1, numerator
/// from its first nonzero coefficient; plus 1 for the dead time of a
/// continuous model),
/// the knot values of its input and output maps, and the terms of its NARX
/// part (whose linear part is a placeholder and does not count).
int ParameterCount(const IdentifiedModel& model);

/// Sorts best first by (RankGroup, -RankScore), then, with
/// options.parsimony_tolerance > 0, takes each place in turn for the model
/// with the fewest parameters among those of the group whose simulation
/// error lies within the tolerance of the best remaining one's (ties by the
/// score); such a model's rank_note names the better-scoring models it was
/// preferred to. Stable for equal scores.
/// @throws InvalidArgument for a null list or invalid options.
void RankModels(std::vector<IdentifiedModel>* models, const ModelQualityOptions& options = {});

}  // namespace pneumid
