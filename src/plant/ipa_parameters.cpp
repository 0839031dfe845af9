// TOML loader of the IPA parameters (config/ipa_default.toml documents every key).
#include <algorithm>
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
      {"valves.tube_conductance", &IpaParameters::tube_conductance},
      {"valves.tube_critical_ratio", &IpaParameters::tube_critical_ratio},
      {"valves.manifold_volume", &IpaParameters::manifold_volume},
      {"pwm.frequency", &IpaParameters::pwm_frequency},
      {"mechanics.mass", &IpaParameters::mass},
      {"mechanics.viscous_friction", &IpaParameters::viscous_friction},
      {"mechanics.coulomb_friction", &IpaParameters::coulomb_friction},
      {"mechanics.static_friction", &IpaParameters::static_friction},
      {"mechanics.stribeck_velocity", &IpaParameters::stribeck_velocity},
      {"mechanics.smoothing_velocity", &IpaParameters::friction_smoothing_velocity},
      {"mechanics.end_stop_stiffness", &IpaParameters::end_stop_stiffness},
      {"mechanics.end_stop_damping", &IpaParameters::end_stop_damping},
      {"mechanics.lugre_stiffness", &IpaParameters::lugre_stiffness},
      {"mechanics.lugre_damping", &IpaParameters::lugre_damping},
      {"sensors.pressure_noise", &IpaParameters::pressure_noise},
      {"sensors.pressure_full_scale", &IpaParameters::pressure_full_scale},
      {"sensors.pressure_filter_time_constant", &IpaParameters::pressure_filter_time_constant},
      {"sensors.position_noise", &IpaParameters::position_noise},
      {"sensors.position_resolution", &IpaParameters::position_resolution},
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

struct Range {
  const char* key;
  const char* unit;
  double lower, upper;
  bool calibratable;
};

// Physically plausible ranges; docs/simulator.md ("Parameter ranges") gives the sources.
constexpr Range kRanges[] = {
    {"cylinder.bore", "m", 0.004, 0.1, true},  // ISO 6432 / ISO 15552 bores 8..100 mm
    {"cylinder.rod", "m", 0.0, 0.04, true},
    {"cylinder.stroke", "m", 0.005, 2.0, true},
    {"cylinder.piston_position", "m", 0.0, 2.0, true},
    {"cylinder.dead_volume_a", "m^3", 1e-7, 1e-3, true},  // 0.1 cm^3 .. 1 l
    {"cylinder.dead_volume_b", "m^3", 1e-7, 1e-3, true},
    {"supply.pressure", "Pa", 1e4, 1.6e6, true},  // gauge; ISO 4414 components <= 1.6 MPa
    {"supply.atmospheric_pressure", "Pa", 5e4, 1.1e5, true},
    {"supply.temperature", "K", 233.0, 373.0, true},
    {"supply.line_conductance", "m^3/(s Pa)", 1e-11, 1e-6, true},
    {"supply.line_critical_ratio", "", 0.05, 0.6, true},
    {"gas.gas_constant", "J/(kg K)", 280.0, 300.0, false},
    {"gas.alpha_in", "", 1.0, 1.4, true},  // polytropic: isothermal .. adiabatic
    {"gas.alpha_out", "", 1.0, 1.4, true},
    {"gas.alpha", "", 1.0, 1.4, true},
    {"valves.inlet_conductance", "m^3/(s Pa)", 1e-11, 1e-7, true},  // 0.001..10 dm^3/(s bar)
    {"valves.inlet_critical_ratio", "", 0.05, 0.6, true},           // ISO 6358 b
    {"valves.exhaust_conductance", "m^3/(s Pa)", 1e-11, 1e-7, true},
    {"valves.exhaust_critical_ratio", "", 0.05, 0.6, true},
    {"valves.laminar_ratio", "", 0.9, 0.9999, true},
    {"valves.open_delay", "s", 0.0, 0.05, true},  // solenoid valves 0.3..30 ms
    {"valves.close_delay", "s", 0.0, 0.05, true},
    {"valves.min_pulse_width", "s", 0.0, 0.05, true},
    {"valves.tube_conductance", "m^3/(s Pa)", 0.0, 1e-6, true},  // 0: no tube
    {"valves.tube_critical_ratio", "", 0.05, 0.6, true},
    {"valves.manifold_volume", "m^3", 1e-7, 1e-3, true},
    {"pwm.frequency", "Hz", 1.0, 2000.0, true},
    {"mechanics.mass", "kg", 0.01, 1000.0, true},
    {"mechanics.viscous_friction", "N s/m", 0.0, 1e5, true},
    {"mechanics.coulomb_friction", "N", 0.0, 1e4, true},
    {"mechanics.static_friction", "N", 0.0, 1e4, true},
    {"mechanics.stribeck_velocity", "m/s", 1e-5, 1.0, true},
    {"mechanics.smoothing_velocity", "m/s", 1e-6, 0.1, false},
    {"mechanics.end_stop_stiffness", "N/m", 1e3, 1e9, false},
    {"mechanics.end_stop_damping", "N s/m", 0.0, 1e6, false},
    {"mechanics.lugre_stiffness", "N/m", 0.0, 1e8, true},  // 0: Stribeck map, no bristles
    {"mechanics.lugre_damping", "N s/m", 0.0, 1e5, true},
    {"sensors.pressure_noise", "Pa", 0.0, 1e5, false},
    {"sensors.pressure_full_scale", "Pa", 1e4, 1e8, false},
    {"sensors.pressure_filter_time_constant", "s", 0.0, 0.5, true},
    {"sensors.position_noise", "m", 0.0, 0.01, false},
    {"sensors.position_resolution", "m", 0.0, 0.01, false},
    {"sensors.adc_range", "V", 0.1, 100.0, false},
    {"sensors.force_offset", "N", -1e4, 1e4, true},
    {"simulation.relative_tolerance", "", 1e-12, 1e-2, false},
    {"simulation.absolute_tolerance", "", 1e-12, 1e-2, false},
};

