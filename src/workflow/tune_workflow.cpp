#include "pneumid/workflow/tune_workflow.hpp"

#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/control/controller.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/workflow/control_scenario.hpp"

namespace pneumid {

bool TuneWorkflowOptions::IsValid(std::string* error) const {
  if (Ts > 0.0 && std::isfinite(Ts)) return true;
  if (error != nullptr) *error = fmt::format("--Ts must be positive, got {}", Ts);
  return false;
}

nlohmann::ordered_json TuneWorkflowResult::ToJson() const {
  if (automatic) return automatic->ToJson();
  if (tuning) return tuning->ToJson();
  return nullptr;
}

namespace {

AutoTuneResult Auto(const TuneWorkflowOptions& c, const TransferFunction& model) {
  PNEUMID_CHECK(c.P == 0 && std::isnan(c.lambda),
                "--rule auto chooses P and lambda itself; drop --P/--lambda");
  AutoTuneOptions o;
  if (!c.controller.empty()) o.controller = ControllerTypeFromString(c.controller);
  o.response_time = c.response_time;
  if (!c.measure.empty()) o.measure = ResponseMeasureFromString(c.measure);
  if (!std::isnan(c.overshoot)) o.max_overshoot = c.overshoot;
  if (!std::isnan(c.aggressiveness)) o.aggressiveness = c.aggressiveness;
  o.limits.u_min = c.u_min;
  o.limits.u_max = c.u_max;
  o.limits.du_max = c.du_max;
  // As `control --plant` designs: the two give the same settings.
  if (!c.plant.empty())
    ResolvePlantInputRange(MakePlant(c.plant, c.Ts)->actuator(), o.limits.u_min, o.limits.u_max);
  o.M = c.M;
  o.measurement_noise = c.measurement_noise;
  o.state_noise = c.state_noise;
  o.disturbance_noise = c.disturbance_noise;
  return AutoTune(model, c.Ts, o);
}

// The settings of a rule other than auto.
TuningResult Conventional(const TuneWorkflowOptions& c, const TransferFunction& model) {
  PNEUMID_CHECK(c.controller.empty() && std::isnan(c.response_time) && c.measure.empty() &&
                    std::isnan(c.overshoot) && std::isnan(c.aggressiveness) &&
                    std::isinf(c.u_min) && std::isinf(c.u_max) && std::isinf(c.du_max) &&
                    c.plant.empty() && std::isnan(c.measurement_noise) &&
                    std::isnan(c.state_noise) && std::isnan(c.disturbance_noise),
                "--controller, --response-time, --measure, --overshoot, --aggressiveness, "
                "the input limits, --plant and the Kalman noises apply to --rule auto only");
  TuningOptions o;
  o.rule = TuningRuleFromString(c.rule);
  o.M = c.M;
  o.P = c.P;
  o.lambda = c.lambda;
  o.tau_significant_digits = c.tau_digits;
  return Tune(model, c.Ts, o);
}

TuneWorkflowResult TuneModel(const TuneWorkflowOptions& o, const TransferFunction& model) {
  TuneWorkflowResult r;
  if (o.rule == "auto") {
    r.automatic = Auto(o, model);
  } else {
    r.tuning = Conventional(o, model);
  }
  return r;
}

void CheckValid(const TuneWorkflowOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) throw InvalidArgument(why);
}

}  // namespace

TuneWorkflowResult RunTuneWorkflow(const TuneWorkflowOptions& o) {
  CheckValid(o);
  return TuneModel(o, ParseModelSpec(o.model));
}

TuneWorkflowResult RunTuneWorkflow(const TuneWorkflowOptions& o, const TransferFunction& model) {
  CheckValid(o);
  return TuneModel(o, model);
}

}  // namespace pneumid
