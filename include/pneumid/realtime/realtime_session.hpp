// A complete logged run, as `pneumid run` and `pneumid experiment` do it:
// log file with header, SIGINT/SIGTERM handling, optional live status line on
// stderr, the loop, then the statistics written into the log.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "pneumid/realtime/log_writer.hpp"
#include "pneumid/realtime/realtime_loop.hpp"

namespace pneumid {

/// Everything RunSession needs besides the backend, controller and set point.
struct SessionOptions {
  LoopOptions loop;      ///< period, duration and scheduling of the loop
  SafetyOptions safety;  ///< limits and fault detection (a SafetyMonitor is built from them)
  std::string log_path;  ///< empty: no log file
  LogWriterOptions log;  ///< format and buffering of the log
  /// Header lines (key, value) recorded in the log besides the automatic ones
  /// (io, controller, period, duration, safety).
  std::vector<std::pair<std::string, std::string>> header;
  /// Redraw a one-line status (t, set point, output, input, jitter; the actuator's
  /// words, e.g. force and duty for the IPA) on stderr every 0.2 s.
  bool live_status = false;
  /// Keep the records in memory (SessionResult::records), e.g. for metrics.
  bool keep_records = false;
};

/// Outcome of RunSession.
struct SessionResult {
  LoopSummary summary;             ///< how the loop ended, with its timing statistics
  std::int64_t log_rows = 0;       ///< records written to the log (LogWriter::written(); 0: none)
  std::vector<LogRecord> records;  ///< when keep_records
};

/// Runs the session. Installs the stop-signal handlers.
/// @throws InvalidArgument / DataError as RunLoop and LogWriter do (before the run);
/// DataError when the log cannot be completed.
SessionResult RunSession(const SessionOptions& options, IoBackend& io, LoopController& controller,
                         const std::vector<double>& setpoint);

/// Human-readable safety settings in the actuator's units and names, e.g.
/// "u in [0, 100] %, rate unlimited, y in [..], ..., safe state valves-closed".
std::string DescribeSafety(const SafetyOptions& s, const Actuator& actuator);

}  // namespace pneumid
