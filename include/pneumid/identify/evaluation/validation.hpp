// Model validation on data: simulation and k-step-ahead prediction fit, and
// estimation/validation splits (MATLAB compare, predict, sim).
//
//   fit [%] = 100 (1 - ||y - yhat|| / ||y - mean(y)||)          (NRMSE, [1])
// with yhat the noise-free simulation (horizon = infinity) or the k-step-ahead
// prediction yhat(t|t-k) of parametric_model.hpp. Initial conditions are zero
// (the data are assumed to start at rest); the first `skip` samples can be left
// out of the fit to reduce the influence of that assumption.
//
// [1] MathWorks, System Identification Toolbox, compare,
//     https://www.mathworks.com/help/ident/ref/dynamicsystem.compare.html
#pragma once

#include <string>
#include <utility>

#include <Eigen/Core>

#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/parametric/parametric_model.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// Prediction horizon, skipped samples and columns of a model-versus-data comparison.
struct CompareOptions {
  /// Prediction horizon k in samples; 0 means infinity (pure simulation).
  int horizon = 0;
  /// Number of initial samples excluded from the fit (>= 0).
  int skip = 0;
  int input = 0;   ///< input column (SISO models)
  int output = 0;  ///< output column
  /// True when horizon, skip, input and output are >= 0; otherwise false with the reason in
  /// *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// Measured and simulated (or k-step predicted) output and the fit measures.
struct CompareResult {
  Eigen::VectorXd t;     ///< seconds
  Eigen::VectorXd y;     ///< measured output
  Eigen::VectorXd yhat;  ///< simulated or predicted output
  /// NRMSE fit over the samples after `skip`, %; -inf when yhat is not finite.
  double fit_percent = 0.0;
  double rmse = 0.0;  ///< root-mean-square error over the same samples (output units)
  int horizon = 0;  ///< 0 = simulation
};

/// Fit of a polynomial model on `data` (all input columns if the model has
/// several inputs, otherwise column options.input).
/// @throws InvalidArgument for invalid options or a model/data mismatch.
CompareResult Compare(const PolynomialModel& model, const Dataset& data,
                      const CompareOptions& options = {});

/// Fit of any transfer function, simulated at rest at 0 by SimulateModel
/// (model_evaluation.hpp: continuous models with a zero-order hold on the
/// data's sample times; discrete models at their Ts).
/// Only simulation (horizon 0) is defined for a transfer function without a noise model.
/// @throws InvalidArgument for horizon != 0, or a discrete model whose Ts
///         differs from the data's sample time.
CompareResult Compare(const TransferFunction& model, const Dataset& data,
                      const CompareOptions& options = {});

/// Splits a data set into its first `fraction` of samples (estimation) and the
/// rest (validation), e.g. 0.7 for 70 / 30 %.
/// @throws InvalidArgument unless 0 < fraction < 1 and both parts hold >= 2 samples.
std::pair<Dataset, Dataset> SplitDataset(const Dataset& data, double fraction);

/// Samples [begin, end) of a data set (channels and source kept).
/// @throws InvalidArgument when the range is empty or out of bounds.
Dataset SliceDataset(const Dataset& data, Eigen::Index begin, Eigen::Index end);

}  // namespace pneumid
