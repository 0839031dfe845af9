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
#include "pneumid/identify/identified_model.hpp"
#include "pneumid/identify/nonlinear/affine_narx.hpp"
#include "pneumid/identify/nonlinear/hammerstein.hpp"
#include "pneumid/identify/nonlinear/narx.hpp"
#include "pneumid/identify/nonlinear/static_map_fit.hpp"

namespace pneumid {

/// Settings of the nonlinear methods beyond the request's orders.
struct NonlinearOptions {
  StaticMapFitOptions static_map;  ///< level detection and map fit of static-map
  /// Knots (or their number), refinement and tolerances of hammerstein and
  /// wiener; na, nb, nk here are ignored (the request's orders are used).
  BlockModelOptions block;
  /// degree, err_tolerance, max_terms of narx; the lags come from the request.
  NarxOptions narx;
  /// hammerstein, wiener, hw: choose the orders na, nb, nk on held-out data
  /// instead of taking the request's (ChooseBlockStructure below). Off by
  /// default in the library; `pneumid identify` turns it on when none of
  /// --na, --nb, --nk is given.
  bool choose_structure = false;
  /// Estimation fraction of the internal split when the structure is chosen
  /// without held-out data; in (0, 1). Default 0.7.
  double structure_split = 0.7;
  /// Largest input delay nk the structure search tries (>= 0, default 10;
  /// narx: nk = 0 and 1 only, its lags cover longer delays).
  int max_delay = 10;
  /// narx: the largest lag ny = nu and the most terms the structure search
  /// tries (>= 1; defaults 8 and 60).
  int max_narx_lag = 8;
  int max_narx_terms = 60;  ///< narx structure search: most terms (>= 1, default 60)
  /// True when structure_split is in (0, 1), max_narx_lag and max_narx_terms >= 1,
  /// max_delay is in 0..1000 and static_map, block and narx are valid (their orders
  /// aside); otherwise false with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// One candidate of the structure search and its held-out simulation fit.
struct StructureCandidate {
  /// A order (narx: the output lags ny).
  int na = 0, nb = 0, nk = 0;  ///< input delay in samples
  /// @var nb
  /// B coefficients (narx: the input lags nu).
  int terms = 0;             ///< narx: terms of the candidate
  double fit_percent = 0.0;  ///< held-out fit; -inf when the estimate failed
  /// Simulation fit on the estimation part; -inf when the estimate failed.
  double record_fit_percent = 0.0;
  std::string error;  ///< why it failed, else empty
  /// narx: the free run on the held-out part forgets its initial outputs
  /// (see ChooseBlockStructure); false candidates are not chosen while any
  /// other is true.
  bool forgets_start = true;
};

/// The orders of a block-oriented model (hammerstein, wiener, hw) chosen by
/// the simulation fit on held-out data, as MATLAB's compare scores (each
/// candidate simulated from its estimated initial state):
///   1. the delay: nk = 0 .. max_delay with na = nb = 1, by the simulation
///      fit on the estimation part (candidates of one size; a held-out part
///      mostly measures the map between the levels it adds, not the delay);
///   2. the orders: na = 1..3, nb = 1..3 with that delay, by the held-out fit;
///   3. the most parsimonious candidate (fewest na + nb, then smaller na)
///      within 0.1 point of the best held-out fit.
/// Held-out data: `held_out` when given (scored from its first sample), else
/// the last 1 - structure_split of `data` (estimated on the first part,
/// simulated over the whole record, scored on the rest).
struct StructureChoice {
  /// Chosen A order (narx: the lags, na = nb).
  int na = 1, nb = 1, nk = 1;  ///< chosen input delay in samples
  /// @var nb
  /// Chosen number of B coefficients (narx: the lags, na = nb).
  int terms = 0;                               ///< narx: terms chosen (0 for the block models)
  double fit_percent = 0.0;                    ///< held-out simulation fit of the choice, NRMSE %
  std::string held_out;                        ///< "the last 30 % of the data" or the file
  std::vector<StructureCandidate> candidates;  ///< in the order tried
  /// "na = 1, nb = 1, nk = 2 (held-out fit 98.7 % on ...); tried: ...".
  std::string Describe() const;
};
/// @throws InvalidArgument for a method other than hammerstein, wiener, hw,
///         too few samples in either part, or when no candidate could be
///         estimated (with the first candidate's reason).
///
/// narx (options.narx.degree kept): for nk = 0, 1 and lags ny = nu =
/// 1..max_narx_lag, FROLS orders up to max_narx_terms terms on the
/// estimation part; every prefix of 1, 2, .., 10, 15, 20, .. terms is refitted by least
/// squares and simulated on the held-out part from its own first measured
/// outputs; the best held-out simulation fit wins (the most parsimonious,
/// fewest terms then shortest lags, within 0.1 point) among the candidates
/// that forget their start: the held-out run is repeated from its first
/// outputs shifted by -+25 % of the estimation output's span, and over the
/// second half of the held-out part both runs must stay within a fifth of
/// that shift (5 % of the span) of the nominal one, as the free run of a model of a
/// stable plant fades its initial state. A polynomial that fits the
/// held-out part from its measured start but runs off from a nearby one
/// (to the output band's edge) is a model a record started elsewhere breaks;
/// only when no candidate forgets its start are they all considered. The choice sets na =
/// nb = lags, nk, and `terms` (StructureChoice::terms). With options.narx.focus
/// kSimulation each prefix is refined by its simulation error on the
/// estimation part before it is scored, and IdentifyNonlinear then refines the
/// chosen candidate (its terms and theta) on all the data.
StructureChoice ChooseBlockStructure(const std::string& method, const Dataset& data,
                                     const IdentifyRequest& request,
                                     const NonlinearOptions& options,
                                     const Dataset* held_out = nullptr);

/// "static-map", "hammerstein", "wiener", "hw", "narx", "affine-narx".
const std::vector<std::string>& NonlinearMethodNames();
/// True when `name` is one of NonlinearMethodNames().
bool IsNonlinearMethod(const std::string& name);

/// True when the model has a nonlinear part (input_map, output_map or narx).
bool IsNonlinearModel(const IdentifiedModel& model);

/// Identifies input column request.input -> output column request.output
/// with one nonlinear method and scores it on the data (fit_percent, iae).
/// Notes list the map (knots and values, dead zone, saturation; the knot
/// intervals the data leave undetermined, FindMapGaps) or the selected NARX
/// terms with their ERR, and the estimator's summary.
/// @throws InvalidArgument for an unknown method, invalid options, or data
///         from which the method cannot work (the estimators' messages).
/// With options.choose_structure (hammerstein, wiener, hw) the orders come
/// from ChooseBlockStructure on `held_out` (or the internal split) and the
/// model is then estimated on all of `data`; a note states the choice.
IdentifiedModel IdentifyNonlinear(const std::string& method, const Dataset& data,
                                  const IdentifyRequest& request,
                                  const NonlinearOptions& options = {},
                                  const Dataset* held_out = nullptr);

/// Warnings for simulating `model` on input column `input` of `data`: an
/// input that leaves the input map's knot range by more than 5 % of it (the
/// map is held there: an extrapolation the estimation data do not support),
/// and an input inside an interval the estimation data left the map
/// undetermined in (IdentifiedModel::input_map_undetermined), one warning
/// per interval visited. NARX models: an input that leaves the estimation
/// input's range (the one its normalisation maps onto [-1, 1]) by more than
/// 5 % of it, and, given the model's free run on `data` (`simulated`, e.g.
/// SimulateNonlinear's), samples where that run is held at the edge of the
/// model's output band (NarxModel::y_min, y_max): the polynomial ran away
/// there, and a fit measures the band rather than the model.
std::vector<std::string> ExtrapolationWarnings(const IdentifiedModel& model, const Dataset& data,
                                               int input = 0,
                                               const Eigen::VectorXd* simulated = nullptr);

/// Simulated output of a nonlinear model on `data` (see the module comment
/// and each estimator's header), with v = f(u) (or u) and G of static gain
/// G(1): Hammerstein / static map y = G(1) v_r + G (v - v_r), Wiener and
/// Hammerstein-Wiener y = g(G(1) v_r + G (v - v_r)), the linear part at rest
/// with input v_r: the rest that gives the first measured output y(0) of
/// column `output` (v_r = y(0) / G(1), through the output map's inverse when
/// y(0) lies within its range: for a map that turns, the preimage nearest the
/// rest at the first input; beyond the map's values, the knot of the nearest
/// value, StaticMap::NearestPreimageOrEnd), or v(0) with `output` < 0 (no
/// measured output: at rest at the first input); a record that starts at
/// rest anywhere then starts right.
/// NARX: free run with its first max-lag outputs from output column `output`.
/// @throws InvalidArgument for a model without nonlinear part, bad columns,
///         or a sample time that differs from the model's.
Eigen::VectorXd SimulateNonlinear(const IdentifiedModel& model, const Dataset& data, int input,
                                  int output);

}  // namespace pneumid
