#include "controller_options.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <tuple>
#include <vector>

#include "pneumid/common/check.hpp"
#include "pneumid/plant/actuator.hpp"
#include "pneumid/workflow/control_scenario.hpp"

#include "validators.hpp"

namespace pneumid::cli {

void AddPidGainOptions(CLI::App& app, ControllerSettings& s) {
  app.add_option("--Kc", s.pid_kc,
                 "PID proportional gain, input units per output unit (default: the rule's)");
  app.add_option("--Ti", s.pid_ti, "PID integral time in s, inf for none (default: the rule's)");
  app.add_option("--Td", s.pid_td, "PID derivative time in s (default: the rule's)");
  app.add_option(
      "--Kff", s.pid_kff,
      "PID velocity feed-forward: input per unit set-point rate, e.g. %/(m/s), 0 for "
      "none (default: 1/Ki + Kc Td on an integrating model of velocity gain Ki, else 0)");
}

void AddControllerOptions(CLI::App& app, ControllerSettings& s) {
  // Names are checked by the control area (the message lists the valid ones).
  app.add_option("--controller", s.controller,
                 "dmc, gpc, pid or mpc (state-space MPC with a Kalman filter and an "
                 "integrating input disturbance; a QP when a limit is set)")
      ->capture_default_str();
  app.add_option("--rule", s.rule,
                 "Tuning rule: shridhar-cooper (conventional), paper-modified, explicit, or auto "
                 "(mpc, dmc, pid: tuned to --response-time and --overshoot by closed-loop "
                 "search, `pneumid tune --rule auto` shows the design review) (default: "
                 "shridhar-cooper, or explicit when --P --M --lambda are all given)");
  app.add_option("--response-time", s.response_time,
                 "--rule auto: target 10-90 % rise time in s (default: from the model)")
      ->check(CLI::PositiveNumber);
  app.add_option("--overshoot", s.overshoot, "--rule auto: largest overshoot in %")
      ->capture_default_str()
      ->check(NonNegative());
  app.add_option("--aggressiveness", s.aggressiveness, "--rule auto: 0 robust .. 1 aggressive")
      ->capture_default_str()
      ->check(InRange(0.0, 1.0));
  app.add_option("--P", s.P, "Prediction horizon (samples)")->check(AtLeast(1));
  app.add_option("--M", s.M, "Control horizon (samples)")->check(AtLeast(1));
  app.add_option("--lambda", s.lambda, "Move suppression")->check(NonNegative());
  app.add_flag("--constrained", s.constrained,
               "DMC: optimize the moves under the input limits (QDMC, QP solver) instead of "
               "clipping (MPC always does when a limit is set)");
  app.add_option("--pid-rule", s.pid_rule, "PID tuning: simc or imc")->capture_default_str();
  app.add_option("--input-map", s.input_map,
                 "the actuator's static map, whose inverse goes in front of the controller "
                 "(designed on the model scaled to unit gain): a static-map or Hammerstein "
                 "model file (FILE.json[#method]) or {\"u\": [...], \"y\": [...]}; a "
                 "Hammerstein --model brings its own");
  app.add_option("--disturbance", s.disturbance,
                 "MPC disturbance model for offset-free tracking: input (an integrating "
                 "disturbance at the plant input), output (on the output) or none")
      ->capture_default_str()
      ->check(CLI::IsMember({"output", "input", "none"}));
  app.add_option("--measurement-noise", s.measurement_noise,
                 "MPC Kalman filter: measurement noise variance, output units squared (default "
                 "1; a position in m wants about the sensor's, e.g. 1e-10)");
  app.add_option("--state-noise", s.state_noise,
                 "MPC Kalman filter: process noise variance on each model state (default 0; > 0 "
                 "with --disturbance none on an integrating model)");
  app.add_option("--disturbance-noise", s.disturbance_noise,
                 "MPC Kalman filter: process noise variance on the disturbance (default 1)");
  app.add_option("--y-valid-min", s.y_valid_min,
                 "Lowest measurement a working sensor gives; a sample below it (or NaN/Inf) is a "
                 "fault: the controller holds its last input and keeps its state (default: any "
                 "finite value)");
  app.add_option("--y-valid-max", s.y_valid_max,
                 "Highest measurement a working sensor gives (see --y-valid-min)");
  app.add_option("--safe-input", s.safe_input,
                 "Input applied on a faulty sample instead of holding the last one (e.g. the "
                 "valves' vented duty), within --u-min..--u-max (default, or nan: hold the last "
                 "input)");
  app.add_option(
      "--input-gaps", s.input_gaps,
      "Inputs the actuator cannot hold, LO:HI[,LO:HI] (IPA: 0:15,85:100), or 'plant' "
      "for the simulated plant's own, or 'none' (a [controller] input_gaps off): the input "
      "is sigma-delta modulated across them, so that their outputs are reached on "
      "average instead of by a limit cycle");
}

void ApplyPlantInputGaps(const Plant& plant, std::string& input_gaps) {
  ApplyPlantInputGaps(PlantActuator(plant), plant.Describe(), input_gaps);
}

void ApplyPlantInputGaps(const Actuator& actuator, const std::string& plant_name,
                         std::string& input_gaps) {
  ResolvePlantInputGaps(actuator, plant_name, input_gaps);
}

void ApplyPlantInputRange(const Plant& plant, double& u_min, double& u_max) {
  ResolvePlantInputRange(plant.actuator(), u_min, u_max);
}

}  // namespace pneumid::cli

