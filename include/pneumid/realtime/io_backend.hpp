// I/O backends of the real-time loop: one interface for the simulator, a data
// acquisition card (comedi) and a remote plant server (UDP).
//
// Per period k the loop calls
//   Read(&m)    -> m.y: the measured output at t_k
//   Write(u)    -> applies the input u until t_(k+1)
// and on a fault or stop EnterSafeState(). Units, input range and the names of
// the safe states are the actuator's (actuator(), plant/actuator.hpp): for the
// IPA (simulator, comedi rig, plant server) u is the valve duty in % and y the
// force in N. Read, Write and EnterSafeState run on
// the loop thread: implementations must not allocate, lock or do file I/O
// there (system calls to the device or socket are the backend's job).
// Open and Close run outside the loop and may allocate and throw.
#pragma once

#include <limits>
#include <memory>
#include <string>

#include "pneumid/realtime/safety.hpp"

namespace pneumid {

/// One sample read from the plant.
struct Measurement {
  double y = 0.0;  ///< measured output (actuator().output units)
  /// Auxiliary measurement (IPA: chamber pressure, Pa) when the backend has one, else NaN.
  double aux = std::numeric_limits<double>::quiet_NaN();
};

/// Plant I/O of the real-time loop: read y, write u, enter a safe state (see above).
class IoBackend {
 public:
  virtual ~IoBackend() = default;
  /// Prepares the device for a run with sample period `period` (s).
  /// @throws DataError (device missing, server not answering) or InvalidArgument.
  virtual void Open(double period) = 0;
  /// Reads the current sample. Never throws; failures are returned as a status.
  virtual IoStatus Read(Measurement* m) noexcept = 0;
  /// Applies input u (actuator().input units) for one period. Never throws.
  virtual IoStatus Write(double u) noexcept = 0;
  /// Drives the outputs to the safe state. Never throws; best effort on a broken device.
  virtual IoStatus EnterSafeState(SafeState state) noexcept = 0;
  /// Releases the device (outputs are left in the last state written).
  virtual void Close() = 0;
  /// True when the backend keeps its own time (simulation) so the loop may run
  /// as fast as possible instead of sleeping.
  virtual bool CanRunFast() const { return false; }
  /// Short description for logs, e.g. "udp://127.0.0.1:5000 (ipa ...)".
  virtual std::string Describe() const = 0;
  /// The actuator behind the backend: channels, input range, safe-state names.
  /// Default: the generic description (Actuator{}).
  virtual Actuator actuator() const { return Actuator{}; }
  /// The period Open() settled on when the device chose it instead of the one
  /// asked for (a plant server's, UdpBackendOptions::adopt_server_period);
  /// NaN (the default): the period given to Open().
  virtual double adopted_period() const { return std::numeric_limits<double>::quiet_NaN(); }
};

/// Backend kinds selectable with --io.
enum class IoKind { kSim, kComedi, kUdp };
const char* ToString(IoKind k);  ///< "sim", "comedi", "udp"

/// Parsed --io value: "sim", "comedi" or "comedi:/dev/comediN", "udp://HOST:PORT".
struct IoSpec {
  IoKind kind = IoKind::kSim;           ///< which backend
  std::string device = "/dev/comedi0";  ///< comedi device path
  std::string host = "127.0.0.1";       ///< udp server host
  int port = 0;                         ///< udp server port
  /// The spec back: "sim", "comedi:DEVICE" or "udp://HOST:PORT".
  std::string ToString() const;
};

/// Parses an --io spec. @throws InvalidArgument naming the spec and what is wrong.
IoSpec ParseIoSpec(const std::string& spec);

}  // namespace pneumid
