#include "pneumid/plant/actuator.hpp"

namespace pneumid {

Actuator IpaActuator(IpaMode mode) {
  Actuator a;
  a.input = {"u", "%"};
  a.output = {"y", mode == IpaMode::kForce ? "N" : "m"};
  a.input_label = "duty";
  a.output_label = mode == IpaMode::kForce ? "force" : "position";
  a.u_min = 0.0;
  a.u_max = 100.0;
  a.hold_name = "valves-closed";
  a.hold_meaning = "inlet and exhaust valves closed: chamber pressure held";
  a.release_name = "exhaust-open";
  a.release_meaning = "inlet closed, exhaust open: the chamber vents, the force falls to its minimum";
  return a;
}

Actuator PlantActuator(const Plant& plant) {
  if (const auto* ipa = dynamic_cast<const IpaSimulator*>(&plant)) {
    Actuator a = IpaActuator(ipa->parameters().mode);
    const double w = 100.0 * ipa->parameters().min_pulse_width * ipa->parameters().pwm_frequency;
    if (w > 0.0 && w < 50.0) a.input_gaps = {{0.0, w}, {100.0 - w, 100.0}};
    return a;
  }
  return Actuator{};
}

}  // namespace pneumid
