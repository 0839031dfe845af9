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
// Fit: fit = 100 (1 - ||y - yhat|| / ||y - mean(y)||) (fit_metrics.hpp) over
// the scored samples; with held-out data that continue the estimation record
// (a split), the model is simulated over the whole record and scored on the
// held-out tail only, so that its state carries over.
//
// Flags (a model is trusted only without flags; [2] sec. 16.5-16.6):
//   not_finite           the simulated output is not finite;
//   unstable             a discrete pole with |z| > 1 or a continuous pole with
//                        Re(s) > 0 (integrators, |z| = 1 or s = 0, are allowed);
//   nyquist_pole         a discrete pole within `nyquist_distance` of z = -1: a
//                        real plant sampled fast enough has none; it models a
//                        ripple aliased onto the Nyquist frequency (e.g. PWM);
//   no_convergence       the iterative estimator stopped before converging;
//   residuals_not_white  the whiteness test of resid at `confidence` fails on
//                        the model's one-step prediction errors (polynomial
//                        models with a noise model: ARX, ARMAX, BJ), or on its
//                        simulation errors (every other model, whose noise
//                        model is white output noise).
// Ranking: models without flags first, then models whose only flag is
// residuals_not_white, then the rest; within each group by validation fit
// when held-out data were given, else by estimation fit. So a flagged model
// is never ranked best while an unflagged model exists.
//
// [1] MathWorks, System Identification Toolbox, compare,
//     https://www.mathworks.com/help/ident/ref/dynamicsystem.compare.html
// [2] L. Ljung, System Identification: Theory for the User, 2nd ed., 1999.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/fit_metrics.hpp"
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
std::string ToString(InitialCondition c);
/// Parses "zero" or "estimate"; @throws InvalidArgument listing them.
InitialCondition InitialConditionFromString(const std::string& name);

/// As SimulateModel, started from the least-squares initial state of the
/// model's discrete state-space form (EstimateInitialState, initial_state.hpp;
/// a continuous model is first sampled at the data's Ts with a zero-order
/// hold) fitted to output column `output`, as MATLAB's compare(..., 'e').
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

struct ModelQualityOptions {
  /// A discrete pole p with |p + 1| <= nyquist_distance is flagged. Default
  /// 0.05; 0 disables the test. In [0, 1).
  double nyquist_distance = 0.05;
  /// Level of the residual whiteness test, in (0, 1). Default 0.99.
  double confidence = 0.99;
  /// Largest lag M of the whiteness test (MATLAB's default 25), >= 1.
  int max_lag = 25;
  bool IsValid(std::string* error) const;
};

/// The flags above of `model` on the data it was identified from (the residual
/// test needs the data; the pole tests only the model).
/// @throws InvalidArgument for invalid options or channels.
std::vector<ModelFlagNote> AssessModel(const IdentifiedModel& model, const Dataset& data,
                                       int input = 0, int output = 0,
                                       const ModelQualityOptions& options = {});

/// The ranking group of a model: 0 without flags, 1 when its only flag is
/// residuals_not_white, 2 otherwise.
int RankGroup(const IdentifiedModel& model);

/// The score that ranks a model within its group: validation_fit_percent when
/// finite, otherwise fit_percent.
double RankScore(const IdentifiedModel& model);

/// Sorts best first by (RankGroup, -RankScore); stable for ties.
void RankModels(std::vector<IdentifiedModel>* models);

}  // namespace pneumid
