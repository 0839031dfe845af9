// pneumid plant-server: serves a simulated plant over the UDP protocol of
// docs/realtime.md, as a stand-in for the rig (hardware in the loop). The plant
// advances one period per request, so the client's real-time loop paces it.
#include <atomic>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "command.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/plant/ipa_simulator.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/realtime/plant_server.hpp"
#include "pneumid/realtime/realtime_loop.hpp"
#include "validators.hpp"

namespace pneumid::cli {
namespace {

struct ServerOptions {
  std::string plant = "ipa";
  std::string plant_config;
  std::string bind = "127.0.0.1";
  int port = 5000;
  double Ts = 0.01;
  std::uint64_t seed = 1;
  std::optional<double> noise;
  std::int64_t stop_answering_after = -1;
  std::vector<std::string> load_steps;
};

void Serve(const ServerOptions& o) {
  PNEUMID_CHECK(o.Ts > 0.0, "--Ts must be positive, got {}", o.Ts);
  PlantOptions po;
  po.seed = o.seed;
  po.noise_sigma = o.noise;
  po.config_path = o.plant_config;
  PlantServerOptions so;
  so.bind_address = o.bind;
  so.port = o.port;
  so.stop_answering_after = o.stop_answering_after;
  for (const std::string& l : o.load_steps)
    so.load_steps.push_back(ParseLoadStep("--load-step", l));
  std::unique_ptr<Plant> plant = MakePlant(o.plant, o.Ts, po);
  PNEUMID_CHECK(o.plant_config.empty() || dynamic_cast<IpaSimulator*>(plant.get()),
                "--plant-config applies to the ipa plant only, not to '{}'", o.plant);
  PlantServer server(std::move(plant), so);
  InstallStopSignalHandlers();
  ClearStopRequest();
  std::cout << fmt::format("serving {} on udp://{}:{} (Ts = {:g} s, protocol v{})\n",
                           server.Describe(), o.bind, server.port(), o.Ts, udp::kVersion)
            << std::flush;
  std::atomic<bool> stop{false};
  server.Serve(stop);
  const PlantServerStats st = server.stats();
  std::cout << fmt::format(
                   "stopped: {} sessions, {} steps, {} requests, {} bad packets, {} safe-state "
                   "requests\n",
                   st.sessions, st.steps, st.requests, st.bad_packets, st.safe_requests)
            << std::flush;
}

}  // namespace

static Registrar reg(
    "plant-server",
    "Serve a simulated plant over UDP for `pneumid run/experiment --io udp://HOST:PORT` "
    "(hardware-in-the-loop stand-in); runs until SIGINT/SIGTERM",
    [](CLI::App& app) {
      auto o = std::make_shared<ServerOptions>();
      app.add_option("--plant", o->plant, "plant to serve\n" + PlantSpecHelp())
          ->capture_default_str();
      app.add_option("--plant-config", o->plant_config, "IPA parameter file (TOML)");
      app.add_option("--port", o->port, "UDP port (0: any free port, printed)")
          ->capture_default_str();
      app.add_option("--bind", o->bind, "numeric address to listen on")->capture_default_str();
      AddSampleTimeOption(app, o->Ts, "sample period of the plant (s); clients must use the same",
                          true);
      app.add_option("--seed", o->seed, "noise seed")->capture_default_str();
      app.add_option("--noise", o->noise, "measurement noise (output units)")->check(NonNegative());
      app.add_option("--stop-answering-after", o->stop_answering_after,
                     "fault drill: go silent after this many steps (-1: never)")
          ->capture_default_str()
          ->check(AtLeast(-1));
      app.add_option("--load-step", o->load_steps,
                     "load disturbance on the output at=T,size=D (repeatable), T in plant time "
                     "since the client's session began");
      app.callback([o] { Serve(*o); });
    });

}  // namespace pneumid::cli