namespace pneumid::cli {

void ApplyControllerConfig(const CLI::App& app, const ControllerConfig& file, std::string& model,
                           ControllerSettings& s) {
  const ControllerSettings& f = file.settings;
  // key in the file -> (flag, copy)
  const std::vector<std::tuple<std::string, std::string, std::function<void()>>> table = {
      {"model", "--model", [&] { model = file.model; }},
      {"type", "--controller", [&] { s.controller = f.controller; }},
      {"rule", "--rule", [&] { s.rule = f.rule; }},
      {"P", "--P", [&] { s.P = f.P; }},
      {"M", "--M", [&] { s.M = f.M; }},
      {"lambda", "--lambda", [&] { s.lambda = f.lambda; }},
      {"overshoot", "--overshoot", [&] { s.overshoot = f.overshoot; }},
      {"aggressiveness", "--aggressiveness", [&] { s.aggressiveness = f.aggressiveness; }},
      {"response_time", "--response-time", [&] { s.response_time = f.response_time; }},
      {"u_min", "--u-min", [&] { s.limits.u_min = f.limits.u_min; }},
      {"u_max", "--u-max", [&] { s.limits.u_max = f.limits.u_max; }},
      {"du_max", "--du-max", [&] { s.limits.du_max = f.limits.du_max; }},
      {"y_min", "--y-min", [&] { s.y_min = f.y_min; }},
      {"y_max", "--y-max", [&] { s.y_max = f.y_max; }},
      {"constrained", "--constrained", [&] { s.constrained = f.constrained; }},
      {"disturbance", "--disturbance", [&] { s.disturbance = f.disturbance; }},
      {"measurement_noise", "--measurement-noise",
       [&] { s.measurement_noise = f.measurement_noise; }},
      {"state_noise", "--state-noise", [&] { s.state_noise = f.state_noise; }},
      {"disturbance_noise", "--disturbance-noise",
       [&] { s.disturbance_noise = f.disturbance_noise; }},
      {"t_filter", "--t-filter", [&] { s.t_filter = f.t_filter; }},
      {"tau_c", "--tau-c", [&] { s.tau_c = f.tau_c; }},
      {"Kc", "--Kc", [&] { s.pid_kc = f.pid_kc; }},
      {"Ti", "--Ti", [&] { s.pid_ti = f.pid_ti; }},
      {"Td", "--Td", [&] { s.pid_td = f.pid_td; }},
      {"Kff", "--Kff", [&] { s.pid_kff = f.pid_kff; }},
      {"pid_rule", "--pid-rule", [&] { s.pid_rule = f.pid_rule; }},
      {"input_map", "--input-map", [&] { s.input_map = f.input_map; }},
      {"input_gaps", "--input-gaps", [&] { s.input_gaps = f.input_gaps; }},
      {"y_valid_min", "--y-valid-min", [&] { s.y_valid_min = f.y_valid_min; }},
      {"y_valid_max", "--y-valid-max", [&] { s.y_valid_max = f.y_valid_max; }},
      {"safe_input", "--safe-input", [&] { s.safe_input = f.safe_input; }},
  };
  for (const auto& [key, flag, copy] : table) {
    if (std::find(file.keys.begin(), file.keys.end(), key) == file.keys.end()) continue;
    const CLI::Option* option = app.get_option_no_throw(flag);
    if (option == nullptr || option->count() == 0) copy();
  }
}

}  // namespace pneumid::cli
