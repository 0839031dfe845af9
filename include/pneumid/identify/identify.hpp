// The one entry point of identification: every method by name, as used by
// `pneumid identify --method`, `pneumid report`, `pneumid paper` and the
// Python function identify().
//
//   names                                   area header
//   reaction-curve tangent smith sundaresan step_methods.hpp (step-response
//   broida sopdt ptn strejc areas           methods on one analyzed step)
//   fit-p1d fit-p2d fit-p2du fit-p3d        step_methods.hpp (process models
//   fit-p1di                                fitted by Ceres, any input)
//   arx armax oe bj iv4 n4sid cra spa       parametric.hpp (black-box)
//   static-map hammerstein wiener narx      nonlinear.hpp (not in `all`: they
//                                           need a staircase / multi-level
//                                           experiment, a step test has two levels)
//
// Every method returns an IdentifiedModel (identified_model.hpp) scored on the
// data it was identified from (fit_percent, iae).
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "pneumid/common/termination.hpp"
#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/evaluation/model_evaluation.hpp"
#include "pneumid/identify/identified_model.hpp"
#include "pneumid/identify/nonlinear/nonlinear.hpp"
#include "pneumid/identify/step/step_methods.hpp"

namespace pneumid {

/// Settings of the methods beyond IdentifyRequest (channels and orders).
struct IdentifyOptions {
  /// Step analysis, tangent and fit-* settings of the step-response methods
  /// (the parametric methods take their orders from the request only).
  StepMethodOptions step;
  /// Flags that rank a model after the trusted ones (IdentifyModels).
  ModelQualityOptions quality;
  /// Settings of static-map, hammerstein, wiener and narx (their orders are
  /// the request's na, nb, nk).
  NonlinearOptions nonlinear;
  /// Held-out split for IdentifyModels: the first `split` fraction of the
  /// samples estimates, the rest validates (models simulated over the whole
  /// record, scored on the rest). 0 (default) = no split; else in (0, 1).
  double split = 0.0;
  /// How the held-out scoring starts each model's simulation: kEstimate
  /// (default; MATLAB compare's 'e') from the initial state that best explains
  /// the held-out output, for every model class (a record that does not start
  /// at rest at its first input is then no penalty on one class and not on
  /// another: a NARX starts from the measured outputs anyway), or kZero (at rest).
  InitialCondition validation_initial = InitialCondition::kEstimate;
  /// Worker threads of IdentifyModels (methods run side by side); 0 = one per
  /// hardware thread. Results do not depend on it.
  int num_threads = 0;
  /// True when step, quality and nonlinear are valid, split is 0 or in (0, 1) and
  /// num_threads >= 0; otherwise false with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// The linear method names, step-response methods first, in the order of the
/// table above (the order `all` expands to). The nonlinear methods are
/// NonlinearMethodNames() (nonlinear.hpp).
const std::vector<std::string>& IdentifyMethodNames();

/// True when `name` is one of IdentifyMethodNames() or NonlinearMethodNames().
bool IsIdentifyMethod(const std::string& name);

/// Method names from a comma-separated list such as "arx, ptn" or "all"
/// (every linear method, IdentifyMethodNames()). Blanks around names are ignored; a repeated name
/// is kept once, at its first position.
/// @throws InvalidArgument naming an unknown method, or for an empty list.
std::vector<std::string> ParseMethodList(const std::string& list);

/// The methods for a record whose input is not a single step: process-model
/// fit, ARX, OE, BJ and IV4, each simulated against the data.
inline constexpr const char* kGeneralInputMethods = "fit-p1d,arx,oe,bj,iv4";

/// What the method list "auto" stands for on `data` (channels request.input
/// and request.output): `for_a_step` when the step analysis accepts the
/// record (AnalyzeStep: one step in the input, from a steady state to a
/// steady state), else kGeneralInputMethods. *warning (may be null) is then
/// the warning that says so, with the step analysis's reason and the methods
/// chosen; it is cleared for a step test.
std::vector<std::string> AutoMethods(const Dataset& data, const IdentifyRequest& request,
                                     const std::vector<std::string>& for_a_step,
                                     std::string* warning);

/// Identifies the input column request.input -> output column request.output
/// of `data` with one method and scores the model on the data.
/// @throws InvalidArgument for an unknown method (listing the valid names),
///         an invalid request or options;
///         DataError when the data do not suit the method (no step, too short,
///         not uniformly sampled, ...).
IdentifiedModel Identify(const std::string& method, const Dataset& data,
                         const IdentifyRequest& request = {}, const IdentifyOptions& options = {});

/// Result of IdentifyModels (after Ceres' Solver::Summary).
struct IdentificationSummary {
  /// The models, ranked best first (RankModels): unflagged models by their
  /// validation fit (held-out data) or else estimation fit, then flagged ones.
  std::vector<IdentifiedModel> models;
  /// Methods that gave no model: (method, reason).
  std::vector<std::pair<std::string, std::string>> failures;
  Eigen::Index estimation_samples = 0;  ///< samples the models were estimated on
  Eigen::Index validation_samples = 0;  ///< held-out samples scored (0: none)
  /// kSuccess: every method gave a model; kPartial: some failed; kFailure: none gave one.
  Termination termination = Termination::kFailure;
  std::string message;  ///< e.g. "all 22 methods produced a model", "2 of 22 methods failed"
  /// What the held-out part cannot tell, e.g. "the last 40 % of two.csv holds a
  /// constant input (u = 60 over 240 samples): ..." (its fit scores one steady
  /// state, not the dynamics, yet the ranking and the structure search rest on
  /// it). The CLI prints them on stderr and as "warnings" in --json.
  std::vector<std::string> warnings;
  /// One line: "identify success: 22 model(s), 0 failed, best fit-p2d (99.1 %)".
  std::string BriefReport() const;
};

/// Called before each method starts and once at the end (done == total).
using IdentifyProgress =
    std::function<void(std::size_t done, std::size_t total, const std::string& method)>;

/// Runs each method on `data` (the first options.split of it when splitting);
/// a method that fails is listed in failures with its reason and the others
/// still run. Each model is flagged (AssessModel on the estimation data),
/// scored on the held-out data when given (`validation`, scored from its first
/// sample, simulated from options.validation_initial; or the split's rest;
/// where the held-out part leaves what the estimation data support, each of
/// ExtrapolationWarnings' warnings is a note "held-out part: ..."), and
/// the list is ranked (RankModels with options.quality). The nonlinear
/// methods' structure search (NonlinearOptions::choose_structure) chooses on
/// the same held-out part: `validation`, or the split's rest, named "the last
/// 30 % of FILE" in its note.
/// @throws InvalidArgument for an empty method list, an unknown method, invalid
///         request/options, a split together with a validation dataset, or a
///         validation dataset whose channels differ from the data's.
IdentificationSummary IdentifyModels(const std::vector<std::string>& methods, const Dataset& data,
                                     const IdentifyRequest& request = {},
                                     const IdentifyOptions& options = {},
                                     const Dataset* validation = nullptr,
                                     const IdentifyProgress& progress = {});

}  // namespace pneumid
