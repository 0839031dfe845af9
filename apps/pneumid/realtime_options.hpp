// Command-line options of the commands that run a loop in real time (run,
// experiment), shared like data_options/model_options:
//
//   --io SPEC            backend: sim, comedi:/dev/comediN or udp://HOST:PORT
//   --config FILE.toml   real-time configuration (flags given override it)
//   --plant SPEC         plant of the sim backend (default ipa)
//   --seed N             noise seed of the simulated plant
//   --noise SIGMA        measurement noise of the simulated plant (output units)
//   --duration T         length of the run in s
//   --Ts TS              loop period in s (aliases --period, --sample-time)
//   --fast               sim only: as fast as possible instead of real time
//   --no-realtime        normal priority (no SCHED_FIFO/mlockall/pinning)
//   --safe-state S       hold or release (IPA aliases: valves-closed, exhaust-open)
//   --max-overruns N     deadline overruns tolerated before the fault stop (-1: never)
//   --log FILE           real-time log
//   --json               the run summary as JSON
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/realtime/realtime_config.hpp"
#include "pneumid/realtime/realtime_loop.hpp"

namespace pneumid::cli {

struct RealtimeOptions {
  std::string io = "sim";
  std::string config;
  std::string plant;
  std::uint64_t seed = 1;
  std::optional<double> noise;
  double duration = 10.0;  ///< the caller may change the default before AddRealtimeOptions
  double period = 0.01;
  bool fast = false;
  bool no_realtime = false;
  std::string safe_state;
  int max_overruns = 10;
  std::string log;
  bool json = false;
};

/// Help texts that differ between commands.
struct RealtimeHelp {
  std::string plant = "plant of the sim backend (default ipa)";
  std::string seed = "noise seed of the simulated plant";
  std::string log = "log file (.csv streamed, .mat written at the end)";
  std::string json = "print the run summary as JSON";
};

/// Adds the flags above to `app`, storing into `options` (which must outlive the parse).
void AddRealtimeOptions(CLI::App& app, RealtimeOptions& options, const RealtimeHelp& help = {});

/// The configuration of the run: --config's file (or the defaults) with the
/// flags given on the command line applied over it (`app` tells which were given).
/// @throws DataError / InvalidArgument for an unreadable or invalid --config,
///   invalid loop settings (naming the flag and value), or --fast with another
///   backend than sim.
RealtimeConfig ResolveRealtimeConfig(const RealtimeOptions& options, const CLI::App& app);

/// Seed and noise of the simulated plant.
PlantOptions SimulatedPlantOptions(const RealtimeOptions& options);

/// True when `path` ends in ".mat" (case-insensitive).
bool IsMatPath(const std::string& path);

/// The common end of a real-time command: when the loop did not complete, says
/// why on stderr ("pneumid <command>: <termination>: <message>") and throws
/// ExitCode with the summary's exit status (3 on a fault, 128 + signal).
void FinishSession(const std::string& command, const LoopSummary& summary);

}  // namespace pneumid::cli
