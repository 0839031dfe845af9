// The step-response methods of `pneumid identify` behind one entry point, and
// the scoring every identified model gets against the data.
//
//   method          structure  header
//   reaction-curve  FOPDT      reaction_curve.hpp (the paper's method)
//   tangent         FOPDT      tangent.hpp (Ziegler-Nichols)
//   smith           FOPDT      two_point.hpp (28.3 / 63.2 %)
//   sundaresan      FOPDT      two_point.hpp (35.3 / 85.3 %)
//   broida          FOPDT      two_point.hpp (28 / 40 %)
//   sopdt           SOPDT      sopdt.hpp (three-point, 20 / 50 / 80 %)
//   ptn             PTn        ptn.hpp (tangent-line method, order request.order)
//   strejc          Strejc     strejc.hpp (n equal lags)
//   areas           FOPDT      areas.hpp (characteristic areas / moments)
//   fit-p1d ... fit-p1di       process_model.hpp (Ceres output-error fit)
//
// Scoring (fit_metrics.hpp): the model is simulated on the whole input of the
// data in deviation variables, yhat = y0 + lsim(G, u - u0), with u0 the input
// before its first change and y0 the model's "y0" parameter when it has one,
// the mean output before the first input change otherwise; fit_percent is the
// NRMSE fit and iae the integrated absolute error of y - yhat.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/identified_model.hpp"
#include "pneumid/identify/parametric/process_model.hpp"
#include "pneumid/identify/step/step_analysis.hpp"
#include "pneumid/identify/step/tangent.hpp"

namespace pneumid {

/// Settings of the step-response methods beyond IdentifyRequest.
struct StepMethodOptions {
  StepAnalysisOptions step;  ///< how the step, the tail and the noise band are found
  TangentOptions tangent;    ///< inflection-tangent settings of the tangent-based methods
  /// Options of the fit-* methods (structure and zero are set from the method name).
  ProcessFitOptions fit;
  /// True when step, tangent and fit are all valid; otherwise false with the first reason
  /// in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// The method names in the order of the table above.
const std::vector<std::string>& StepMethodNames();

/// True when `name` is one of StepMethodNames().
bool IsStepMethod(const std::string& name);

/// Runs one step-response method on input column request.input and output
/// column request.output of `data`, and scores the model (fit_percent, iae).
/// @throws InvalidArgument for an unknown method or invalid request/options;
///         DataError when the data do not suit the method (see step_analysis.hpp).
IdentifiedModel IdentifyStepMethod(const std::string& method, const Dataset& data,
                                   const IdentifyRequest& request,
                                   const StepMethodOptions& options = {});

/// Simulated output of model `g` on the data (see the header comment); y0 is
/// the output offset, NaN = the mean output before the first input change.
/// @throws InvalidArgument when a discrete model's Ts differs from the data's.
Eigen::VectorXd SimulateOnData(const TransferFunction& g, const Dataset& data, int input = 0,
                               int output = 0,
                               double y0 = std::numeric_limits<double>::quiet_NaN());

}  // namespace pneumid
