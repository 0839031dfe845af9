#include "pneumid/realtime/realtime_config.hpp"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <utility>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "pneumid/common/check.hpp"

namespace pneumid {

namespace {

struct Reader {
  const std::string& source;

  [[noreturn]] void Fail(const toml::node& n, const std::string& what) const {
    const auto& s = n.source().begin;
    throw DataError(fmt::format("{}:{}:{}: {}", source, s.line, s.column, what));
  }

  template <typename T>
  void Get(const toml::table& t, const char* section, const char* key, T* out) const {
    const toml::node* n = t.get(key);
    if (!n) return;
    if constexpr (std::is_same_v<T, bool>) {
      if (!n->is_boolean()) Fail(*n, fmt::format("[{}] {} must be true or false", section, key));
      *out = n->as_boolean()->get();
    } else if constexpr (std::is_same_v<T, std::string>) {
      if (!n->is_string()) Fail(*n, fmt::format("[{}] {} must be a string", section, key));
      *out = n->as_string()->get();
    } else if constexpr (std::is_integral_v<T>) {
      if (!n->is_integer()) Fail(*n, fmt::format("[{}] {} must be an integer", section, key));
      const std::int64_t v = n->as_integer()->get();
      if (!std::in_range<T>(v)) {
        Fail(*n, fmt::format("[{}] {} = {} is out of range (at most {}, at least {})", section, key,
                             v, std::numeric_limits<T>::max(), std::numeric_limits<T>::min()));
      }
      *out = static_cast<T>(v);
    } else {
      if (!n->is_number()) Fail(*n, fmt::format("[{}] {} must be a number", section, key));
      *out = n->is_integer() ? static_cast<double>(n->as_integer()->get())
                             : n->as_floating_point()->get();
    }
  }

  void CheckKeys(const toml::table& t, const char* section,
                 std::initializer_list<const char*> keys) const {
    for (const auto& [k, v] : t) {
      bool known = false;
      for (const char* key : keys) known = known || k.str() == key;
      if (!known) {
        std::string list;
        for (const char* key : keys) list += (list.empty() ? "" : ", ") + std::string(key);
        Fail(v, fmt::format("unknown key '{}' in [{}] (known: {})", k.str(), section, list));
      }
    }
  }

