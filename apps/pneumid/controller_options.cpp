#include "controller_options.hpp"

#include <cmath>

#include "pneumid/common/check.hpp"
#include "pneumid/plant/actuator.hpp"

#include "validators.hpp"

namespace pneumid::cli {

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
      ->check(CLI::Range(0.0, 1.0));
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
  app.add_option("--y-valid-min", s.y_valid_min,
                 "Lowest measurement a working sensor gives; a sample below it (or NaN/Inf) is a "
                 "fault: the controller holds its last input and keeps its state (default: any "
                 "finite value)");
  app.add_option("--y-valid-max", s.y_valid_max,
                 "Highest measurement a working sensor gives (see --y-valid-min)");
  app.add_option("--safe-input", s.safe_input,
                 "Input applied on a faulty sample instead of holding the last one (e.g. the "
                 "valves' vented duty)");
}

void ApplyPlantInputRange(const Plant& plant, double& u_min, double& u_max) {
  const Actuator actuator = PlantActuator(plant);
  if (!std::isfinite(u_min)) u_min = actuator.u_min;
  if (!std::isfinite(u_max)) u_max = actuator.u_max;
  PNEUMID_CHECK(u_min <= u_max,
                "--u-min {} is above --u-max {} (the plant's input range is {} .. {})", u_min,
                u_max, actuator.u_min, actuator.u_max);
}

}  // namespace pneumid::cli
