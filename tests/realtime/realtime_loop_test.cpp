// Tests of the fixed-period loop: sample count, closed-loop result against an
// offline simulation, no allocation on the loop thread, every fault ending in
// the safe state with a complete log, stop requests.
#include "pneumid/realtime/realtime_loop.hpp"

#include <cstdlib>
#include <fstream>
#include <new>
#include <sstream>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/realtime/sim_backend.hpp"
#include "test_support.hpp"

// Counting allocator: every operator new on a thread bumps that thread's counter.
namespace {
thread_local std::int64_t t_allocations = 0;
}
void* operator new(std::size_t n) {
  ++t_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  ++t_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace pneumid::testing {
std::int64_t ThreadAllocations() { return t_allocations; }
}  // namespace pneumid::testing

namespace pneumid {
namespace {

using testing::CountingPi;
using testing::FaultyBackend;
using testing::FirstOrderPlant;
using ::testing::HasSubstr;
using testing::Injected;

struct CsvLog {
  std::vector<std::string> header;             // '#' lines
  std::vector<std::vector<std::string>> rows;  // data rows split on ','
};

CsvLog ReadCsvLog(const std::string& path) {
  CsvLog log;
  std::ifstream in(path);
  std::string line;
  bool names = false;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] == '#') {
      log.header.push_back(line);
      continue;
    }
    if (!names) {
      names = true;
      continue;
    }
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.emplace_back();
    log.rows.push_back(cells);
  }
  return log;
}

std::string TempPath(const std::string& name) {
  return std::string(PNEUMID_BINARY_DIR) + "/realtime_test_" + name;
}

LoopOptions FastOptions(double duration, double period = 0.01) {
  LoopOptions o;
  o.period = period;
  o.duration = duration;
  o.fast = true;
  o.realtime = false;
  return o;
}

// Offline reference: the same plant and controller stepped in a plain loop.
std::vector<double> OfflineOutputs(int n, double r) {
  FirstOrderPlant plant(0.01, 0.95, 0.05);
  CountingPi pi(0.8, 4.0, 0.01);
  pi.Reset();
  plant.Reset();
  std::vector<double> y;
  for (int k = 0; k < n; ++k) {
    y.push_back(plant.Measure());
    plant.Advance(std::clamp(pi.Update(k, r, y.back()), 0.0, 100.0));
  }
  return y;
}

TEST(LoopOptions, Validation) {
  LoopOptions o;
  std::string error;
  EXPECT_TRUE(o.IsValid(&error));
  EXPECT_EQ(o.Samples(), 1000);  // 10 s at 10 ms
  o.period = 0.0;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("period"));
  o = LoopOptions{};
  o.priority = 0;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("priority"));
}

TEST(RealtimeLoop, FastSimMatchesOfflineSimulationAndLogsEveryRow) {
  const std::string path = TempPath("fast.csv");
  SimBackend io(std::make_unique<FirstOrderPlant>(0.01, 0.95, 0.05));
  CountingPi pi(0.8, 4.0, 0.01);
  SafetyMonitor safety(SafetyOptions{});
  LogWriter log(path, {{"controller", pi.Describe()}});
  const std::vector<double> r(200, 10.0);
  const LoopSummary s = RunLoop(FastOptions(2.0), io, pi, r, safety, &log);
  log.Close(s.timing.BriefReport(), s.message);
  EXPECT_EQ(s.termination, Termination::kSuccess) << s.message;
  EXPECT_EQ(s.ExitStatus(), 0);
  EXPECT_EQ(s.samples, 200);
  const CsvLog csv = ReadCsvLog(path);
  ASSERT_EQ(csv.rows.size(), 200u);
  const std::vector<double> ref = OfflineOutputs(200, 10.0);
  for (std::size_t k = 0; k < 200; ++k) {
    EXPECT_NEAR(std::stod(csv.rows[k][0]), 0.01 * static_cast<double>(k), 1e-9);
    EXPECT_NEAR(std::stod(csv.rows[k][2]), ref[k], 1e-6 * (1 + std::abs(ref[k]))) << k;
  }
  EXPECT_NEAR(std::stod(csv.rows.back()[2]), 10.0, 0.05);  // integral action: no offset
  // The statistics and the stop reason were filled into the reserved header lines.
  std::string timing, stop;
  for (const auto& h : csv.header) {
    if (h.rfind("# timing: ", 0) == 0) timing = h;
    if (h.rfind("# stop: ", 0) == 0) stop = h;
  }
  EXPECT_THAT(timing, HasSubstr("200 samples"));
  EXPECT_THAT(stop, HasSubstr("200 samples completed"));
}

