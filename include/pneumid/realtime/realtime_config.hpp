// Configuration of a real-time run from a TOML file (config/realtime_example.toml),
// shared by `pneumid run`, `pneumid experiment` and the bindings. Command-line
// flags override the file. Every key is optional; defaults are those of the
// option structs:
//
//   [loop]    period (s), duration (s), realtime (bool), priority, cpu, fast (bool)
//   [io]      backend = "sim" | "comedi:/dev/comedi0" | "udp://HOST:PORT", plant (sim)
//   [safety]  u_min, u_max, rate_max (per s), y_min, y_max, frozen_samples, frozen_tolerance
//             (the actuator's units: % and N for the IPA), max_overruns,
//             safe_state = "hold" | "release" (IPA: "valves-closed" | "exhaust-open")
//   [udp]     max_missed, reply_wait (periods), hello_timeout (s), hello_attempts
//   [comedi]  device, ai_subdevice, ai_channel, ai_range, ai_aref, v_min, v_max,
//             pressure_gain, pressure_offset, force_gain, force_offset, ao_subdevice,
//             inlet_channel, exhaust_channel, ao_range, v_closed, v_open,
//             exhaust_complementary, use_calibration
//   [log]     flush_interval (s), capacity (records)
//   [controller] model (spec or FILE.json#METHOD, relative to the file's folder),
//             type (dmc, gpc, pid, mpc), rule, P, M, lambda, overshoot,
//             aggressiveness, response_time, u_min, u_max, du_max, y_min, y_max,
//             constrained, disturbance, t_filter, tau_c, pid_rule, input_map,
//             input_gaps, y_valid_min, y_valid_max, safe_input: the flags of
//             control/run/codegen (controller_factory.hpp ControllerSettings),
//             which override them (`pneumid commission` writes this section)
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pneumid/control/controller_factory.hpp"

#include "pneumid/realtime/comedi_backend.hpp"
#include "pneumid/realtime/log_writer.hpp"
#include "pneumid/realtime/realtime_loop.hpp"
#include "pneumid/realtime/safety.hpp"
#include "pneumid/realtime/udp_backend.hpp"

namespace pneumid {

/// The [controller] section: a controller as control, run and codegen build it.
struct ControllerConfig {
  std::string model;              ///< the --model spec
  ControllerSettings settings;    ///< the settings the file gives (the others at their defaults)
  std::vector<std::string> keys;  ///< the keys the file gives (the flags override only these)
};

/// Every setting of a real-time run, by TOML section (see above).
struct RealtimeConfig {
  LoopOptions loop;           ///< [loop]: period, duration, scheduling
  SafetyOptions safety;       ///< [safety]: limits, fault detection, safe state
  std::string io = "sim";     ///< --io spec
  std::string plant = "ipa";  ///< plant of the sim backend (MakePlant spec)
  /// [io] gave the plant (`control --config` simulates the model otherwise,
  /// as `control` does without --plant; `run` the default "ipa").
  bool plant_given = false;
  UdpBackendOptions udp;      ///< [udp]: used by a udp:// backend (host, port from io)
  ComediConfig comedi;        ///< [comedi]: used by a comedi backend (device from io)
  LogWriterOptions log;       ///< [log]: flushing and buffer capacity
  std::optional<ControllerConfig> controller;  ///< [controller], when the file has it
  /// [safety] gave u_min or u_max; otherwise `pneumid run` clamps to the
  /// plant's input range (PlantActuator: IPA force 0..100 %, position -100..100 %).
  bool safety_range_given = false;
};

/// Reads a configuration file. @throws DataError naming the file, line and column
/// for a syntax error, an unknown section or key, or a value of the wrong type.
RealtimeConfig LoadRealtimeConfig(const std::string& path);
/// Same from TOML text (`source` names it in errors).
RealtimeConfig ParseRealtimeConfig(const std::string& text, const std::string& source);

}  // namespace pneumid
