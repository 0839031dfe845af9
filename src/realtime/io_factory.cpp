#include "pneumid/realtime/io_factory.hpp"

#include "pneumid/realtime/comedi_backend.hpp"
#include "pneumid/realtime/sim_backend.hpp"
#include "pneumid/realtime/udp_backend.hpp"

namespace pneumid {

std::unique_ptr<IoBackend> MakeIoBackend(const IoSpec& spec, const RealtimeConfig& config,
                                         const PlantOptions& plant_options) {
  switch (spec.kind) {
    case IoKind::kSim:
      return std::make_unique<SimBackend>(
          MakePlant(config.plant, config.loop.period, plant_options));
    case IoKind::kComedi: {
      ComediConfig c = config.comedi;
      c.device = spec.device;
      return std::make_unique<ComediBackend>(c);
    }
    case IoKind::kUdp: {
      UdpBackendOptions u = config.udp;
      u.host = spec.host;
      u.port = spec.port;
      return std::make_unique<UdpBackend>(u);
    }
  }
  return nullptr;
}

}  // namespace pneumid
