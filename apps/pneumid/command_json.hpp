// The results of `control`, `tune`, `identify` and `run` as data and JSON,
// shared by those commands (their --json output) and by `pneumid app` (its
// HTTP API answers with the same JSON). The structs hold the commands'
// options; each function does the command's work without printing. The work
// of `control`, `tune`, `identify` and `run` is the library's (workflow/*.hpp):
// here only their flags and the conversion to the library's options.
#pragma once

#include <atomic>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "data_options.hpp"
#include "pneumid/control/closed_loop.hpp"
#include "pneumid/control/controller_factory.hpp"
#include "pneumid/identify/identify.hpp"
#include "pneumid/realtime/log_writer.hpp"
#include "pneumid/realtime/realtime_config.hpp"
#include "pneumid/realtime/realtime_loop.hpp"
#include "pneumid/realtime/spsc_ring_buffer.hpp"
#include "pneumid/workflow/control_scenario.hpp"
#include "pneumid/workflow/identify_workflow.hpp"
#include "pneumid/workflow/run_workflow.hpp"
#include "pneumid/workflow/tune_workflow.hpp"
#include "realtime_options.hpp"

namespace pneumid::cli {

// ---------------------------------------------------------------- control

struct ControlArgs {
  ControllerSettings controller;  // --controller, --rule, --P, ..., --u-min, --t-filter, --tau-c
  std::string model;
  std::string config;  // --config FILE.toml ([controller], [loop] period, [io] plant)
  std::string plant;
  double Ts = 0.01;
  std::string setpoint;
  double duration = 0.0;
  double noise = 0.0;
  std::uint64_t seed = 1;
  std::vector<std::string> load_steps;
  bool json = false;
  std::string plot;
  std::string output;
  bool compare_given = false;
  std::string compare;
  /// When set and true, the simulations throw Cancelled (the app: the client left).
  const std::atomic<bool>* stop = nullptr;
};

/// One closed-loop simulation of `control` (the library's scenario run).
using ControlRun = ControlScenarioRun;

/// The scenario of `control`'s flags (workflow/control_scenario.hpp).
/// @throws InvalidArgument for a bad --load-step or an empty --compare list.
ControlScenarioOptions ToScenarioOptions(const ControlArgs& c);

/// The simulations of `control` (one, or one per rule with --compare:
/// RunControlScenario), after writing -o and --plot when given.
/// @throws InvalidArgument / DataError for invalid settings or an unreadable model.
/// `warnings`, when given, receives the scenario's (ControlScenarioResult::warnings).
std::vector<ControlRun> SimulateControl(const ControlArgs& c,
                                        std::vector<std::string>* warnings = nullptr);

/// What `control --json` prints for these runs and the scenario's warnings.
nlohmann::ordered_json ControlJson(const std::vector<ControlRun>& runs,
                                   const std::vector<std::string>& warnings);

// ---------------------------------------------------------------- tune

struct TuneArgs {
  TuneWorkflowOptions options;  // every flag but --json
  bool json = false;
};


// ---------------------------------------------------------------- identify

struct IdentifyArgs {
  DataOptions data;
  PreprocessArgs preprocess;
  std::string methods = "auto";
  IdentifyRequest request;
  std::string loss = "none";
  NonlinearOptions nonlinear;
  bool json = false;
  std::string plot;
  std::string output;
  std::string validation;  ///< held-out data file (same column options)
  double split = 0.0;
  bool progress = false;
};

/// The identification of `identify`'s flags, all but the data, the output
/// files and --json (workflow/identify_workflow.hpp: RunIdentifyWorkflow, whose
/// ToJson is what `identify --json` prints and -o writes).
IdentifyWorkflowOptions ToWorkflowOptions(const IdentifyArgs& args);

// ---------------------------------------------------------------- run

struct RunArgs {
  ControllerSettings controller;  // --controller, --rule, --P, --M, --lambda, ...
  std::string model = "fopdt-paper";
  std::string setpoint = "step:from=0,to=100,at=0.5";
  RealtimeOptions rt;  // --io, --config, --plant, --Ts, --duration, --log, --json, ...
  RunSafetyOverrides safety;  // --u-min, --u-max, --rate-max, --y-min, --y-max, --frozen-samples
  bool offline = false;
  std::vector<std::string> load_steps;
  /// A model held in memory under the name `model` (the app's model objects:
  /// RunWorkflowOptions::model_document); none = a file or spec.
  std::optional<nlohmann::json> model_document;
};

/// The run of `run`'s flags, all but the real-time configuration
/// (workflow/run_workflow.hpp: RunRealtimeWorkflow, whose ToJson is what
/// `run --json` prints); the status line when stderr is a terminal and no --json.
/// @throws InvalidArgument for a bad --load-step.
RunWorkflowOptions ToWorkflowOptions(const RunArgs& args);


}  // namespace pneumid::cli