double IpaParameters::*FieldOf(const std::string& key) {
  for (const auto& k : DoubleKeys())
    if (key == k.key) return k.field;
  return nullptr;
}

/// Shortest round-trip decimal that TOML reads as a float (never as an integer).
std::string TomlFloat(double v) {
  std::string s = fmt::format("{}", v);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

std::string Where(const std::string& path, const toml::node& node) {
  const auto& src = node.source();
  if (src.begin.line == 0) return path;
  return fmt::format("{}:{}:{}", path, src.begin.line, src.begin.column);
}

}  // namespace

const std::vector<IpaParameterInfo>& IpaParameterTable() {
  static const std::vector<IpaParameterInfo> table = [] {
    std::vector<IpaParameterInfo> t;
    for (const Range& r : kRanges) t.push_back({r.key, r.unit, r.lower, r.upper, r.calibratable});
    return t;
  }();
  return table;
}

const IpaParameterInfo& FindIpaParameter(const std::string& name) {
  const IpaParameterInfo* found = nullptr;
  int matches = 0;
  for (const auto& info : IpaParameterTable()) {
    if (info.key == name) return info;
    const auto dot = info.key.find('.');
    if (info.key.compare(dot + 1, std::string::npos, name) == 0) {
      found = &info;
      ++matches;
    }
  }
  if (matches == 1) return *found;
  std::string keys;
  for (const auto& info : IpaParameterTable()) keys += (keys.empty() ? "" : ", ") + info.key;
  if (matches > 1)
    throw InvalidArgument(fmt::format(
        "IPA parameter name '{}' is ambiguous: give it with its section; valid names: {}",
        Excerpt(name), keys));
  throw InvalidArgument(
      fmt::format("unknown IPA parameter '{}'; valid names: {}", Excerpt(name), keys));
}

double GetIpaParameter(const IpaParameters& p, const std::string& name) {
  return p.*FieldOf(FindIpaParameter(name).key);
}

void SetIpaParameter(IpaParameters& p, const std::string& name, double value) {
  p.*FieldOf(FindIpaParameter(name).key) = value;
}

std::string IpaParametersToToml(const IpaParameters& p, const std::string& comment) {
  std::string out;
  std::size_t begin = 0;
  while (!comment.empty() && begin <= comment.size()) {
    const auto end = std::min(comment.find('\n', begin), comment.size());
    out += "# " + comment.substr(begin, end - begin) + "\n";
    begin = end + 1;
  }
  // One table per section, in the order of first appearance; [simulation]
  // first, with the two modes.
  std::vector<std::string> sections = {"simulation"};
  for (const auto& info : IpaParameterTable()) {
    const std::string sec = info.key.substr(0, info.key.find('.'));
    if (std::find(sections.begin(), sections.end(), sec) == sections.end()) sections.push_back(sec);
  }
  for (const auto& sec : sections) {
    out += fmt::format("\n[{}]\n", sec);
    if (sec == "simulation")
      out +=
          fmt::format("mode = \"{}\"\npwm_mode = \"{}\"\n", ToString(p.mode), ToString(p.pwm_mode));
    for (const auto& info : IpaParameterTable()) {
      const auto dot = info.key.find('.');
      if (info.key.compare(0, dot, sec) != 0 || dot != sec.size()) continue;
      out += fmt::format("{} = {}", info.key.substr(dot + 1), TomlFloat(p.*FieldOf(info.key)));
      out += info.unit.empty() ? "\n" : fmt::format("    # {}\n", info.unit);
    }
    if (sec == "sensors") {
      out += fmt::format("adc_bits = {}\n", p.adc_bits);
      out += fmt::format("transport_delay_samples = {}\n", p.transport_delay_samples);
    }
  }
  return out;
}

IpaParameters DefaultIpaParameters(IpaMode mode) {
  IpaParameters p;
  p.mode = mode;
  if (mode == IpaMode::kPosition) {
    // The position rig (docs/position.md): four small fast 2/2 valves.
    p.inlet_conductance = 1.0e-9;
    p.exhaust_conductance = 1.2e-9;
    p.open_delay = 0.0003;
    p.close_delay = 0.0005;
    p.min_pulse_width = 0.0003;
  }
  return p;
}

IpaParameters LoadIpaParameters(const std::string& path, IpaMode mode) {
  toml::table root;
  try {
    root = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    const auto& src = e.source();
    if (src.begin.line == 0) throw DataError(fmt::format("{}: {}", path, e.description()));
    throw DataError(
        fmt::format("{}:{}:{}: {}", path, src.begin.line, src.begin.column, e.description()));
  }
  // Keys not in the file keep the defaults of the file's mode (checked below).
  if (auto named = root["simulation"]["mode"].value<std::string>()) {
    try {
      mode = IpaModeFromString(*named);
    } catch (const InvalidArgument&) {
    }
  }
  IpaParameters p = DefaultIpaParameters(mode);
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
