// A closed-loop scenario: a controller designed from a model, run against a
// plant through a set-point sequence with load steps, and its metrics. This is
// the work of `pneumid control`; the command line, the app's /api/control and
// Python's simulate_control all call RunControlScenario, so that the same
// scenario gives the same numbers everywhere.
//
//   ControlScenarioOptions o;
//   o.model = "fopdt-paper";                       // model spec (model_io.hpp)
//   o.plant = "ipa";                               // plant spec; empty = the model
//   o.controller.controller = "dmc";               // ControllerSettings
//   o.setpoint = "staircase:levels=0 40 80 40,dwell=2";
//   o.duration = 8;
//   o.load_steps = {{7.0, -15.0}};
//   const ControlScenarioResult r = RunControlScenario(o);
//   r.ToJson();                                    // what `control --json` prints
//
// Input limits left open take the plant's physical input range (IPA: duty
// 0..100 %), and input gaps "plant" the plant's own (ResolvePlantLimits). With
// `compare_rules`, the same controller runs once per tuning rule (the paper's
// Figure 6: shridhar-cooper against paper-modified).
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "pneumid/control/closed_loop.hpp"
#include "pneumid/control/controller_factory.hpp"
#include "pneumid/plant/actuator.hpp"
#include "pneumid/plant/plant.hpp"

namespace pneumid {

/// What to simulate (see the file comment).
struct ControlScenarioOptions {
  std::string model;               ///< model spec the controller is designed from
  ControllerSettings controller;   ///< type, rule, horizons, limits, gains, ...
  std::string plant;               ///< plant spec (plant_factory.hpp); empty = the model
  double Ts = 0.01;                ///< loop period [s]
  std::string setpoint;            ///< set-point signal spec (signal.hpp)
  double duration = 0.0;           ///< simulated time [s], > 0
  double noise = 0.0;              ///< measurement noise standard deviation (output units)
  std::uint64_t seed = 1;          ///< seed of the plant's and the loop's noise
  std::vector<LoadStep> load_steps;  ///< load disturbances on the output
  /// One run per tuning rule name (tuning.hpp), each with the rule's own
  /// horizons; empty = one run with `controller` as given.
  std::vector<std::string> compare_rules;
  /// When set and true, the simulations throw Cancelled.
  const std::atomic<bool>* stop = nullptr;

  /// False (with the reason) for a non-positive Ts or duration.
  bool IsValid(std::string* error) const;
};

/// One closed-loop simulation of a scenario.
struct ControlScenarioRun {
  BuiltController built;   ///< the controller as designed
  ClosedLoopResult result; ///< traces and metrics
  /// The run's name: BuiltController::Label(), but "pid RULE" ("pid simc",
  /// "pid imc", "pid auto") for each run of a comparison of PID rules.
  std::string label;
  /// label, controller, plant, settings and the metrics' keys
  /// (ClosedLoopMetrics::ToJson), as `control --json` prints one run.
  nlohmann::ordered_json ToJson() const;
};

/// Everything RunControlScenario simulated.
struct ControlScenarioResult {
  std::vector<ControlScenarioRun> runs;  ///< one, or one per compared rule
  std::string plant_spec;                ///< the plant simulated (the model when none given)
  Actuator actuator;                     ///< the plant's actuator: channels, input range, gaps
  /// What the scenario asks that its model says it cannot do: set-points
  /// beyond the steady outputs the controller's model reaches with the input
  /// held anywhere within its limits (SteadyOutputRange); `control` prints
  /// them on stderr.
  std::vector<std::string> warnings;
  /// One run's ToJson, or {"compare": [...]} for several: `control --json`.
  nlohmann::ordered_json ToJson() const;
};

/// One run's ToJson, or {"compare": [one per run]} for several, with
/// "warnings": the scenario's warnings (`control --json`).
nlohmann::ordered_json ControlScenarioJson(const std::vector<ControlScenarioRun>& runs,
                                           const std::vector<std::string>& warnings);

/// Designs the controller(s) and simulates the scenario.
/// @throws InvalidArgument for invalid options, settings or specs (naming them);
///         DataError for an unreadable model file; Cancelled when `stop` is set.
ControlScenarioResult RunControlScenario(const ControlScenarioOptions& options);

/// The steady outputs a controller's model reaches with its input held
/// anywhere in [u_min, u_max] (sampled at 401 inputs and the map's knots):
/// G(1) f(u), through the output map g when there is one (Hammerstein,
/// Wiener, Hammerstein-Wiener), or the input-affine NARX's fixed point
/// (spec.narx_model). nullopt for a model without a map or NARX (a linear
/// model's operating point is not known to the controller), for open input
/// limits, or when the model has no steady state at some input.
std::optional<std::pair<double, double>> SteadyOutputRange(const TransferFunction& model,
                                                           const ControllerSpec& spec,
                                                           double u_min, double u_max);

/// The warning for a set-point, sampled as the loop runs it (Signal::Sample),
/// that goes beyond the steady outputs of SteadyOutputRange by more than 1 %
/// of that range: the range reached, the model's, the limits and how many
/// samples; nullopt when none does or the range is unknown.
std::optional<std::string> UnreachableSetpointWarning(const Eigen::VectorXd& setpoint,
                                                      const TransferFunction& model,
                                                      const ControllerSpec& spec, double u_min,
                                                      double u_max);

/// Input limits of a design against a plant: a limit left open (not finite)
/// takes the actuator's physical input range (IPA: duty 0..100 %).
/// @throws InvalidArgument when u_min > u_max, naming the actuator's range.
void ResolvePlantInputRange(const Actuator& actuator, double& u_min, double& u_max);
/// Replaces the input-gap setting "plant" by the actuator's known gaps
/// (Actuator::input_gaps, as "LO:HI,..."); plant_name names the plant in the error.
/// @throws InvalidArgument when the actuator has none.
void ResolvePlantInputGaps(const Actuator& actuator, const std::string& plant_name,
                           std::string& input_gaps);

}  // namespace pneumid
