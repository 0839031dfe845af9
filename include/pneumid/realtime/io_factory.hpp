// Builds the I/O backend selected by an --io spec (io_backend.hpp) and a
// configuration (realtime_config.hpp).
#pragma once

#include <memory>

#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/realtime/io_backend.hpp"
#include "pneumid/realtime/realtime_config.hpp"

namespace pneumid {

/// sim: MakePlant(config.plant, config.loop.period, plant_options) in a SimBackend;
/// comedi: config.comedi with the device of the spec; udp: config.udp with the
/// host and port of the spec. The backend is not opened yet.
/// @throws InvalidArgument for a bad spec or configuration, DataError for an
/// unreadable plant file.
std::unique_ptr<IoBackend> MakeIoBackend(const IoSpec& spec, const RealtimeConfig& config,
                                         const PlantOptions& plant_options = {});

}  // namespace pneumid
