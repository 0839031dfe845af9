#include "pneumid/plant/actuator.hpp"

#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"

namespace pneumid {

Actuator IpaActuator(IpaMode mode) {
  Actuator a;
  a.input = {"u", "%"};
  a.output = {"y", mode == IpaMode::kForce ? "N" : "m"};
  a.hold_name = "valves-closed";
  a.release_name = "exhaust-open";
  if (mode == IpaMode::kPosition) {
    a.integrating = true;
    a.input_label = "command";
    a.output_label = "position";
    a.u_min = -100.0;
    a.u_max = 100.0;
    a.hold_meaning = "all four valves closed: both chambers hold their gas, the piston is held";
    a.release_meaning = "inlets closed, exhausts open: both chambers vent, the piston is free";
    return a;
  }
  a.input_label = "duty";
  a.output_label = "force";
  a.u_min = 0.0;
  a.u_max = 100.0;
  a.hold_meaning = "inlet and exhaust valves closed: chamber pressure held";
  a.release_meaning =
      "inlet closed, exhaust open: the chamber vents, the force falls to its minimum";
  return a;
}

Actuator Plant::actuator() const { return Actuator{}; }

Actuator PlantActuator(const Plant& plant) { return plant.actuator(); }

void CheckSetpointsInOutputRange(const Actuator& actuator, const double* r, std::size_t n,
                                 double Ts) {
  if (!std::isfinite(actuator.y_min) && !std::isfinite(actuator.y_max)) return;
  const std::string unit = actuator.output.unit.empty() ? "" : " " + actuator.output.unit;
  for (std::size_t k = 0; k < n; ++k) {
    if (r[k] >= actuator.y_min && r[k] <= actuator.y_max) continue;
    throw InvalidArgument(fmt::format(
        "set-point {:g}{} at t = {:g} s is outside the plant's {} range {:g} .. {:g}{}: it "
        "cannot be reached",
        r[k], unit, static_cast<double>(k) * Ts, actuator.output_label, actuator.y_min,
        actuator.y_max, unit));
  }
}

}  // namespace pneumid
