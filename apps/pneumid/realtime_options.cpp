#include "realtime_options.hpp"

#include <cctype>
#include <filesystem>
#include <iostream>

#include "command.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/realtime/io_backend.hpp"
#include "pneumid/realtime/safety.hpp"
#include "validators.hpp"

namespace pneumid::cli {

void AddRealtimeOptions(CLI::App& app, RealtimeOptions& o, const RealtimeHelp& help) {
  app.add_option("--io", o.io, "backend: sim, comedi:/dev/comediN or udp://HOST:PORT")
      ->capture_default_str();
  app.add_option("--config", o.config, "real-time TOML configuration (flags override it)");
  app.add_option("--plant", o.plant, help.plant);
  app.add_option("--seed", o.seed, help.seed)->capture_default_str();
  app.add_option("--noise", o.noise, "measurement noise of the simulated plant (output units)")
      ->check(NonNegative());
  app.add_option("--duration", o.duration, "length of the run in s")
      ->capture_default_str()
      ->check(Positive());
  AddSampleTimeOption(app, o.period, "loop period (sample time) in s, 0.0001 .. 10 (default 10 ms)",
                      true, 1e-4, 10.0);
  app.add_flag("--fast", o.fast, "sim only: as fast as possible instead of real time");
  app.add_flag("--no-realtime", o.no_realtime,
               "do not ask for SCHED_FIFO/mlockall/pinning (normal priority)");
  app.add_option("--safe-state", o.safe_state,
                 "actuator state after a fault or stop: hold (default; IPA: valves-closed) or "
                 "release (IPA: exhaust-open)")
      ->check(CLI::IsMember({"hold", "release", "valves-closed", "exhaust-open"}));
  app.add_option("--max-overruns", o.max_overruns,
                 "deadline overruns tolerated before the fault stop (-1: never)")
      ->capture_default_str()
      ->check(AtLeast(-1));
  app.add_option("--log", o.log, help.log);
  app.add_flag("--json", o.json, help.json);
}

RealtimeConfig ResolveRealtimeConfig(const RealtimeOptions& o, const CLI::App& app) {
  RealtimeConfig config = o.config.empty() ? RealtimeConfig{} : LoadRealtimeConfig(o.config);
  if (app.count("--io") || o.config.empty()) config.io = o.io;
  if (!o.plant.empty()) config.plant = o.plant;
  if (app.count("--duration") || o.config.empty()) config.loop.duration = o.duration;
  if (app.count("--Ts") || o.config.empty()) config.loop.period = o.period;
  if (o.fast) config.loop.fast = true;
  if (o.no_realtime) config.loop.realtime = false;
  if (!o.safe_state.empty()) config.safety.safe_state = SafeStateFromString(o.safe_state);
  if (app.count("--max-overruns")) config.safety.max_overruns = o.max_overruns;
  std::string error;
  PNEUMID_CHECK(config.loop.IsValid(&error), "{}", error);
  PNEUMID_CHECK(!config.loop.fast || ParseIoSpec(config.io).kind == IoKind::kSim,
                "--fast runs the simulator as fast as possible; it needs --io sim, got '{}'",
                config.io);
  return config;
}

PlantOptions SimulatedPlantOptions(const RealtimeOptions& o) {
  PlantOptions p;
  p.seed = o.seed;
  p.noise_sigma = o.noise;
  return p;
}

bool IsMatPath(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".mat";
}

void FinishSession(const std::string& command, const LoopSummary& summary) {
  if (summary.termination == Termination::kSuccess) return;
  std::cerr << "pneumid " << command << ": " << ToString(summary.termination) << ": "
            << summary.message << "\n";
  throw ExitCode{summary.ExitStatus()};
}

}  // namespace pneumid::cli
