#include "live_run.hpp"

#include <filesystem>

#include "pneumid/realtime/realtime_loop.hpp"
#include "pneumid/workflow/run_workflow.hpp"

namespace pneumid::app {

LiveRun::LiveRun(std::string log_path) : log_path_(std::move(log_path)) {}

LiveRun::~LiveRun() {
  Stop();
  Join();
}

void LiveRun::Join() {
  if (worker_.joinable()) worker_.join();
}

bool LiveRun::Running() const {
  std::lock_guard lock(mutex_);
  return state_ == "running";
}

bool LiveRun::Start(const cli::RunArgs& args, RealtimeConfig config) {
  RunWorkflowOptions options = cli::ToWorkflowOptions(args);
  options.log = log_path_;
  options.live_status = false;
  {
    std::lock_guard lock(mutex_);
    if (state_ == "running") return false;
  }
  Join();  // the previous run's thread has ended (its state is set last)
  std::lock_guard lock(mutex_);
  state_ = "running";
  error_.clear();
  summary_ = nullptr;
  history_.clear();
  ++run_id_;
  start_ = end_ = std::chrono::steady_clock::now();
  // Room for 10 s at 1 kHz between two drains (25 ms apart).
  ring_ = std::make_unique<SpscRingBuffer<LogRecord>>(1 << 14);
  worker_ = std::thread([this, options = std::move(options), config = std::move(config)] {
    std::atomic<bool> loop_done{false};
    std::thread pump([&] {
      std::vector<LogRecord> scratch;
      scratch.reserve(ring_->capacity());
      while (!loop_done.load()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(25));
        Drain(*ring_, scratch);
      }
      Drain(*ring_, scratch);
    });
    std::string state, error;
    nlohmann::json summary;
    try {
      const RunWorkflowResult out = RunRealtimeWorkflow(options, config, ring_.get());
      summary = out.ToJson();
      state = out.summary.termination == Termination::kSuccess   ? "finished"
              : out.summary.termination == Termination::kStopped ? "stopped"
                                                                 : "failed";
    } catch (const std::exception& e) {
      state = "failed";
      error = e.what();
      summary = {{"termination", "failure"}, {"message", e.what()}};
    }
    loop_done = true;
    pump.join();
    std::lock_guard done_lock(mutex_);
    state_ = state;
    error_ = error;
    summary_ = summary;
    end_ = std::chrono::steady_clock::now();
    ended_.notify_all();
  });
  return true;
}

void LiveRun::Drain(SpscRingBuffer<LogRecord>& ring, std::vector<LogRecord>& scratch) {
  scratch.clear();
  LogRecord r;
  while (scratch.size() < scratch.capacity() && ring.TryPop(&r)) scratch.push_back(r);
  if (scratch.empty()) return;
  std::lock_guard lock(mutex_);
  history_.insert(history_.end(), scratch.begin(), scratch.end());
}

nlohmann::json LiveRun::Status() const {
  std::lock_guard lock(mutex_);
  nlohmann::json j;
  j["state"] = state_;
  const bool running = state_ == "running";
  j["samples"] = !running && summary_.contains("samples") ? summary_["samples"]
                                                          : nlohmann::json(history_.size());
  const auto end = running ? std::chrono::steady_clock::now() : end_;
  j["elapsed"] = std::chrono::duration<double>(end - start_).count();
  if (!running && state_ != "idle") j["summary"] = summary_;
  if (!error_.empty()) j["error"] = error_;
  return j;
}

nlohmann::json LiveRun::Stop() {
  std::unique_lock lock(mutex_);
  // Repeated: a request that came before the session cleared the previous one
  // (RunSession calls ClearStopRequest as it starts) would be lost.
  while (state_ == "running") {
    RequestStop(0);
    ended_.wait_for(lock, std::chrono::milliseconds(100));
  }
  return state_ == "idle" ? nlohmann::json(nullptr) : summary_;
}

std::string LiveRun::LogPath() const { return log_path_; }

bool LiveRun::HasLog() const {
  std::lock_guard lock(mutex_);
  return state_ != "idle" && std::filesystem::exists(log_path_);
}

LiveRun::Update LiveRun::Since(std::uint64_t run_id, std::size_t from) const {
  std::lock_guard lock(mutex_);
  Update u;
  u.run_id = run_id_;
  if (run_id != run_id_) from = 0;  // a new run: from its start
  if (from < history_.size())
    u.samples.assign(history_.begin() + static_cast<std::ptrdiff_t>(from), history_.end());
  u.ended = state_ != "running" && state_ != "idle";
  if (u.ended) u.summary = summary_;
  return u;
}

}  // namespace pneumid::app