TEST(RealtimeLoop, RealTimePacingRunsOnePeriodPerSample) {
  SimBackend io(std::make_unique<FirstOrderPlant>(0.002, 0.95, 0.05));
  CountingPi pi(0.8, 4.0, 0.002);
  SafetyMonitor safety(SafetyOptions{});
  LoopOptions o;
  o.period = 0.002;
  o.duration = 0.2;  // 100 samples
  o.realtime = false;
  SafetyOptions so;
  so.max_overruns = -1;  // a loaded CI machine must not fail this test
  SafetyMonitor lenient(so);
  const LoopSummary s = RunLoop(o, io, pi, {5.0}, lenient);
  EXPECT_EQ(s.termination, Termination::kSuccess);
  EXPECT_EQ(s.samples, 100);
  EXPECT_EQ(s.timing.samples, 100);
  // Absolute sleeps: the last wake-up is at t_0 + 99 Ts or later, the first at t_0 plus its
  // lateness (at most the maximum jitter), so wall time + max jitter >= 99 Ts.
  EXPECT_GE(s.wall_time + s.timing.jitter_max_us * 1e-6, 0.198 - 1e-5);
  EXPECT_GE(s.timing.jitter_max_us, s.timing.jitter_p99_us);
  EXPECT_GE(s.timing.jitter_p99_us, s.timing.jitter_p50_us);
  EXPECT_GT(s.timing.compute_max_us, 0.0);
}

TEST(RealtimeLoop, NoAllocationOnTheLoopThread) {
  const std::string path = TempPath("noalloc.csv");
  SimBackend io(std::make_unique<FirstOrderPlant>(0.001, 0.95, 0.05));
  CountingPi pi(0.8, 4.0, 0.001);
  SafetyOptions so;
  so.max_overruns = -1;
  so.rate_max = 1000.0;
  SafetyMonitor safety(so);
  LogWriter log(path, {});
  LoopStatus status;
  LoopOptions o;
  o.period = 0.001;
  o.duration = 0.3;
  o.realtime = true;  // exercises the scheduling set-up (granted or not)
  const LoopSummary s = RunLoop(o, io, pi, {1.0, 2.0, 3.0}, safety, &log, &status);
  log.Close();
  EXPECT_EQ(s.samples, 300);
  EXPECT_EQ(pi.calls(), 300);
  EXPECT_EQ(pi.allocations_during_run(), 0);
  EXPECT_FALSE(s.scheduling.empty());
  EXPECT_EQ(status.k.load(), 299);
  EXPECT_EQ(ReadCsvLog(path).rows.size(), 300u);
}

struct FaultCase {
  Injected injected;
  Fault expected;
  SafeState safe;
};

class FaultInjection : public ::testing::TestWithParam<FaultCase> {};

