// The nonlinear identification methods of `pneumid identify --method`:
//
//   static-map   steady-state map from a staircase or slow ramp (static_map_fit.hpp)
//   hammerstein  input map + linear dynamics (hammerstein.hpp), orders na, nb, nk
//   wiener       linear dynamics + output map (hammerstein.hpp), orders na, nb, nk
//   hw           Hammerstein-Wiener: input map + linear dynamics + output map
//                (hammerstein.hpp), orders na, nb, nk
//   narx         polynomial NARX by FROLS (narx.hpp): ny = na, nu = nb, delay nk
//   affine-narx  input-affine first-order NARX with an input map (affine_narx.hpp):
//                degree of narx, knots of hammerstein, delay nk
//
// They are not part of `--method all` (identify.hpp): a plain step test has
// two input levels, from which no map follows, and the fits would only fail.
//
// An IdentifiedModel of these methods carries its nonlinear part in the
// optional members input_map (static-map, hammerstein, hw), output_map
// (wiener, hw) or narx (affine-narx: narx and input_map, the NARX in f(u));
// `discrete` is the linear part G of unit static gain (static-map: G = 1, no
// dynamics), `tf` its continuous (zoh d2c) form when it exists. The operating
// point is u0 = y0 = 0 (the maps hold the offsets). SimulateModel
// (model_evaluation.hpp) simulates them as SimulateNonlinear below.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/affine_narx.hpp"
#include "pneumid/identify/hammerstein.hpp"
#include "pneumid/identify/identified_model.hpp"
#include "pneumid/identify/narx.hpp"
#include "pneumid/identify/static_map_fit.hpp"

namespace pneumid {

/// Settings of the nonlinear methods beyond the request's orders.
struct NonlinearOptions {
  StaticMapFitOptions static_map;
  /// Knots (or their number), refinement and tolerances of hammerstein and
  /// wiener; na, nb, nk here are ignored (the request's orders are used).
  BlockModelOptions block;
  /// degree, err_tolerance, max_terms of narx; the lags come from the request.
  NarxOptions narx;
  bool IsValid(std::string* error) const;
};

/// "static-map", "hammerstein", "wiener", "hw", "narx", "affine-narx".
const std::vector<std::string>& NonlinearMethodNames();
bool IsNonlinearMethod(const std::string& name);

/// True when the model has a nonlinear part (input_map, output_map or narx).
bool IsNonlinearModel(const IdentifiedModel& model);

/// Identifies input column request.input -> output column request.output
/// with one nonlinear method and scores it on the data (fit_percent, iae).
/// Notes list the map (knots and values, dead zone, saturation) or the
/// selected NARX terms with their ERR, and the estimator's summary.
/// @throws InvalidArgument for an unknown method, invalid options, or data
///         from which the method cannot work (the estimators' messages).
IdentifiedModel IdentifyNonlinear(const std::string& method, const Dataset& data,
                                  const IdentifyRequest& request,
                                  const NonlinearOptions& options = {});

/// Simulated output of a nonlinear model on `data` (see the module comment
/// and each estimator's header): Hammerstein / static map
/// f(u(0)) + G (f(u) - f(u(0))), Wiener f(u(0) + G (u - u(0))),
/// Hammerstein-Wiener g(f(u(0)) + G (f(u) - f(u(0)))), NARX free
/// run with its first max-lag outputs from output column `output`.
/// @throws InvalidArgument for a model without nonlinear part, bad columns,
///         or a sample time that differs from the model's.
Eigen::VectorXd SimulateNonlinear(const IdentifiedModel& model, const Dataset& data, int input,
                                  int output);

}  // namespace pneumid
