#include "pneumid/realtime/realtime_loop.hpp"

#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <thread>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"

namespace pneumid {

namespace {

std::atomic<int> g_stop_signal{-1};

void StopHandler(int sig) { g_stop_signal.store(sig, std::memory_order_relaxed); }

constexpr std::int64_t kNsPerS = 1000000000;

std::int64_t NowNs() noexcept {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kNsPerS + ts.tv_nsec;
}

void SleepUntilNs(std::int64_t t) noexcept {
  timespec ts;
  ts.tv_sec = static_cast<time_t>(t / kNsPerS);
  ts.tv_nsec = static_cast<long>(t % kNsPerS);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    if (g_stop_signal.load(std::memory_order_relaxed) >= 0) return;
  }
}

// Asks for real-time scheduling of the calling thread; returns a one-line notice.
std::string SetUpScheduling(const LoopOptions& o) {
  if (!o.realtime) return "normal priority (real-time scheduling not requested)";
  std::vector<std::string> got, missed;
  // Memory locking: only when it cannot make later allocations fail (no limit or
  // privileged), since MCL_FUTURE counts every future mapping against RLIMIT_MEMLOCK.
  rlimit lim{};
#if defined(__SANITIZE_ADDRESS__)
  // AddressSanitizer reserves terabytes of shadow memory: never lock it.
  const bool sanitizer = true;
#else
  const bool sanitizer = false;
#endif
  const bool may_lock =
      !sanitizer &&
      (geteuid() == 0 || (getrlimit(RLIMIT_MEMLOCK, &lim) == 0 && lim.rlim_cur == RLIM_INFINITY));
  if (sanitizer) {
    missed.push_back("mlockall (skipped under AddressSanitizer)");
  } else if (may_lock && mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
    got.push_back("mlockall");
  } else {
    missed.push_back(may_lock ? fmt::format("mlockall ({})", std::strerror(errno))
                              : "mlockall (RLIMIT_MEMLOCK is limited)");
  }
  sched_param sp{};
  sp.sched_priority = o.priority;
  const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
  if (rc == 0) {
    got.push_back(fmt::format("SCHED_FIFO {}", o.priority));
  } else {
    missed.push_back(fmt::format("SCHED_FIFO ({})", std::strerror(rc)));
  }
  if (o.cpu != -2) {
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    int cpu = o.cpu;
    if (cpu == -1 && sched_getaffinity(0, sizeof(allowed), &allowed) == 0) {
      for (int c = CPU_SETSIZE - 1; c >= 0; --c)
        if (CPU_ISSET(c, &allowed)) {
          cpu = c;
          break;
        }
    }
    cpu_set_t set;
    CPU_ZERO(&set);
    int prc = EINVAL;
    if (cpu >= 0 && cpu < CPU_SETSIZE) {
      CPU_SET(cpu, &set);
      prc = pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
    }
    if (prc == 0)
      got.push_back(fmt::format("pinned to CPU {}", cpu));
    else
      missed.push_back(fmt::format("CPU pinning ({})", std::strerror(prc)));
  }
  // Pre-fault some stack so the first periods do not page-fault.
  volatile unsigned char stack[64 * 1024];
  for (std::size_t i = 0; i < sizeof(stack); i += 4096) stack[i] = 0;
  if (missed.empty()) return "real-time: " + fmt::format("{}", fmt::join(got, ", "));
  return fmt::format(
      "{}; not permitted: {} (running at normal priority where refused)",
      got.empty() ? "normal priority" : "real-time: " + fmt::format("{}", fmt::join(got, ", ")),
      fmt::join(missed, ", "));
}

}  // namespace

OpenLoopInput::OpenLoopInput(std::vector<double> input, std::string description)
    : input_(std::move(input)), description_(std::move(description)) {
  PNEUMID_CHECK(!input_.empty(), "open-loop input must not be empty");
  for (std::size_t i = 0; i < input_.size(); ++i)
    PNEUMID_CHECK(std::isfinite(input_[i]), "open-loop input sample {} is not finite ({})", i,
                  input_[i]);
}

double OpenLoopInput::Update(std::int64_t k, double, double) noexcept {
  const auto i = static_cast<std::size_t>(std::max<std::int64_t>(0, k));
  return input_[std::min(i, input_.size() - 1)];
}

