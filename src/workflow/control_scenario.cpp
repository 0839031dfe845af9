#include "pneumid/workflow/control_scenario.hpp"

#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/control/duty_modulator.hpp"
#include "pneumid/control/tuning.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/plant/signal.hpp"

namespace pneumid {

bool ControlScenarioOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string message) {
    if (error != nullptr) *error = std::move(message);
    return false;
  };
  if (!(Ts > 0.0 && std::isfinite(Ts))) return fail(fmt::format("--Ts must be positive, got {}", Ts));
  if (!(duration > 0.0)) return fail(fmt::format("--duration must be positive, got {}", duration));
  return true;
}

nlohmann::ordered_json ControlScenarioRun::ToJson() const {
  nlohmann::ordered_json j;
  j["label"] = built.Label();
  j["controller"] = result.controller;
  j["plant"] = result.plant;
  j["settings"] = built.SettingsToJson();
  const nlohmann::ordered_json metrics = result.metrics.ToJson();  // outlives the loop
  for (const auto& [key, value] : metrics.items()) j[key] = value;
  return j;
}

nlohmann::ordered_json ControlScenarioJson(const std::vector<ControlScenarioRun>& runs) {
  if (runs.size() == 1) return runs[0].ToJson();
  nlohmann::ordered_json j;
  j["compare"] = nlohmann::json::array();
  for (const ControlScenarioRun& run : runs) j["compare"].push_back(run.ToJson());
  return j;
}

nlohmann::ordered_json ControlScenarioResult::ToJson() const { return ControlScenarioJson(runs); }

void ResolvePlantInputRange(const Actuator& actuator, double& u_min, double& u_max) {
  if (!std::isfinite(u_min)) u_min = actuator.u_min;
  if (!std::isfinite(u_max)) u_max = actuator.u_max;
  PNEUMID_CHECK(u_min <= u_max,
                "--u-min {} is above --u-max {} (the plant's input range is {} .. {})", u_min,
                u_max, actuator.u_min, actuator.u_max);
}

void ResolvePlantInputGaps(const Actuator& actuator, const std::string& plant_name,
                           std::string& input_gaps) {
  if (input_gaps != "plant") return;
  PNEUMID_CHECK(!actuator.input_gaps.empty(),
                "--input-gaps plant: the plant '{}' has no known input gaps (give LO:HI)",
                plant_name);
  input_gaps = InputGapsToString(actuator.input_gaps);
}

namespace {

// The controller specifications to run: the given one, or one per compared rule.
std::vector<ControllerSpec> ScenarioSpecs(const ControlScenarioOptions& o,
                                          const ControllerSpec& base) {
  if (o.compare_rules.empty()) return {base};
  std::vector<ControllerSpec> specs;
  for (const std::string& rule : o.compare_rules) {
    ControllerSpec spec = base;
    spec.tuning = TuningOptions{};
    spec.tuning.rule = TuningRuleFromString(rule);
    specs.push_back(spec);
  }
  return specs;
}

}  // namespace

ControlScenarioResult RunControlScenario(const ControlScenarioOptions& o) {
  std::string error;
  if (!o.IsValid(&error)) throw InvalidArgument(error);
  const TransferFunction model = ParseControllerModel(o.model);
  const auto setpoint = ParseSignal(o.setpoint);
  ClosedLoopOptions loop;
  loop.duration = o.duration;
  loop.stop = o.stop;
  loop.noise_std = o.noise;
  loop.seed = o.seed;
  loop.load_steps = o.load_steps;
  PlantOptions plant_options;
  plant_options.seed = o.seed;
  ControlScenarioResult result;
  result.plant_spec = o.plant.empty() ? o.model : o.plant;
  // One plant per run, each from its initial state; the first also describes the actuator.
  auto plant = MakePlant(result.plant_spec, o.Ts, plant_options);
  ControllerSettings settings = o.controller;
  result.actuator = plant->actuator();
  ResolvePlantInputRange(result.actuator, settings.limits.u_min, settings.limits.u_max);
  ResolvePlantInputGaps(result.actuator, plant->Describe(), settings.input_gaps);
  loop.actuator.u_min = settings.limits.u_min;
  loop.actuator.u_max = settings.limits.u_max;
  const ControllerSpec base = WithModelInputMap(ToControllerSpec(settings), o.model);
  for (const ControllerSpec& spec : ScenarioSpecs(o, base)) {
    if (!plant) plant = MakePlant(result.plant_spec, o.Ts, plant_options);
    ControlScenarioRun run;
    run.built = MakeController(model, o.Ts, spec);
    run.result = SimulateClosedLoop(*run.built.controller, *plant, *setpoint, loop);
    result.runs.push_back(std::move(run));
    plant.reset();
  }
  return result;
}

}  // namespace pneumid