  template <typename F>
  void Convert(const toml::table& t, const char* key, F&& f) const {
    const toml::node* n = t.get(key);
    if (!n) return;
    try {
      f(n->value_or(std::string()));
    } catch (const InvalidArgument& e) {
      Fail(*n, e.what());
    }
  }
};

// [controller]: the model and the settings of ControllerSettings under the
// names of the command-line flags (with '_' for '-').
void ParseControllerSection(const Reader& r, const toml::table& t, RealtimeConfig& c) {
  r.CheckKeys(t, "controller",
              {"model",
               "type",
               "rule",
               "P",
               "M",
               "lambda",
               "overshoot",
               "aggressiveness",
               "response_time",
               "u_min",
               "u_max",
               "du_max",
               "y_min",
               "y_max",
               "constrained",
               "disturbance",
               "measurement_noise",
               "state_noise",
               "disturbance_noise",
               "t_filter",
               "tau_c",
               "pid_rule",
               "input_map",
               "input_gaps",
               "y_valid_min",
               "y_valid_max",
               "safe_input",
               "Kc",
               "Ti",
               "Td",
               "Kff"});
  ControllerConfig cc;
  ControllerSettings& s = cc.settings;
  r.Get(t, "controller", "model", &cc.model);
  r.Get(t, "controller", "type", &s.controller);
  r.Get(t, "controller", "rule", &s.rule);
  r.Get(t, "controller", "P", &s.P);
  r.Get(t, "controller", "M", &s.M);
  r.Get(t, "controller", "lambda", &s.lambda);
  r.Get(t, "controller", "overshoot", &s.overshoot);
  r.Get(t, "controller", "aggressiveness", &s.aggressiveness);
  r.Get(t, "controller", "response_time", &s.response_time);
  r.Get(t, "controller", "u_min", &s.limits.u_min);
  r.Get(t, "controller", "u_max", &s.limits.u_max);
  r.Get(t, "controller", "du_max", &s.limits.du_max);
  r.Get(t, "controller", "y_min", &s.y_min);
  r.Get(t, "controller", "y_max", &s.y_max);
  r.Get(t, "controller", "constrained", &s.constrained);
  r.Get(t, "controller", "disturbance", &s.disturbance);
  r.Get(t, "controller", "measurement_noise", &s.measurement_noise);
  r.Get(t, "controller", "state_noise", &s.state_noise);
  r.Get(t, "controller", "disturbance_noise", &s.disturbance_noise);
  r.Get(t, "controller", "t_filter", &s.t_filter);
  r.Get(t, "controller", "tau_c", &s.tau_c);
  r.Get(t, "controller", "Kc", &s.pid_kc);
  r.Get(t, "controller", "Ti", &s.pid_ti);
  r.Get(t, "controller", "Td", &s.pid_td);
  r.Get(t, "controller", "Kff", &s.pid_kff);
  r.Get(t, "controller", "pid_rule", &s.pid_rule);
  r.Get(t, "controller", "input_map", &s.input_map);
  r.Get(t, "controller", "input_gaps", &s.input_gaps);
  r.Get(t, "controller", "y_valid_min", &s.y_valid_min);
  r.Get(t, "controller", "y_valid_max", &s.y_valid_max);
  r.Get(t, "controller", "safe_input", &s.safe_input);
  for (const auto& [k, v] : t) cc.keys.emplace_back(k.str());
  // NaN stands for "the rule's value" in ControllerSettings, and 0 for the
  // rule's horizons: a file that writes them would silently get the rule's.
  for (const auto& [k, v] : t) {
    if (const auto* d = v.as_floating_point(); d != nullptr && std::isnan(d->get()))
      r.Fail(v, fmt::format("[controller] {} must be a number, got nan (leave the key out for the "
                            "rule's value)",
                            k.str()));
  }
  for (const char* key : {"P", "M"}) {
    if (const toml::node* n = t.get(key); n != nullptr && n->is_integer() &&
                                          n->as_integer()->get() < 1)
      r.Fail(*n, fmt::format("[controller] {} must be >= 1, got {} (leave the key out for the "
                             "rule's value)",
                             key, n->as_integer()->get()));
  }
  // A model file named relative to the configuration is found beside it.
  const auto hash = cc.model.find('#');
  const std::filesystem::path file = cc.model.substr(0, hash);
  const std::filesystem::path dir = std::filesystem::path(r.source).parent_path();
  if (!file.empty() && file.is_relative() && !dir.empty() && std::filesystem::exists(dir / file))
    cc.model = (dir / file).string() + (hash == std::string::npos ? "" : cc.model.substr(hash));
  if (const toml::node* n = t.get("type")) {
    try {
      (void)ControllerTypeFromString(s.controller);
    } catch (const InvalidArgument& e) {
      r.Fail(*n, e.what());
    }
  }
  if (const toml::node* n = t.get("input_gaps")) {
    try {
      (void)ParseInputGaps(s.input_gaps);
    } catch (const InvalidArgument& e) {
      r.Fail(*n, e.what());
    }
  }
  c.controller = cc;
}

}  // namespace

RealtimeConfig ParseRealtimeConfig(const std::string& text, const std::string& source) {
  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    throw DataError(fmt::format("{}:{}:{}: {}", source, e.source().begin.line,
                                e.source().begin.column, e.description()));
  }
  Reader r{source};
  RealtimeConfig c;
  for (const auto& [k, v] : root) {
    const std::string name(k.str());
    if (!v.is_table())
      r.Fail(v, fmt::format("'{}' must be a section ([controller], [loop], [io], [safety], [udp], "
                            "[comedi], [log])",
                            name));
    const toml::table& t = *v.as_table();
    if (name == "loop") {
      r.CheckKeys(t, "loop", {"period", "duration", "realtime", "priority", "cpu", "fast"});
      r.Get(t, "loop", "period", &c.loop.period);
      r.Get(t, "loop", "duration", &c.loop.duration);
      r.Get(t, "loop", "realtime", &c.loop.realtime);
      r.Get(t, "loop", "priority", &c.loop.priority);
      r.Get(t, "loop", "cpu", &c.loop.cpu);
      r.Get(t, "loop", "fast", &c.loop.fast);
    } else if (name == "io") {
      r.CheckKeys(t, "io", {"backend", "plant"});
      r.Get(t, "io", "backend", &c.io);
      r.Convert(t, "backend", [](const std::string& s) { ParseIoSpec(s); });
      r.Get(t, "io", "plant", &c.plant);
      c.plant_given = t.contains("plant");
    } else if (name == "safety") {
      r.CheckKeys(t, "safety",
                  {"u_min", "u_max", "rate_max", "y_min", "y_max", "frozen_samples",
                   "frozen_tolerance", "max_overruns", "safe_state"});
      auto& s = c.safety;
      r.Get(t, "safety", "u_min", &s.u_min);
      r.Get(t, "safety", "u_max", &s.u_max);
      c.safety_range_given = t.contains("u_min") || t.contains("u_max");
      r.Get(t, "safety", "rate_max", &s.rate_max);
      r.Get(t, "safety", "y_min", &s.y_min);
      r.Get(t, "safety", "y_max", &s.y_max);
      r.Get(t, "safety", "frozen_samples", &s.frozen_samples);
      r.Get(t, "safety", "frozen_tolerance", &s.frozen_tolerance);
      r.Get(t, "safety", "max_overruns", &s.max_overruns);
      r.Convert(t, "safe_state",
                [&](const std::string& v) { s.safe_state = SafeStateFromString(v); });
    } else if (name == "udp") {
      r.CheckKeys(t, "udp", {"max_missed", "reply_wait", "hello_timeout", "hello_attempts"});
      r.Get(t, "udp", "max_missed", &c.udp.max_missed);
      r.Get(t, "udp", "reply_wait", &c.udp.reply_wait);
      r.Get(t, "udp", "hello_timeout", &c.udp.hello_timeout);
      r.Get(t, "udp", "hello_attempts", &c.udp.hello_attempts);
    } else if (name == "comedi") {
      r.CheckKeys(t, "comedi",
                  {"device", "ai_subdevice", "ai_channel", "ai_range", "ai_aref", "v_min", "v_max",
                   "pressure_gain", "pressure_offset", "force_gain", "force_offset", "ao_subdevice",
                   "inlet_channel", "exhaust_channel", "ao_range", "v_closed", "v_open",
                   "exhaust_complementary", "use_calibration"});
      auto& m = c.comedi;
      r.Get(t, "comedi", "device", &m.device);
      r.Get(t, "comedi", "ai_subdevice", &m.ai_subdevice);
      r.Get(t, "comedi", "ai_channel", &m.ai_channel);
      r.Get(t, "comedi", "ai_range", &m.ai_range);
      r.Convert(t, "ai_aref",
                [&](const std::string& v) { m.ai_aref = AnalogReferenceFromString(v); });
      r.Get(t, "comedi", "v_min", &m.v_min);
      r.Get(t, "comedi", "v_max", &m.v_max);
      r.Get(t, "comedi", "pressure_gain", &m.pressure_gain);
      r.Get(t, "comedi", "pressure_offset", &m.pressure_offset);
      r.Get(t, "comedi", "force_gain", &m.force_gain);
      r.Get(t, "comedi", "force_offset", &m.force_offset);
      r.Get(t, "comedi", "ao_subdevice", &m.ao_subdevice);
      r.Get(t, "comedi", "inlet_channel", &m.inlet_channel);
      r.Get(t, "comedi", "exhaust_channel", &m.exhaust_channel);
      r.Get(t, "comedi", "ao_range", &m.ao_range);
      r.Get(t, "comedi", "v_closed", &m.v_closed);
      r.Get(t, "comedi", "v_open", &m.v_open);
      r.Get(t, "comedi", "exhaust_complementary", &m.exhaust_complementary);
      r.Get(t, "comedi", "use_calibration", &m.use_calibration);
    } else if (name == "controller") {
      ParseControllerSection(r, t, c);
    } else if (name == "log") {
      r.CheckKeys(t, "log", {"flush_interval", "capacity"});
      r.Get(t, "log", "flush_interval", &c.log.flush_interval);
      r.Get(t, "log", "capacity", &c.log.capacity);
    } else {
      r.Fail(v, fmt::format(
                    "unknown section [{}] (known: controller, loop, io, safety, udp, comedi, log)",
                    name));
    }
  }
  // Value checks, reported against the file.
  std::string error;
  if (!c.loop.IsValid(&error)) throw DataError(fmt::format("{}: [loop] {}", source, error));
  if (!c.safety.IsValid(&error)) throw DataError(fmt::format("{}: [safety] {}", source, error));
  if (!c.comedi.IsValid(&error)) throw DataError(fmt::format("{}: [comedi] {}", source, error));
  if (!c.log.IsValid(&error)) throw DataError(fmt::format("{}: [log] {}", source, error));
  return c;
}

RealtimeConfig LoadRealtimeConfig(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw DataError(fmt::format("{}: cannot open configuration file", path));
  std::stringstream ss;
  ss << in.rdbuf();
  return ParseRealtimeConfig(ss.str(), path);
}

}  // namespace pneumid
