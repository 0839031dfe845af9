// Plant server: serves a Plant over the UDP protocol of udp_protocol.hpp so that
// the real-time loop can run against a simulator in another process, as it
// would against the rig (hardware in the loop). `pneumid plant-server` wraps it.
//
// The server does not keep time: it advances its plant by one period per Step
// request, so the client's loop paces the simulation.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pneumid/control/closed_loop.hpp"
#include "pneumid/plant/actuator.hpp"
#include "pneumid/plant/plant.hpp"
#include "pneumid/realtime/safety.hpp"
#include "pneumid/realtime/udp_protocol.hpp"

namespace pneumid {

/// Socket, fault drill and load disturbances of a PlantServer.
struct PlantServerOptions {
  std::string bind_address = "127.0.0.1";  ///< numeric IPv4/IPv6 address to listen on
  int port = 5000;                         ///< UDP port (0: any free port, see port())
  /// Fault drill: stop answering after this many Step requests (-1: never). The
  /// server keeps receiving, so a client sees a silent server.
  std::int64_t stop_answering_after = -1;
  /// Load disturbances on the plant's output (closed_loop.hpp), by plant time
  /// since the session's Hello (the plant's Reset).
  std::vector<LoadStep> load_steps;
  /// True for a port in 0..65535 and a numeric IPv4/IPv6 bind_address; otherwise false
  /// with the reason in *error (when not null).
  bool IsValid(std::string* error) const;
};

/// Counters of a PlantServer since construction.
struct PlantServerStats {
  std::int64_t requests = 0;       ///< valid requests received
  std::int64_t steps = 0;          ///< plant steps taken
  std::int64_t sessions = 0;       ///< Hello requests
  std::int64_t bad_packets = 0;    ///< datagrams rejected (size, magic, version, type)
  std::int64_t safe_requests = 0;  ///< Safe requests (their state: last_safe_state)
  int last_safe_state = -1;        ///< SafeState of the last Safe request (-1: none)
};

/// Serves a Plant over UDP (udp_protocol.hpp), one plant period per Step request.
class PlantServer {
 public:
  /// Binds the socket. @throws InvalidArgument on bad options or null plant, DataError
  /// when the address cannot be bound (e.g. port in use).
  PlantServer(std::unique_ptr<Plant> plant, PlantServerOptions options);
  ~PlantServer();
  PlantServer(const PlantServer&) = delete;  ///< not copyable: owns the socket
  PlantServer& operator=(const PlantServer&) = delete;

  /// The bound port.
  int port() const { return port_; }
  /// Serves requests until `stop` becomes true or a stop signal is requested
  /// (RequestStop / SIGINT with InstallStopSignalHandlers); checks every 50 ms.
  void Serve(const std::atomic<bool>& stop);
  /// Handles one request datagram and fills the reply; returns false when no reply is
  /// to be sent (bad packet, or the fault drill is active). Exposed for tests.
  bool Handle(const std::uint8_t* data, std::size_t size, udp::Packet* reply);
  /// Counters (read them while Serve is not running).
  PlantServerStats stats() const { return stats_; }
  std::string Describe() const { return plant_->Describe(); }  ///< the plant's Describe()

 private:
  std::unique_ptr<Plant> plant_;
  PlantServerOptions options_;
  Actuator actuator_;  // the plant's, told by Info (its gaps) and Describe
  int fd_ = -1;
  int port_ = 0;
  bool session_ = false;
  std::uint32_t last_seq_ = 0;
  bool have_last_ = false;
  udp::Packet last_reply_{};
  PlantServerStats stats_;
};

}  // namespace pneumid
