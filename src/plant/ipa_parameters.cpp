// TOML loader of the IPA parameters (config/ipa_default.toml documents every key).
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "pneumid/common/check.hpp"
#include "pneumid/plant/ipa_simulator.hpp"

namespace pneumid {

namespace {

struct DoubleKey {
  const char* key;
  double IpaParameters::*field;
};
struct IntKey {
  const char* key;
  int IpaParameters::*field;
};

const std::vector<DoubleKey>& DoubleKeys() {
  static const std::vector<DoubleKey> keys = {
      {"cylinder.bore", &IpaParameters::bore},
      {"cylinder.rod", &IpaParameters::rod},
      {"cylinder.stroke", &IpaParameters::stroke},
      {"cylinder.piston_position", &IpaParameters::piston_position},
      {"cylinder.dead_volume_a", &IpaParameters::dead_volume_a},
      {"cylinder.dead_volume_b", &IpaParameters::dead_volume_b},
      {"supply.pressure", &IpaParameters::supply_pressure},
      {"supply.atmospheric_pressure", &IpaParameters::atmospheric_pressure},
      {"supply.temperature", &IpaParameters::temperature},
      {"supply.line_conductance", &IpaParameters::supply_line_conductance},
      {"supply.line_critical_ratio", &IpaParameters::supply_line_critical_ratio},
      {"gas.gas_constant", &IpaParameters::gas_constant},
      {"gas.alpha_in", &IpaParameters::alpha_in},
      {"gas.alpha_out", &IpaParameters::alpha_out},
      {"gas.alpha", &IpaParameters::alpha},
      {"valves.inlet_conductance", &IpaParameters::inlet_conductance},
      {"valves.inlet_critical_ratio", &IpaParameters::inlet_critical_ratio},
      {"valves.exhaust_conductance", &IpaParameters::exhaust_conductance},
      {"valves.exhaust_critical_ratio", &IpaParameters::exhaust_critical_ratio},
      {"valves.laminar_ratio", &IpaParameters::laminar_ratio},
      {"valves.open_delay", &IpaParameters::open_delay},
      {"valves.close_delay", &IpaParameters::close_delay},
      {"valves.min_pulse_width", &IpaParameters::min_pulse_width},
      {"pwm.frequency", &IpaParameters::pwm_frequency},
      {"mechanics.mass", &IpaParameters::mass},
      {"mechanics.viscous_friction", &IpaParameters::viscous_friction},
      {"mechanics.coulomb_friction", &IpaParameters::coulomb_friction},
      {"mechanics.static_friction", &IpaParameters::static_friction},
      {"mechanics.stribeck_velocity", &IpaParameters::stribeck_velocity},
      {"mechanics.smoothing_velocity", &IpaParameters::friction_smoothing_velocity},
      {"mechanics.end_stop_stiffness", &IpaParameters::end_stop_stiffness},
      {"mechanics.end_stop_damping", &IpaParameters::end_stop_damping},
      {"sensors.pressure_noise", &IpaParameters::pressure_noise},
      {"sensors.pressure_full_scale", &IpaParameters::pressure_full_scale},
      {"sensors.position_noise", &IpaParameters::position_noise},
      {"sensors.adc_range", &IpaParameters::adc_range},
      {"sensors.force_offset", &IpaParameters::force_offset},
      {"simulation.relative_tolerance", &IpaParameters::relative_tolerance},
      {"simulation.absolute_tolerance", &IpaParameters::absolute_tolerance},
  };
  return keys;
}

const std::vector<IntKey>& IntKeys() {
  static const std::vector<IntKey> keys = {
      {"sensors.adc_bits", &IpaParameters::adc_bits},
      {"sensors.transport_delay_samples", &IpaParameters::transport_delay_samples},
  };
  return keys;
}

std::string Where(const std::string& path, const toml::node& node) {
  const auto& src = node.source();
  if (src.begin.line == 0) return path;
  return fmt::format("{}:{}:{}", path, src.begin.line, src.begin.column);
}

}  // namespace

IpaParameters LoadIpaParameters(const std::string& path) {
  toml::table root;
  try {
    root = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    const auto& src = e.source();
    if (src.begin.line == 0) throw DataError(fmt::format("{}: {}", path, e.description()));
    throw DataError(
        fmt::format("{}:{}:{}: {}", path, src.begin.line, src.begin.column, e.description()));
  }
  IpaParameters p;
  for (auto&& [table_key, table_node] : root) {
    const std::string table_name(table_key.str());
    const toml::table* table = table_node.as_table();
    if (!table)
      throw DataError(fmt::format("{}: '{}' must be a table such as [cylinder], [valves], ...",
                                  Where(path, table_node), table_name));
    for (auto&& [key, node] : *table) {
      const std::string full = table_name + "." + std::string(key.str());
      bool known = false;
      for (const auto& k : DoubleKeys()) {
        if (full != k.key) continue;
        known = true;
        auto v = node.value<double>();
        if (!v || node.is_boolean())
          throw DataError(fmt::format("{}: key '{}': expected a number", Where(path, node), full));
        p.*(k.field) = *v;
      }
      for (const auto& k : IntKeys()) {
        if (full != k.key) continue;
        known = true;
        if (!node.is_integer())
          throw DataError(
              fmt::format("{}: key '{}': expected an integer", Where(path, node), full));
        const std::int64_t v = node.as_integer()->get();
        if (!std::in_range<int>(v))
          throw DataError(
              fmt::format("{}: key '{}': {} is out of range for an integer (at most {})",
                          Where(path, node), full, v, std::numeric_limits<int>::max()));
        p.*(k.field) = static_cast<int>(v);
      }
      if (full == "simulation.mode" || full == "simulation.pwm_mode") {
        known = true;
        auto s = node.value<std::string>();
        if (!s)
          throw DataError(fmt::format("{}: key '{}': expected a string", Where(path, node), full));
        try {
          if (full == "simulation.mode")
            p.mode = IpaModeFromString(*s);
          else
            p.pwm_mode = PwmModeFromString(*s);
        } catch (const InvalidArgument& e) {
          throw DataError(fmt::format("{}: key '{}': {}", Where(path, node), full, e.what()));
        }
      }
      if (!known)
        throw DataError(fmt::format("{}: unknown key '{}' (see config/ipa_default.toml)",
                                    Where(path, node), full));
    }
  }
  std::string error;
  if (!p.IsValid(&error)) throw DataError(fmt::format("{}: {}", path, error));
  return p;
}

}  // namespace pneumid
