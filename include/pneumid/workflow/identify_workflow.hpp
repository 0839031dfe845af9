// Identify and rank: preprocess the data, run several identification methods
// (each fails alone), flag and rank the models, and write them as a model file.
// This is the work of `pneumid identify`; the command line, the app's
// /api/identify and Python's identify_json all call RunIdentifyWorkflow, so
// that the same data and settings give the same models everywhere.
//
//   IdentifyWorkflowOptions o;
//   o.methods = "fit-p1d,arx";           // as --method: names, "all" or "auto"
//   o.preprocess.detrend = "constant";   // as --detrend, --window, ...
//   o.split = 0.7;                       // or validation data below
//   const IdentifyWorkflowResult r = RunIdentifyWorkflow(o, data);
//   r.summary.models.front();            // the best model
//   r.ToJson();                          // what `identify --json` prints
//
// Settings are given as the command line writes them (method list, loss,
// preprocessing as text), and errors name the flags.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "pneumid/data/dataset.hpp"
#include "pneumid/data/preprocess.hpp"
#include "pneumid/identify/identified_model.hpp"
#include "pneumid/identify/identify.hpp"
#include "pneumid/identify/nonlinear/nonlinear.hpp"

namespace pneumid {

/// Preprocessing as the flags give it, applied in the order of
/// PreprocessOptions (data/preprocess.hpp):
///   window "T0:T1" (either side may be empty), resample TS (s, 0 = keep),
///   remove_initial, detrend none|constant|linear, filter "lowpass:F" |
///   "bandpass:F1,F2" (Hz), decimate N (>= 1).
struct PreprocessSettings {
  std::string window;            ///< --window "T0:T1" (empty = all samples)
  double resample = 0.0;         ///< --resample Ts (0 = keep the sampling)
  bool remove_initial = false;   ///< --remove-initial: subtract the levels before the step
  std::string detrend = "none";  ///< --detrend none|constant|linear
  std::string filter;            ///< --filter spec (empty = none)
  int decimate = 1;              ///< --decimate factor (>= 1)

  /// The library options of these settings.
  /// @throws InvalidArgument naming the flag (--window, --detrend, ...) for a
  ///         malformed value, and for remove_initial together with a detrend.
  PreprocessOptions ToOptions() const;
};

/// What to identify (see the file comment).
struct IdentifyWorkflowOptions {
  /// Comma-separated method names, "all" (ParseMethodList), or "auto": the
  /// paper's reaction curve when the input is a single step, else
  /// kGeneralInputMethods (AutoMethods, identify.hpp), with a warning in
  /// summary.warnings that gives the reason.
  std::string methods = "auto";
  PreprocessSettings preprocess;  ///< applied to the data (and, as recorded, to validation data)
  IdentifyRequest request;        ///< channels and orders
  std::string loss = "none";      ///< loss of the fit-* methods: none, huber, cauchy
  NonlinearOptions nonlinear;     ///< static-map, hammerstein, wiener, hw, narx, affine-narx
  /// Estimate on the first fraction of the data and rank by the fit on the
  /// rest; 0 = no split, else in (0, 1). Not together with validation data.
  double split = 0.0;

  /// False (with the reason) for an invalid request or a split outside (0, 1).
  bool IsValid(std::string* error) const;
};

/// The models of RunIdentifyWorkflow.
struct IdentifyWorkflowResult {
  Dataset data;                   ///< the estimation data after preprocessing
  PreprocessRecord record;        ///< what the preprocessing did
  IdentificationSummary summary;  ///< models best first, each with the preprocessing record
  /// The model file: {"models": [...], "best", "ranked_by", "estimation_samples",
  /// "validation_samples", "failures", "termination", "message"}, each model
  /// with its "rank_reason" (what `identify --json` prints and `-o FILE`
  /// writes); null when no model was identified.
  nlohmann::json ToJson() const;
};

/// Preprocesses `raw` (and `validation_raw`, when given, with the recorded
/// steps and offsets of `raw`), runs the methods (IdentifyModels) and ranks
/// the models. `progress` (may be empty) is called as IdentifyModels does; an
/// exception it throws (e.g. Cancelled) ends the run.
/// When no model could be identified, summary.models is empty (the reason in
/// summary.message and summary.failures).
/// @throws InvalidArgument for invalid options, an unknown method, a split
///         together with validation data, or validation data whose channels
///         differ; DataError when the preprocessing does not suit the data.
IdentifyWorkflowResult RunIdentifyWorkflow(const IdentifyWorkflowOptions& options,
                                           const Dataset& raw,
                                           const Dataset* validation_raw = nullptr,
                                           const IdentifyProgress& progress = nullptr);

}  // namespace pneumid