TEST_P(FaultInjection, EndsInSafeStateWithCompleteLog) {
  const FaultCase c = GetParam();
  // One file per case: two cases expect the same fault and ctest runs them side by side.
  std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  name = name.substr(name.rfind('/') + 1);  // "EndsInSafeStateWithCompleteLog/io_error_write"
  const std::string path = TempPath("fault_" + name + ".csv");
  FaultyBackend io(0.01, c.injected, 40);
  CountingPi pi(0.8, 4.0, 0.01);
  SafetyOptions so;
  so.y_min = -100.0;
  so.y_max = 100.0;
  so.frozen_samples = 20;
  so.safe_state = c.safe;
  SafetyMonitor safety(so);
  LogWriter log(path, {{"controller", pi.Describe()}});
  const LoopSummary s = RunLoop(FastOptions(5.0), io, pi, {10.0}, safety, &log);
  log.Close(s.timing.BriefReport(), s.message);

  EXPECT_EQ(s.termination, Termination::kFailure);
  EXPECT_EQ(s.fault, c.expected);
  EXPECT_EQ(s.ExitStatus(), 3);
  EXPECT_EQ(io.safe_calls_, 1);
  EXPECT_EQ(io.safe_, c.safe);
  EXPECT_TRUE(io.closed_);
  EXPECT_THAT(s.message, HasSubstr(ToString(c.expected)));
  EXPECT_THAT(s.message, HasSubstr(ToString(c.safe)));
  // Frozen needs 20 equal samples (from 40 to 59); the others fault at once.
  const std::int64_t fault_k = c.expected == Fault::kSensorFrozen ? 40 + 19 : 40;
  EXPECT_EQ(s.samples, fault_k + 1);
  const CsvLog csv = ReadCsvLog(path);
  ASSERT_EQ(csv.rows.size(), static_cast<std::size_t>(fault_k + 1));  // nothing lost
  EXPECT_EQ(csv.rows.back().back(), ToString(c.expected));            // the reason is logged
  EXPECT_EQ(std::stoi(csv.rows.back()[8]) & kLogSafeState, kLogSafeState);
  for (std::size_t k = 0; k + 1 < csv.rows.size(); ++k) EXPECT_EQ(csv.rows[k].back(), "") << k;
  bool stop_line = false;
  for (const auto& h : csv.header)
    if (h.rfind("# stop: failure", 0) == 0 || h.find(ToString(c.expected)) != std::string::npos)
      stop_line = true;
  EXPECT_TRUE(stop_line);
}

INSTANTIATE_TEST_SUITE_P(
    AllFaults, FaultInjection,
    ::testing::Values(
        FaultCase{Injected::kNaN, Fault::kSensorNaN, SafeState::kHold},
        FaultCase{Injected::kOutOfRange, Fault::kSensorOutOfRange, SafeState::kRelease},
        FaultCase{Injected::kRail, Fault::kSensorOutOfRange, SafeState::kHold},
        FaultCase{Injected::kFrozen, Fault::kSensorFrozen, SafeState::kHold},
        FaultCase{Injected::kReadError, Fault::kIoError, SafeState::kRelease},
        FaultCase{Injected::kWriteError, Fault::kIoError, SafeState::kHold}),
    [](const auto& info) {
      std::string n = ToString(info.param.expected);
      n += info.param.injected == Injected::kRail         ? "_rail"
           : info.param.injected == Injected::kWriteError ? "_write"
                                                          : "";
      for (char& ch : n)
        if (ch == '-') ch = '_';
      return n;
    });

// A controller that takes longer than the period.
class SlowController : public LoopController {
 public:
  double Update(std::int64_t, double, double) noexcept override {
    std::this_thread::sleep_for(std::chrono::milliseconds(3));
    return 10.0;
  }
  std::string Describe() const override { return "slow"; }
};

