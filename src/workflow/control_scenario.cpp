#include "pneumid/workflow/control_scenario.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
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
  // The traces hold every sample (t, r, y, u, ...): 1e308 s ran 2 samples
  // (the count overflowed) and exited 0.
  if (!(duration / Ts <= 1e8))
    return fail(fmt::format("--duration {} s at --Ts {} s is {:.3g} samples; a simulation holds "
                            "at most 1e8",
                            duration, Ts, duration / Ts));
  return true;
}

namespace {

// A loop that grows instead of settling: over the last tenth of the run the
// error reaches 3 times the largest set-point change (or the set-point's
// span) and more than over the first tenth. SIMC on a lightly damped model
// (zeta 0.1) ran to y = -37 after 30 s, reported as any other run. And one
// that keeps oscillating: over the last tenth, with the set-point constant
// there, the output swings by half the span or more (SIMC on a lag 50 times
// shorter than Ts swung between 0.04 and 1.98 on a step to 1, and the ripple
// rule widened the settling band to call it settled).
std::optional<std::string> DivergenceWarning(const std::string& label, const ClosedLoopResult& r) {
  const Eigen::Index n = r.y.size(), tenth = std::max<Eigen::Index>(1, n / 10);
  if (n < 20) return std::nullopt;
  const Eigen::VectorXd e = r.r - r.y;
  double span = r.r.maxCoeff() - r.r.minCoeff();
  if (span == 0.0) span = std::abs(r.r(0));
  if (!(span > 0.0)) return std::nullopt;
  const double late = e.tail(tenth).cwiseAbs().maxCoeff();
  const double early = e.head(tenth).cwiseAbs().maxCoeff();
  if (!(late > 3.0 * span && late > early)) {
    const auto rr = r.r.tail(tenth), yy = r.y.tail(tenth);
    const double swing = yy.maxCoeff() - yy.minCoeff();
    if (rr.maxCoeff() == rr.minCoeff() && swing >= 0.5 * span)
      return fmt::format(
          "the loop of {} keeps oscillating: over the last tenth of the run, at a constant "
          "set-point, the output swings by {:.4g}, {:.0f} % of the set-point's span {:.4g}; a "
          "step the band of such a swing calls settled is not (tune it more softly, or give "
          "a rule that suits the model)",
          label, swing, 100.0 * swing / span, span);
    return std::nullopt;
  }
  return fmt::format(
      "the loop of {} looks unstable: over the last tenth of the run the error reaches {:.4g}, "
      "{:.3g} times the set-point's span {:.4g} (over the first tenth {:.4g}); the metrics "
      "describe a loop that does not settle: tune it more softly (a rule outside its range, e.g. "
      "SIMC on a lightly damped or very fast model) or check the model",
      label, late, late / span, span, early);
}

}  // namespace

nlohmann::ordered_json ControlScenarioRun::ToJson() const {
  nlohmann::ordered_json j;
  j["label"] = label;
  j["controller"] = result.controller;
  j["plant"] = result.plant;
  j["settings"] = built.SettingsToJson();
  const nlohmann::ordered_json metrics = result.metrics.ToJson();  // outlives the loop
  for (const auto& [key, value] : metrics.items()) j[key] = value;
  return j;
}

nlohmann::ordered_json ControlScenarioJson(const std::vector<ControlScenarioRun>& runs,
                                           const std::vector<std::string>& warnings) {
  nlohmann::ordered_json j;
  if (runs.size() == 1) {
    j = runs[0].ToJson();
  } else {
    j["compare"] = nlohmann::json::array();
    for (const ControlScenarioRun& run : runs) j["compare"].push_back(run.ToJson());
  }
  j["warnings"] = warnings;
  return j;
}

nlohmann::ordered_json ControlScenarioResult::ToJson() const {
  return ControlScenarioJson(runs, warnings);
}

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

std::optional<std::pair<double, double>> SteadyOutputRange(const TransferFunction& model,
                                                           const ControllerSpec& spec, double u_min,
                                                           double u_max) {
  if (!std::isfinite(u_min) || !std::isfinite(u_max) || !(u_max > u_min)) return std::nullopt;
  if (!spec.input_map && !spec.output_map && !spec.narx_model) return std::nullopt;
  std::vector<double> inputs;
  constexpr int kSamples = 400;
  for (int i = 0; i <= kSamples; ++i)
    inputs.push_back(u_min + (u_max - u_min) * static_cast<double>(i) / kSamples);
  // A piecewise-linear map takes its extremes at its knots or the limits.
  if (spec.input_map)
    for (double k : spec.input_map->u())
      if (k > u_min && k < u_max) inputs.push_back(k);
  std::sort(inputs.begin(), inputs.end());
  const double dc = model.DcGain();
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, y_prev = 0.0;
  for (double u : inputs) {
    double y = 0.0;
    if (spec.narx_model) {
      y = spec.narx_model->SteadyOutput(u, y_prev);
    } else {
      y = dc * (spec.input_map ? spec.input_map->Evaluate(u) : u);
      if (spec.output_map) y = spec.output_map->Evaluate(y);
    }
    if (!std::isfinite(y)) return std::nullopt;
    lo = std::min(lo, y);
    hi = std::max(hi, y);
    y_prev = y;
  }
  return std::make_pair(lo, hi);
}

