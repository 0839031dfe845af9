// A Plant over an I/O backend (io_backend.hpp), so that the code written for
// plants (experiments, closed loops, workflow/commission.hpp) drives a real
// plant: a data acquisition card (comedi) or a plant server over UDP.
//
//   Measure()  -> backend.Read(): the measured output plus the load
//                 disturbance set by SetLoadDisturbance (an output
//                 disturbance, as every simulated plant applies it), NaN when
//                 the read fails or times out (the caller's safety check stops then)
//   Advance(u) -> backend.Write(u), then, in real time, a wait until the
//                 next period (absolute deadlines on the steady clock, so the
//                 period does not drift); without real time the next sample
//                 follows at once (the simulator, or a plant server, which
//                 advances its plant by one period per request)
//   Reset()    -> a real plant cannot be reset: the clock restarts
//
// The destructor leaves the actuator in its release state (IPA: exhaust open)
// and closes the backend.
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include "pneumid/plant/actuator.hpp"
#include "pneumid/plant/plant.hpp"
#include "pneumid/realtime/io_backend.hpp"

namespace pneumid {

/// A Plant whose samples come from an IoBackend (file comment).
class IoPlant : public Plant {
 public:
  /// Opens `backend` with period Ts (s); `realtime` paces Advance() to the period.
  /// @throws InvalidArgument for a null backend or Ts <= 0; DataError when Open fails.
  IoPlant(std::unique_ptr<IoBackend> backend, double Ts, bool realtime);
  /// Enters the release safe state and closes the backend.
  ~IoPlant() override;
  IoPlant(const IoPlant&) = delete;             ///< not copyable: owns the backend
  IoPlant& operator=(const IoPlant&) = delete;  ///< not copyable: owns the backend

  /// Restarts the clock and clears the load disturbance (a real plant keeps its state).
  void Reset() override;
  /// False: Reset() does not bring the plant back to rest.
  bool can_reset() const override { return false; }
  /// backend.Read(): the output plus the load disturbance, NaN on a read that
  /// failed or timed out.
  double Measure() override;
  /// backend.Write(u), then the wait for the next period in real time.
  void Advance(double u) override;
  double Ts() const override { return Ts_; }                              ///< the period in s
  double time() const override { return static_cast<double>(k_) * Ts_; }  ///< k Ts since Reset()
  /// "io: " + the backend's description.
  std::string Describe() const override;
  /// The backend's actuator (channels, input range, safe states).
  Actuator actuator() const override { return backend_->actuator(); }
  /// Status of the last Read or Write.
  IoStatus last_status() const { return status_; }
  /// Drives the actuator to `state` (best effort, as the backend's EnterSafeState).
  void EnterSafeState(SafeState state);

 private:
  std::unique_ptr<IoBackend> backend_;
  double Ts_;
  bool realtime_;
  long k_ = 0;
  IoStatus status_ = IoStatus::kOk;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace pneumid
