// Logging of the real-time loop: the loop thread pushes one LogRecord per
// sample into a lock-free ring buffer; a writer thread formats and writes them.
//
// CSV layout (format "csv"):
//   # pneumid real-time log                      <- header lines start with '#'
//   # key: value                                 <- configuration, controller, ...
//   # timing: ...                                <- filled in at Close() (reserved space)
//   # stop: ...                                  <- filled in at Close() (reserved space)
//   t,u,y,r,u_ctrl,aux,jitter_us,compute_us,flags,fault
//   0.00,12.5,0.31,...
// Columns (in the actuator's units, IoBackend::actuator(); for the IPA duty %,
// force N, chamber pressure Pa): t (s, scheduled time), u (applied input, after
// the safety layer), y (measured output), r (set point), u_ctrl (controller
// output before the safety layer), aux (auxiliary measurement, or nan),
// jitter_us (wake-up lateness), compute_us (time of the step), flags (bit 0
// clamped, 1 rate limited, 2 stale sample, 3 deadline overrun, 4 safe state),
// fault (name, or empty). The dataset format ("dataset") writes only t,u,y so that
// `pneumid identify` reads it directly.
//
// Durability: the writer flushes to the operating system at least every
// flush_interval seconds (default 1 s), so a process killed with SIGKILL loses
// at most the last second; Close() drains the buffer, writes the statistics,
// flushes and fsyncs. With ".mat" output the records are kept in memory and
// written with matio at Close() (nothing survives SIGKILL: use CSV for that).
#pragma once

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "pneumid/realtime/safety.hpp"
#include "pneumid/realtime/spsc_ring_buffer.hpp"

namespace pneumid {

/// One logged sample (trivially copyable, pushed from the loop thread).
struct LogRecord {
  std::int64_t k = 0;          ///< sample index from 0
  double t = 0.0;              ///< scheduled time k * period, s
  double u = 0.0;              ///< input after the safety layer (NaN: sensor/controller fault)
  double y = 0.0;              ///< measured output (actuator units, IPA: force N)
  double r = 0.0;              ///< set point, output units
  double u_ctrl = 0.0;         ///< controller output before the safety layer (IPA: duty %)
  double aux = 0.0;            ///< auxiliary measurement (IPA: chamber pressure, Pa) or NaN
  double jitter_us = 0.0;      ///< wake-up lateness after the deadline, microseconds
  double compute_us = 0.0;     ///< wake-up to end of the step (read, control, write), us
  std::uint32_t flags = 0;     ///< LogFlag bits
  Fault fault = Fault::kNone;  ///< fault raised at this sample (kNone: none)
};

/// Bits of LogRecord::flags.
enum LogFlag : std::uint32_t {
  kLogClamped = 1u << 0,
  kLogRateLimited = 1u << 1,
  kLogStale = 1u << 2,
  kLogOverrun = 1u << 3,
  kLogSafeState = 1u << 4,
};

/// File format of a LogWriter.
enum class LogFormat {
  kCsv,      ///< all columns, CSV with '#' header
  kDataset,  ///< t,u,y only (CSV with '#' header), for `pneumid identify`
  kMat,      ///< MATLAB .mat (v5) written at Close()
};
const char* ToString(LogFormat f);  ///< "csv", "dataset", "mat"
/// "csv", "dataset", "mat". @throws InvalidArgument.
LogFormat LogFormatFromString(const std::string& name);

/// Format, buffering and flushing of a LogWriter.
struct LogWriterOptions {
  LogFormat format = LogFormat::kCsv;  ///< file format (see LogFormat)
  std::size_t capacity = 1 << 16;      ///< ring buffer records (65 s at 1 kHz)
  double flush_interval = 1.0;         ///< seconds between flushes to the OS
  /// Also keep every record in memory (writer thread) for records() after Close().
  bool keep_in_memory = false;
  /// Also offer every record to this ring buffer (not owned; may be null), e.g. for
  /// live plots: Push() copies the record into it from the loop thread without
  /// blocking or allocating, and drops it (uncounted) when the ring is full. Its
  /// single consumer must keep draining it while the writer lives.
  SpscRingBuffer<LogRecord>* live = nullptr;
  /// True for capacity in [16, 2^26] and flush_interval in (0, 60] s; otherwise false
  /// with the reason in *error (when not null).
  bool IsValid(std::string* error) const;
};

/// Writes the real-time loop's records from a writer thread (see above): the loop
/// thread only pushes into a lock-free ring buffer.
class LogWriter {
 public:
  /// Opens `path` (truncating; empty with keep_in_memory: no file), writes the header lines (key,
  /// value) and starts the writer thread. @throws DataError when the file cannot be created,
  /// InvalidArgument on bad options.
  LogWriter(std::string path, std::vector<std::pair<std::string, std::string>> header,
            LogWriterOptions options = {});
  /// Closes if still open (errors ignored).
  ~LogWriter();
  LogWriter(const LogWriter&) = delete;  ///< not copyable: owns the file and the thread
  LogWriter& operator=(const LogWriter&) = delete;

  /// Loop thread: queues a record. Never blocks or allocates; when the buffer is
  /// full the record is dropped and counted.
  void Push(const LogRecord& r) noexcept {
    if (!ring_.TryPush(r)) dropped_.fetch_add(1, std::memory_order_relaxed);
    if (options_.live != nullptr) options_.live->TryPush(r);
  }
  /// Stops the writer thread after draining every queued record, fills in the
  /// reserved `timing` and `stop` header lines, flushes and fsyncs.
  /// @throws DataError on a write error.
  void Close(const std::string& timing_line = "", const std::string& stop_line = "");

  const std::string& path() const { return path_; }  ///< the log file (empty: none)
  /// Records formatted by the writer thread so far (any thread may ask).
  std::int64_t written() const { return written_.load(); }
  /// Records lost because the ring buffer was full (any thread may ask).
  std::int64_t dropped() const { return dropped_.load(); }
  /// Records written, when keep_in_memory or the .mat format (valid after Close()).
  const std::vector<LogRecord>& records() const { return mat_records_; }

 private:
  void WriterMain();
  void WriteRecord(const LogRecord& r);
  void WriteMat();

  std::string path_;
  LogWriterOptions options_;
  std::vector<std::pair<std::string, std::string>> header_;
  SpscRingBuffer<LogRecord> ring_;
  std::FILE* file_ = nullptr;
  long timing_offset_ = -1;
  long stop_offset_ = -1;
  std::vector<LogRecord> mat_records_;
  std::atomic<bool> stop_{false};
  std::atomic<std::int64_t> written_{0};
  std::atomic<std::int64_t> dropped_{0};
  std::atomic<bool> io_error_{false};
  std::thread thread_;
  bool closed_ = false;
};

}  // namespace pneumid