TEST(RealtimeLoop, DeadlineOverrunsBeyondTheLimitFault) {
  const std::string path = TempPath("overrun.csv");
  FaultyBackend io(0.001, Injected::kNone, 0);
  SlowController slow;
  SafetyOptions so;
  so.max_overruns = 5;
  SafetyMonitor safety(so);
  LogWriter log(path, {});
  LoopOptions o;
  o.period = 0.001;
  o.duration = 1.0;
  o.realtime = false;
  const LoopSummary s = RunLoop(o, io, slow, {}, safety, &log);
  log.Close(s.timing.BriefReport(), s.message);
  EXPECT_EQ(s.termination, Termination::kFailure);
  EXPECT_EQ(s.fault, Fault::kDeadlineOverruns);
  EXPECT_EQ(s.timing.overruns, 6);  // every 3 ms step overruns a 1 ms period
  EXPECT_EQ(s.samples, 6);
  EXPECT_EQ(io.safe_calls_, 1);
  const CsvLog csv = ReadCsvLog(path);
  ASSERT_EQ(csv.rows.size(), 6u);
  EXPECT_EQ(csv.rows.back().back(), "deadline-overruns");
}

TEST(RealtimeLoop, ControllerReturningNaNFaults) {
  class NanController : public LoopController {
   public:
    double Update(std::int64_t k, double, double) noexcept override {
      return k < 10 ? 1.0 : std::numeric_limits<double>::quiet_NaN();
    }
    std::string Describe() const override { return "nan"; }
  } ctrl;
  FaultyBackend io(0.01, Injected::kNone, 0);
  SafetyMonitor safety(SafetyOptions{});
  const LoopSummary s = RunLoop(FastOptions(1.0), io, ctrl, {}, safety);
  EXPECT_EQ(s.fault, Fault::kControllerError);
  EXPECT_EQ(s.samples, 11);
  EXPECT_EQ(io.safe_calls_, 1);
}

TEST(RealtimeLoop, StopRequestEndsWithSafeStateAndSignalStatus) {
  ClearStopRequest();
  FaultyBackend io(0.001, Injected::kNone, 0);
  CountingPi pi(0.8, 4.0, 0.001);
  SafetyOptions so;
  so.max_overruns = -1;
  SafetyMonitor safety(so);
  LoopStatus status;
  LoopOptions o;
  o.period = 0.001;
  o.duration = 30.0;
  o.realtime = false;
  std::thread stopper([&] {
    while (status.k.load() < 50) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    RequestStop(SIGTERM);
  });
  const LoopSummary s = RunLoop(o, io, pi, {1.0}, safety, nullptr, &status);
  stopper.join();
  ClearStopRequest();
  EXPECT_EQ(s.termination, Termination::kStopped);
  EXPECT_EQ(s.signal, SIGTERM);
  EXPECT_EQ(s.ExitStatus(), 128 + SIGTERM);
  EXPECT_GE(s.samples, 50);
  EXPECT_LT(s.samples, 30000);
  EXPECT_EQ(io.safe_calls_, 1);
}

TEST(RealtimeLoop, RejectsBadArguments) {
  FaultyBackend io(0.01, Injected::kNone, 0);
  CountingPi pi(0.8, 4.0, 0.01);
  SafetyMonitor safety(SafetyOptions{});
  LoopOptions o = FastOptions(1.0);
  o.period = -1;
  EXPECT_THROW(RunLoop(o, io, pi, {}, safety), InvalidArgument);
  EXPECT_THROW(RunLoop(FastOptions(1.0), io, pi, {std::nan("")}, safety), InvalidArgument);
  SimBackend sim(std::make_unique<FirstOrderPlant>(0.01, 0.9, 0.1));
  LoopOptions wrong_period = FastOptions(1.0, 0.02);
  EXPECT_THROW(RunLoop(wrong_period, sim, pi, {}, safety), InvalidArgument);
}

TEST(OpenLoopInput, HoldsTheLastValue) {
  OpenLoopInput in({1.0, 2.0, 3.0}, "test");
  EXPECT_EQ(in.Update(0, 0, 0), 1.0);
  EXPECT_EQ(in.Update(2, 0, 0), 3.0);
  EXPECT_EQ(in.Update(10, 0, 0), 3.0);
  EXPECT_THROW(OpenLoopInput({}, "empty"), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
