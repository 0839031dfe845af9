// The real-time run of `pneumid app`: one at a time, on a worker thread, as
// `pneumid run` does it (workflow/run_workflow.hpp RunRealtimeWorkflow), with
// its log in a file and its samples kept for the live plots. The loop thread
// hands every sample over through a lock-free ring buffer
// (LogWriterOptions::live); a pump thread drains it every 25 ms into the
// history that the WebSocket sessions read.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "../command_json.hpp"
#include "pneumid/realtime/log_writer.hpp"
#include "pneumid/realtime/realtime_config.hpp"
#include "pneumid/realtime/spsc_ring_buffer.hpp"

namespace pneumid::app {

class LiveRun {
 public:
  /// `log_path`: the file each run logs to (overwritten by the next run).
  explicit LiveRun(std::string log_path);
  /// Stops a run going on and waits for it.
  ~LiveRun();
  LiveRun(const LiveRun&) = delete;
  LiveRun& operator=(const LiveRun&) = delete;

  /// Starts a run of `args` (cli::ToWorkflowOptions; the log path is set
  /// here) with `config`.
  /// @returns false when a run is going on (nothing started).
  /// @throws InvalidArgument for a bad load step (nothing started).
  bool Start(const cli::RunArgs& args, RealtimeConfig config);

  /// True while a run is going on.
  bool Running() const;

  /// {"state": "idle"|"running"|"finished"|"stopped"|"failed", "samples", "elapsed",
  /// "summary"? (when ended), "error"? (when it failed before the loop)}.
  nlohmann::json Status() const;

  /// Asks a run to stop (outputs to the safe state) and waits until it has
  /// ended. @returns the run's summary (what `run --json` prints), or null when
  /// no run was ever started.
  nlohmann::json Stop();

  /// The log of the last run, when one has started.
  std::string LogPath() const;
  bool HasLog() const;

  /// What a stream reader has not seen yet: the samples of run `run_id` from
  /// index `from` on, whether the run has ended, and its summary then.
  struct Update {
    std::uint64_t run_id = 0;  ///< 0: no run started yet
    std::vector<LogRecord> samples;
    bool ended = false;
    nlohmann::json summary;
  };
  Update Since(std::uint64_t run_id, std::size_t from) const;

 private:
  void Drain(SpscRingBuffer<LogRecord>& ring, std::vector<LogRecord>& scratch);
  void Join();

  std::string log_path_;
  mutable std::mutex mutex_;
  std::condition_variable ended_;
  std::string state_ = "idle";
  std::string error_;
  nlohmann::json summary_;
  std::vector<LogRecord> history_;
  std::uint64_t run_id_ = 0;
  std::chrono::steady_clock::time_point start_, end_;
  std::unique_ptr<SpscRingBuffer<LogRecord>> ring_;
  std::thread worker_;
};

}  // namespace pneumid::app
