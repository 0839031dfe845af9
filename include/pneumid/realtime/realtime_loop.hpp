// Fixed-period real-time loop.
//
// The loop runs on its own thread. At start-up that thread asks for real-time
// scheduling (SCHED_FIFO, mlockall, CPU pinning); when the system refuses, it
// keeps normal priority and says so in one line (LoopSummary::scheduling).
// Then, for k = 0 .. N-1, with t_k = t_0 + k Ts on CLOCK_MONOTONIC:
//
//   clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, t_k)   (skipped when fast)
//   y_k = io.Read()            -> SafetyMonitor::CheckMeasurement
//   u_k = controller(r_k, y_k) -> SafetyMonitor::LimitOutput (clamp, rate)
//   io.Write(u_k)
//   timing (jitter, compute, overrun) -> TimingStats; record -> LogWriter ring
//
// After start-up nothing on the loop thread allocates, locks or does file
// I/O (tests/realtime/realtime_loop_test.cpp checks it with a counting
// allocator). A fault, a stop signal (SIGINT/SIGTERM with
// InstallStopSignalHandlers) or the end of the run drive the outputs to the
// safe state.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pneumid/common/termination.hpp"
#include "pneumid/realtime/io_backend.hpp"
#include "pneumid/realtime/log_writer.hpp"
#include "pneumid/realtime/safety.hpp"
#include "pneumid/realtime/timing_stats.hpp"

namespace pneumid {

/// What the loop calls every period. Update runs on the loop thread: it must not
/// allocate, lock or do I/O, and must not throw (return NaN to report a failure).
class LoopController {
 public:
  virtual ~LoopController() = default;
  /// Called once before the first period (may allocate).
  virtual void Reset() {}
  /// Called on the loop thread before the first Update with the first valid
  /// measurement y (a rig need not start at the output Reset assumed); same
  /// rules as Update. Default: nothing.
  virtual void Start(double /*y*/) noexcept {}
  /// Input u_k for set point r and measurement y at sample k (the actuator's units,
  /// IoBackend::actuator(): for the IPA duty % from force N).
  virtual double Update(std::int64_t k, double r, double y) noexcept = 0;
  /// The input the safety layer applied, when it changed Update()'s (rate or
  /// range limit): controllers with memory follow it (Controller::Applied,
  /// anti-windup). Same rules as Update. Default: nothing.
  virtual void Applied(double /*u*/) noexcept {}
  /// Description for the log header, e.g. "dmc P=126 M=5 lambda=2.25".
  virtual std::string Describe() const = 0;
};

/// Open-loop input (experiments): u_k = input[k] (the last value held beyond the end).
class OpenLoopInput : public LoopController {
 public:
  /// @throws InvalidArgument when input is empty or holds non-finite values.
  OpenLoopInput(std::vector<double> input, std::string description);
  double Update(std::int64_t k, double r, double y) noexcept override;
  std::string Describe() const override { return description_; }

 private:
  std::vector<double> input_;
  std::string description_;
};

/// Timing and scheduling of RunLoop.
struct LoopOptions {
  double period = 0.01;    ///< s; default 10 ms (the paper's Ts), allowed 1e-4 .. 10 s
  double duration = 10.0;  ///< s; number of samples = round(duration / period)
  /// Run as fast as possible (no sleeping; only for backends that keep their own
  /// time, i.e. sim). Jitter is then not measured. Default false.
  bool fast = false;
  bool realtime = true;  ///< try SCHED_FIFO + mlockall + pinning (default true)
  int priority = 80;     ///< SCHED_FIFO priority 1..99
  int cpu = -1;          ///< CPU to pin to; -1: the last allowed CPU; -2: no pinning
  /// True for period in [1e-4, 10] s, a finite duration > 0 of at most 1e9 samples,
  /// priority 1..99 and cpu >= -2; otherwise false with the reason in *error (if not null).
  bool IsValid(std::string* error) const;
  /// round(duration / period).
  std::int64_t Samples() const;
};

// Termination here: kSuccess (all samples run), kStopped (SIGINT/SIGTERM or RequestStop()) or
// kFailure (a safety fault, named in LoopSummary::fault; outputs in the safe
// state). Written "success", "stopped", "failure" (common/termination.hpp;
// earlier versions wrote "completed" and "fault").

/// How a run of RunLoop ended, with its timing statistics.
struct LoopSummary {
  Termination termination = Termination::kSuccess;  ///< success, stopped or failure
  Fault fault = Fault::kNone;  ///< the safety fault that ended the run (kNone: none)
  int signal = 0;              ///< signal number when stopped by a signal
  std::string message;         ///< what happened, e.g. "sensor-nan at t = 1.230 s (sample 123) ..."
  std::string scheduling;      ///< one line: real-time scheduling obtained or why not
  std::int64_t samples = 0;    ///< samples run (rows logged)
  std::int64_t log_dropped = 0;             ///< records the log could not take (ring buffer full)
  SafeState safe_state = SafeState::kHold;  ///< safe state the outputs were left in
  /// The actuator's name of safe_state (IoBackend::actuator()), e.g. "valves-closed".
  std::string safe_state_name = "hold";
  IoStatus safe_state_status = IoStatus::kOk;  ///< result of EnterSafeState
  TimingReport timing;                         ///< jitter, compute-time and overrun statistics
  double wall_time = 0.0;                      ///< s from the first to the last sample

  /// 0 when completed, 128 + signal when stopped by a signal, 3 on a fault.
  int ExitStatus() const;
  /// One line: "TERMINATION: message; " and TimingReport::BriefReport().
  std::string BriefReport() const;
  /// timing keys of TimingReport::ToJson plus termination, fault, message, samples,
  /// scheduling, safe_state, log_dropped, wall_time.
  nlohmann::json ToJson() const;
};

/// Live values published by the loop (relaxed atomics) for a status line.
struct LoopStatus {
  std::atomic<std::int64_t> k{-1};        ///< last sample done (-1: none yet)
  std::atomic<double> r{0.0},             ///< set point of sample k (output units)
      y{0.0},                             ///< measured output of sample k (IPA: force N)
      u{0.0},                             ///< applied input of sample k (IPA: duty %)
      jitter_us{0.0};                     ///< wake-up lateness of sample k, microseconds
  std::atomic<std::int64_t> overruns{0};  ///< deadline overruns so far
  std::atomic<bool> running{false};       ///< true while the loop thread runs its periods
};

/// Runs the loop (blocking until it ends). `setpoint` holds r_k per sample (the last
/// value is held; empty means 0). `log` and `status` may be null. The backend is
/// opened before and closed after the run; the log is not closed (the caller adds
/// the summary with LogWriter::Close).
/// @throws InvalidArgument on invalid options (or fast with a backend that cannot),
/// DataError when the backend cannot be opened. Faults during the run are reported
/// in the summary, never thrown.
LoopSummary RunLoop(const LoopOptions& options, IoBackend& io, LoopController& controller,
                    const std::vector<double>& setpoint, SafetyMonitor& safety,
                    LogWriter* log = nullptr, LoopStatus* status = nullptr);

/// Installs SIGINT and SIGTERM handlers that ask every running loop to stop
/// (outputs to the safe state, log flushed). Idempotent.
void InstallStopSignalHandlers();
/// Asks running loops to stop as a signal would (signal 0 = programmatic).
void RequestStop(int signal = 0);
/// Clears a previous stop request (before a new run).
void ClearStopRequest();
/// The signal that requested a stop (-1 when none).
int StopRequestSignal();

}  // namespace pneumid
