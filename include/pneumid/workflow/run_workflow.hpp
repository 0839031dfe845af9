// A closed loop in real time: a controller (DMC, GPC, PID or MPC) designed from
// a model, run on the I/O backend of a real-time configuration (the simulator,
// a plant server over UDP or a Comedi card) with the safety layer, a log and
// timing statistics, and the closed-loop metrics of the run. This is the work
// of `pneumid run`; the command line and the app's /api/run/start both call
// RunRealtimeWorkflow, so that the same settings give the same run everywhere.
//
//   RealtimeConfig config;                  // realtime/realtime_config.hpp
//   config.loop.duration = 2;
//   config.loop.fast = true;                // sim only: as fast as possible
//   RunWorkflowOptions o;
//   o.model = "fopdt-paper";                // controller model spec (model_io.hpp)
//   o.controller.controller = "pid";        // ControllerSettings
//   o.setpoint = "step:from=0,to=80,at=0.5";
//   o.offline = true;                       // also the same scenario simulated offline
//   const RunWorkflowResult r = RunRealtimeWorkflow(o, config);
//   r.ToJson();                             // what `run --json` prints
//
// Without an output clamp from the options or the configuration ([safety]
// u_min/u_max), the loop clamps to the plant's input range where it is finite
// (the position twin's -100..100 %). Settings are given as the command line
// writes them, and errors name the flags.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pneumid/control/closed_loop.hpp"
#include "pneumid/control/controller_factory.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/realtime/log_writer.hpp"
#include "pneumid/realtime/realtime_config.hpp"
#include "pneumid/realtime/realtime_loop.hpp"
#include "pneumid/realtime/safety.hpp"
#include "pneumid/realtime/spsc_ring_buffer.hpp"

namespace pneumid {

/// Safety settings given for one run over those of the configuration
/// (RealtimeConfig::safety); each one left unset keeps the configuration's.
struct RunSafetyOverrides {
  std::optional<double> u_min;        ///< --u-min: output clamp, lower (input units)
  std::optional<double> u_max;        ///< --u-max: output clamp, upper
  std::optional<double> rate_max;     ///< --rate-max: output rate limit per s (0 = none)
  std::optional<double> y_min;        ///< --y-min: measurement range, lower (output units)
  std::optional<double> y_max;        ///< --y-max: measurement range, upper
  std::optional<int> frozen_samples;  ///< --frozen-samples: frozen-sensor count (0 = off)

  /// True when u_min or u_max is set (the loop then does not take the plant's range).
  bool GivesClamp() const { return u_min.has_value() || u_max.has_value(); }
  /// Writes the settings given into `safety`.
  void ApplyTo(SafetyOptions& safety) const;
  /// False (with the reason, naming the flag) for a limit that is not finite,
  /// u_min >= u_max or y_min >= y_max when both are given, a negative rate_max
  /// or frozen_samples.
  bool IsValid(std::string* error) const;
};

/// What to run (see the file comment); the loop, the backend, the plant and
/// the safety defaults are the RealtimeConfig's. Its [controller] section
/// (RealtimeConfig::controller) is not read here: the caller applies it to
/// `model` and `controller` first (the command line: unless a flag overrides it).
struct RunWorkflowOptions {
  /// Type, rule, horizons, gains, ...; its input limits are replaced by the
  /// safety layer's output clamp.
  ControllerSettings controller;
  /// Model spec the controller is designed from (ParseControllerModel).
  std::string model = "fopdt-paper";
  /// The JSON of a model file held in memory under the name `model`
  /// (ModelFileScope::Provide for the run); none = `model` is a file or a spec.
  std::optional<nlohmann::json> model_document;
  std::string setpoint = "step:from=0,to=100,at=0.5";  ///< set-point signal spec (signal.hpp)
  /// Load disturbances on the output: applied by the sim backend and the
  /// offline simulation; with another backend they say when the plant's load
  /// changes, for the metrics.
  std::vector<LoadStep> load_steps;
  /// Also simulate the same scenario offline on RealtimeConfig::plant (no real
  /// time, no I/O) and report its metrics.
  bool offline = false;
  PlantOptions plant_options;  ///< seed and noise of the simulated plant (sim backend, offline)
  RunSafetyOverrides safety;   ///< over RealtimeConfig::safety
  /// Log file (.csv streamed, .mat written at the end); empty = none.
  std::string log;
  /// Redraw a one-line status on stderr while the loop runs (a terminal's).
  bool live_status = false;
  /// Receives, before the loop starts, what the run asks that the
  /// controller's model says it cannot do (UnreachableSetpointWarning); none
  /// = not reported.
  std::function<void(const std::string&)> warn;

  /// False (with the reason, naming the flag) for an empty model or set-point,
  /// a load step that is not finite or before t = 0, invalid safety overrides
  /// (RunSafetyOverrides::IsValid) or plant options (PlantOptions::IsValid).
  bool IsValid(std::string* error) const;
};

/// How a run went: the loop's summary and the run's metrics.
struct RunWorkflowResult {
  LoopSummary summary;        ///< termination, timing statistics, scheduling, ...
  std::string controller;     ///< the controller's description
  std::string io;             ///< the backend's description
  std::string log;            ///< the log file (RunWorkflowOptions::log; empty = none)
  std::int64_t log_rows = 0;  ///< records written to the log
  nlohmann::json metrics;     ///< closed-loop metrics (ClosedLoopMetrics), null unless completed
  nlohmann::json offline;     ///< metrics of the offline simulation, null unless asked for
  /// LoopSummary::ToJson with controller, io, log, log_rows, metrics and, when
  /// the offline simulation ran, offline_metrics: what `run --json` prints.
  nlohmann::json ToJson() const;
};

/// Runs the loop of `options` with `config` (its safety settings with
/// options.safety applied). `live` (may be null) receives a copy of every
/// logged record from the loop thread (LogWriterOptions::live). Installs the
/// stop-signal handlers (RunSession); RequestStop ends the run early.
/// @throws InvalidArgument for invalid options (naming the flag), safety
///         settings or specs; InvalidArgument / DataError as RunSession does
///         (before the run).
RunWorkflowResult RunRealtimeWorkflow(const RunWorkflowOptions& options,
                                      const RealtimeConfig& config,
                                      SpscRingBuffer<LogRecord>* live = nullptr);

/// The safety settings of a session on `io` whose input clamp nobody gave
/// (`config.safety_range_given` false, no --u-min/--u-max): config.safety
/// with the plant's input range where it is finite (the IPA's 0..100 %, the
/// position twin's -100..100 %), no clamp (+-1e300) for a simulated linear
/// plant, whose input is unbounded as in `control`, and the safety defaults
/// for a plant server or a rig. `run` and `experiment` use it.
SafetyOptions DefaultSessionSafety(const RealtimeConfig& config, const IoSpec& spec,
                                   const IoBackend& io);

}  // namespace pneumid
