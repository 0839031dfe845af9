// Command-line options that design a controller, shared by `control` and `run`
// (like data_options/model_options), bound to the control area's
// ControllerSettings (controller_factory.hpp: the rule inference and parsing
// live there):
//
//   --controller dmc|gpc|pid   controller type
//   --rule NAME                shridhar-cooper (conventional), paper-modified, explicit
//                              (default: shridhar-cooper, or explicit when --P --M
//                              --lambda are all given)
//   --P N, --M N, --lambda L   horizons and move suppression (override the rule)
//   --constrained              dmc: QDMC, moves optimized under the input limits
//   --pid-rule simc|imc        PID tuning rule
#pragma once

#include <CLI/CLI.hpp>

#include "pneumid/control/controller_factory.hpp"
#include "pneumid/plant/actuator.hpp"
#include "pneumid/plant/plant.hpp"
#include "pneumid/realtime/realtime_config.hpp"

namespace pneumid::cli {

/// Adds the options above, writing into `settings`.
void AddControllerOptions(CLI::App& app, ControllerSettings& settings);

/// Adds --Kc, --Ti, --Td, --Kff: PID gains given explicitly, each replacing the
/// rule's value of that gain (ControllerSettings::pid_kc, pid_ti, pid_td).
void AddPidGainOptions(CLI::App& app, ControllerSettings& settings);

/// Input limits of a design against `plant` (`control`, `tune --plant`,
/// `codegen --plant`): a limit left open (not finite, no --u-min/--u-max) takes
/// the plant's physical input range (IPA: duty 0..100 %).
/// @throws InvalidArgument when u_min > u_max, naming the plant's range.
void ApplyPlantInputRange(const Plant& plant, double& u_min, double& u_max);
/// Replaces the --input-gaps value "plant" by the plant's known gaps
/// (PlantActuator(plant).input_gaps). @throws InvalidArgument when it has none.
void ApplyPlantInputGaps(const Plant& plant, std::string& input_gaps);
/// The same for the plant behind an I/O backend, described by its actuator
/// (realtime: IoBackend::actuator()); plant_name names it in the error.
void ApplyPlantInputGaps(const Actuator& actuator, const std::string& plant_name,
                         std::string& input_gaps);
/// The [controller] section of a --config file (realtime_config.hpp) applied
/// to `model` and `settings`: each key the file gives, unless its flag was
/// given on the command line (flags override the file).
void ApplyControllerConfig(const CLI::App& app, const ControllerConfig& file, std::string& model,
                           ControllerSettings& settings);

}  // namespace pneumid::cli
