// Costs of the pieces on the real-time loop's path: log ring buffer, timing
// histogram, safety checks, UDP packet coding, and one whole loop step (fast
// mode, first-order plant, PI) including the log push.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <string>
#include <thread>

#include "pneumid/plant/plant.hpp"
#include "pneumid/realtime/log_writer.hpp"
#include "pneumid/realtime/realtime_loop.hpp"
#include "pneumid/realtime/safety.hpp"
#include "pneumid/realtime/sim_backend.hpp"
#include "pneumid/realtime/spsc_ring_buffer.hpp"
#include "pneumid/realtime/timing_stats.hpp"
#include "pneumid/realtime/udp_protocol.hpp"

namespace pneumid {
namespace {

void BM_RingBufferPushPop(benchmark::State& state) {
  SpscRingBuffer<LogRecord> rb(1024);
  LogRecord r, out;
  for (auto _ : state) {
    rb.TryPush(r);
    rb.TryPop(&out);
    benchmark::DoNotOptimize(out);
  }
}
BENCHMARK(BM_RingBufferPushPop);

void BM_TimingStatsAdd(benchmark::State& state) {
  TimingStats s(0.01);
  std::int64_t j = 0;
  for (auto _ : state) {
    s.Add(j, 2 * j, false);
    j = (j + 7919) % 200000;
  }
}
BENCHMARK(BM_TimingStatsAdd);

void BM_SafetyCheckAndLimit(benchmark::State& state) {
  SafetyOptions o;
  o.rate_max = 500;
  o.frozen_samples = 50;
  SafetyMonitor s(o);
  double y = 0.0;
  for (auto _ : state) {
    y += 0.01;
    benchmark::DoNotOptimize(s.CheckMeasurement(IoStatus::kOk, y));
    unsigned flags;
    benchmark::DoNotOptimize(s.LimitOutput(std::sin(y) * 120, 0.01, &flags));
  }
}
BENCHMARK(BM_SafetyCheckAndLimit);

void BM_UdpEncodeDecode(benchmark::State& state) {
  udp::Request req;
  req.u = 42.0;
  udp::Request back;
  for (auto _ : state) {
    ++req.sequence;
    const udp::Packet p = udp::Encode(req);
    benchmark::DoNotOptimize(udp::DecodeRequest(p.data(), p.size(), &back));
  }
}
BENCHMARK(BM_UdpEncodeDecode);

class Lag : public Plant {
 public:
  void Reset() override { y_ = 0; }
  double Measure() override { return y_; }
  void Advance(double u) override { y_ = 0.95 * y_ + 0.05 * u; }
  double Ts() const override { return 0.001; }
  double time() const override { return 0; }
  std::string Describe() const override { return "lag"; }

 private:
  double y_ = 0;
};

class Pi : public LoopController {
 public:
  double Update(std::int64_t, double r, double y) noexcept override {
    const double e = r - y;
    u_ += 0.5 * (e - e_) + 0.005 * e;
    e_ = e;
    return u_;
  }
  std::string Describe() const override { return "pi"; }

 private:
  double u_ = 0, e_ = 0;
};

// Whole loop per sample in fast mode (no sleeping): read, control, safety, write,
// timing, log push; the writer thread formats CSV to /dev/null meanwhile.
void BM_LoopStepFast(benchmark::State& state) {
  for (auto _ : state) {
    SimBackend io(std::make_unique<Lag>());
    Pi pi;
    SafetyMonitor safety(SafetyOptions{});
    LogWriterOptions lo;
    lo.capacity = 1 << 17;
    LogWriter log("/dev/null", {}, lo);
    LoopOptions o;
    o.period = 0.001;
    o.duration = 100.0;  // 100000 samples
    o.fast = true;
    const LoopSummary s = RunLoop(o, io, pi, {50.0}, safety, &log);
    log.Close();
    benchmark::DoNotOptimize(s.samples);
  }
  state.SetItemsProcessed(state.iterations() * 100000);
}
BENCHMARK(BM_LoopStepFast)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace pneumid

BENCHMARK_MAIN();