bool LoopOptions::IsValid(std::string* error) const {
  auto fail = [error](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (!(period >= 1e-4 && period <= 10.0))
    return fail(fmt::format("period must be in [1e-4, 10] s, got {}", period));
  if (!(duration > 0.0 && std::isfinite(duration)))
    return fail(fmt::format("duration must be positive, got {} s", duration));
  if (duration / period > 1e9)
    return fail(
        fmt::format("duration {} s at period {} s is more than 1e9 samples", duration, period));
  if (priority < 1 || priority > 99)
    return fail(fmt::format("priority must be in 1..99, got {}", priority));
  if (cpu < -2) return fail(fmt::format("cpu must be >= 0, -1 (last) or -2 (none), got {}", cpu));
  return true;
}

std::int64_t LoopOptions::Samples() const {
  return std::max<std::int64_t>(1, std::llround(duration / period));
}

int LoopSummary::ExitStatus() const {
  switch (termination) {
    case Termination::kSuccess:
      return 0;
    case Termination::kStopped:
      return signal > 0 ? 128 + signal : 130;
    case Termination::kFailure:
      return 3;
    default:
      return 1;
  }
}

std::string LoopSummary::BriefReport() const {
  return fmt::format("{}: {}; {}", ToString(termination), message, timing.BriefReport());
}

nlohmann::json LoopSummary::ToJson() const {
  nlohmann::json j = timing.ToJson();
  j["termination"] = ToString(termination);
  j["fault"] = ToString(fault);
  j["message"] = message;
  j["samples"] = samples;
  j["scheduling"] = scheduling;
  j["safe_state"] = safe_state_name;
  j["log_dropped"] = log_dropped;
  j["wall_time"] = wall_time;
  return j;
}

void InstallStopSignalHandlers() {
  struct sigaction sa {};
  sa.sa_handler = StopHandler;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: interrupt blocking calls so loops notice quickly
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

void RequestStop(int signal) { g_stop_signal.store(signal, std::memory_order_relaxed); }
void ClearStopRequest() { g_stop_signal.store(-1, std::memory_order_relaxed); }
int StopRequestSignal() { return g_stop_signal.load(std::memory_order_relaxed); }

LoopSummary RunLoop(const LoopOptions& options, IoBackend& io, LoopController& controller,
                    const std::vector<double>& setpoint, SafetyMonitor& safety, LogWriter* log,
                    LoopStatus* status) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid loop options: {}", error);
  PNEUMID_CHECK(!options.fast || io.CanRunFast(),
                "--fast needs a simulated backend; {} runs in real time", io.Describe());
  for (std::size_t i = 0; i < setpoint.size(); ++i)
    PNEUMID_CHECK(std::isfinite(setpoint[i]), "set point sample {} is not finite ({})", i,
                  setpoint[i]);

  const std::int64_t n = options.Samples();
  const std::int64_t period_ns = std::llround(options.period * 1e9);
  TimingStats stats(options.period);
  io.Open(options.period);
  controller.Reset();
  safety.Reset(0.0);

  LoopSummary summary;
  summary.safe_state = safety.options().safe_state;
  summary.safe_state_name = SafeStateName(io.actuator(), summary.safe_state);
  // Details of the fault, filled on the loop thread without allocation.
  Fault fault = Fault::kNone;
  std::int64_t fault_k = -1;
  double fault_y = 0.0, fault_u = 0.0;
  IoStatus fault_io = IoStatus::kOk;
  int stop_signal = -1;
  std::int64_t done = 0;
  std::int64_t t_first = 0, t_last = 0;
  bool started = false;  // controller.Start() called (at the first valid measurement)

  auto body = [&] {
    summary.scheduling = options.fast ? std::string("as fast as possible (simulation time)")
                                      : SetUpScheduling(options);
    if (status) status->running.store(true);
    const std::int64_t t0 = NowNs() + 2 * period_ns;  // leave time for the first wake-up
    for (std::int64_t k = 0; k < n; ++k) {
      const std::int64_t deadline = t0 + k * period_ns;
      if (!options.fast) SleepUntilNs(deadline);
      const std::int64_t wake = NowNs();
      if (k == 0) t_first = wake;
      const int sig = g_stop_signal.load(std::memory_order_relaxed);
      if (sig >= 0) {
        stop_signal = sig;
        break;
      }
      LogRecord rec;
      rec.k = k;
      rec.t = static_cast<double>(k) * options.period;
      rec.jitter_us = options.fast ? 0.0 : static_cast<double>(wake - deadline) * 1e-3;
      rec.r =
          setpoint.empty()
              ? 0.0
              : setpoint[std::min<std::size_t>(static_cast<std::size_t>(k), setpoint.size() - 1)];
      Measurement m;
      const IoStatus rs = io.Read(&m);
      rec.y = m.y;
      rec.aux = m.aux;
      if (rs == IoStatus::kStale) rec.flags |= kLogStale;
      Fault f = safety.CheckMeasurement(rs, m.y);
      IoStatus fio = rs;
      if (f == Fault::kNone) {
        if (!started) {
          controller.Start(m.y);
          started = true;
        }
        rec.u_ctrl = controller.Update(k, rec.r, m.y);
        unsigned lim = 0;
        rec.u = safety.LimitOutput(rec.u_ctrl, options.period, &lim);
        rec.flags |= lim;
        if (std::isfinite(rec.u) && rec.u != rec.u_ctrl) controller.Applied(rec.u);
        if (!std::isfinite(rec.u)) {
          f = Fault::kControllerError;
        } else {
          const IoStatus ws = io.Write(rec.u);
          if (ws == IoStatus::kError) f = Fault::kIoError;
          if (ws == IoStatus::kTimeout) f = Fault::kTimeout;
          if (f != Fault::kNone) fio = ws;
        }
      } else {
        rec.u = rec.u_ctrl = std::numeric_limits<double>::quiet_NaN();
      }
      const std::int64_t end = NowNs();
      t_last = end;
      const bool overrun = !options.fast && end > deadline + period_ns;
      rec.compute_us = static_cast<double>(end - wake) * 1e-3;
      stats.Add(options.fast ? 0 : wake - deadline, end - wake, overrun);
      if (overrun) {
        rec.flags |= kLogOverrun;
        const Fault of = safety.OnOverrun();
        if (f == Fault::kNone) f = of;
      }
      if (f != Fault::kNone) {
        rec.fault = f;
        rec.flags |= kLogSafeState;
        summary.safe_state_status = io.EnterSafeState(safety.options().safe_state);
        fault = f;
        fault_k = k;
        fault_y = m.y;
        fault_u = rec.u_ctrl;
        fault_io = fio;
      }
      if (log) log->Push(rec);
      ++done;
      if (status) {
        status->k.store(k, std::memory_order_relaxed);
        status->r.store(rec.r, std::memory_order_relaxed);
        status->y.store(rec.y, std::memory_order_relaxed);
        status->u.store(rec.u, std::memory_order_relaxed);
        status->jitter_us.store(rec.jitter_us, std::memory_order_relaxed);
        status->overruns.store(stats.overruns(), std::memory_order_relaxed);
      }
      if (fault != Fault::kNone) break;
    }
    if (fault == Fault::kNone)
      summary.safe_state_status = io.EnterSafeState(safety.options().safe_state);
    if (status) status->running.store(false);
  };

  std::thread loop_thread(body);
  loop_thread.join();
  io.Close();

  summary.samples = done;
  summary.timing = stats.Report();
  summary.wall_time = static_cast<double>(t_last - t_first) * 1e-9;
  summary.log_dropped = log ? log->dropped() : 0;
  summary.fault = fault;
  if (fault != Fault::kNone) {
    summary.termination = Termination::kFailure;
    summary.message = fmt::format(
        "{} at t = {:.4f} s (sample {}): y = {}, u = {}, I/O status {}; outputs set to {}{}",
        ToString(fault), static_cast<double>(fault_k) * options.period, fault_k, fault_y, fault_u,
        ToString(fault_io), summary.safe_state_name,
        summary.safe_state_status == IoStatus::kOk ? "" : " (safe-state write failed)");
    if (fault == Fault::kDeadlineOverruns)
      summary.message += fmt::format(" ({} overruns > max {})", summary.timing.overruns,
                                     safety.options().max_overruns);
  } else if (stop_signal >= 0) {
    summary.termination = Termination::kStopped;
    summary.signal = stop_signal;
    summary.message = fmt::format(
        "stopped by {} after {} samples; outputs set to {}",
        stop_signal > 0 ? fmt::format("signal {} ({})", stop_signal, strsignal(stop_signal))
                        : std::string("request"),
        done, summary.safe_state_name);
  } else {
    summary.termination = Termination::kSuccess;
    summary.message =
        fmt::format("{} samples completed; outputs set to {}", done, summary.safe_state_name);
  }
  return summary;
}

}  // namespace pneumid