std::optional<std::string> UnreachableSetpointWarning(const Eigen::VectorXd& setpoint,
                                                      const TransferFunction& model,
                                                      const ControllerSpec& spec, double u_min,
                                                      double u_max) {
  const std::optional<std::pair<double, double>> range =
      SteadyOutputRange(model, spec, u_min, u_max);
  if (!range) return std::nullopt;
  const auto [lo, hi] = *range;
  const double tol = 0.01 * (hi - lo);
  double r_lo = std::numeric_limits<double>::infinity(), r_hi = -r_lo;
  long outside = 0;
  for (double r : setpoint) {
    if (!std::isfinite(r)) continue;
    r_lo = std::min(r_lo, r);
    r_hi = std::max(r_hi, r);
    if (r < lo - tol || r > hi + tol) ++outside;
  }
  if (outside == 0) return std::nullopt;
  return fmt::format(
      "the set-point reaches [{:.4g}, {:.4g}], beyond the steady outputs [{:.4g}, {:.4g}] that "
      "the controller's model reaches with the input within its limits [{:g}, {:g}] ({} of {} "
      "samples): there the input saturates and the output stays short of the set-point; keep "
      "the set-points within that range, or widen the input limits or the actuator (a higher "
      "supply pressure, larger valves)",
      r_lo, r_hi, lo, hi, u_min, u_max, outside, setpoint.size());
}

namespace {

// The controller specifications to run: the given one, or one per compared
// rule: "auto" (tuned to the specification), else a tuning rule of dmc, gpc
// and mpc (shridhar-cooper, paper-modified) or of a pid (simc, imc). A pid
// compared under a predictive rule ran the same PID once per rule.
std::vector<ControllerSpec> ScenarioSpecs(const ControlScenarioOptions& o,
                                          const ControllerSpec& base) {
  if (o.compare_rules.empty()) return {base};
  std::vector<ControllerSpec> specs;
  for (const std::string& rule : o.compare_rules) {
    ControllerSpec spec = base;
    spec.tuning = TuningOptions{};
    spec.auto_tune = rule == "auto";
    if (spec.auto_tune) {
      spec.pid_kc = spec.pid_ti = spec.pid_td = std::numeric_limits<double>::quiet_NaN();
    } else if (base.type == ControllerType::kPid) {
      PNEUMID_CHECK(rule == "simc" || rule == "imc",
                    "--compare for a pid takes its tuning rules simc, imc or auto, got '{}'",
                    rule);
      spec.pid_rule = PidTuningRuleFromString(rule);
      spec.pid_kc = spec.pid_ti = spec.pid_td = std::numeric_limits<double>::quiet_NaN();
    } else {
      spec.tuning.rule = TuningRuleFromString(rule);
    }
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
  if (std::optional<std::string> w =
          UnreachableSetpointWarning(setpoint->Sample(o.Ts, loop.Samples(o.Ts)), model, base,
                                     settings.limits.u_min, settings.limits.u_max))
    result.warnings.push_back(std::move(*w));
  const std::vector<ControllerSpec> specs = ScenarioSpecs(o, base);
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const ControllerSpec& spec = specs[i];
    if (!plant) plant = MakePlant(result.plant_spec, o.Ts, plant_options);
    ControlScenarioRun run;
    run.built = MakeController(model, o.Ts, spec);
    run.label = !o.compare_rules.empty() && spec.type == ControllerType::kPid
                    ? "pid " + o.compare_rules[i]
                    : run.built.Label();
    run.result = SimulateClosedLoop(*run.built.controller, *plant, *setpoint, loop);
    if (std::optional<std::string> w = DivergenceWarning(run.label, run.result))
      result.warnings.push_back(std::move(*w));
    if (!run.built.auto_summary.empty() && !run.built.auto_converged)
      result.warnings.push_back(fmt::format(
          "the rule auto found no design that meets the specification on the model and on every "
          "robustness row (gain +-20 %, one more sample of dead time), and runs the best it "
          "found: {} (`pneumid tune --rule auto` prints the review)",
          run.built.auto_summary));
    result.runs.push_back(std::move(run));
    plant.reset();
  }
  return result;
}

}  // namespace pneumid
