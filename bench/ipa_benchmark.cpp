// Speed of the plant simulators. Counter x_real_time = simulated seconds per
// second of CPU time (the issue asks for >= 1000 in force mode on one core).
//   build/bench/ipa_benchmark
#include <benchmark/benchmark.h>

#include "pneumid/plant/ipa_simulator.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/plant/signal.hpp"

namespace {

// Force mode: the paper's step test (0.61 -> 82 % at 1 s) followed by a PRBS,
// 10 s at Ts = 0.01 s. Position mode (the position rig): a signed PRBS of
// +-30 % that moves the piston back and forth within the stroke.
void RunIpa(benchmark::State& state, pneumid::IpaMode mode, pneumid::PwmMode pwm) {
  pneumid::IpaParameters p = pneumid::DefaultIpaParameters(mode);
  p.pwm_mode = pwm;
  pneumid::IpaSimulator sim(p, 0.01, 1);
  const bool force = mode == pneumid::IpaMode::kForce;
  auto step = pneumid::ParseSignal(force ? "step:from=0.61,to=82,at=1.0"
                                         : "prbs:low=-30,high=30,order=7,clock=0.03");
  auto prbs = pneumid::ParseSignal(force ? "prbs:low=20,high=90,order=7,clock=0.05"
                                         : "prbs:low=-30,high=30,order=7,clock=0.03");
  const int n = 1000;
  long long steps = 0;
  for (auto _ : state) {
    sim.Reset();
    double y = 0.0;
    for (int k = 0; k < n; ++k) {
      const double t = k * 0.01;
      y += sim.Measure();
      sim.Advance(t < 5.0 ? (*step)(t) : (*prbs)(t));
    }
    benchmark::DoNotOptimize(y);
    steps += sim.steps();
  }
  const double simulated = n * 0.01 * static_cast<double>(state.iterations());
  state.counters["x_real_time"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
  state.counters["ode_steps_per_simulated_s"] =
      benchmark::Counter(static_cast<double>(steps) / simulated);
}

void BM_IpaForceSwitching(benchmark::State& s) {
  RunIpa(s, pneumid::IpaMode::kForce, pneumid::PwmMode::kSwitching);
}
void BM_IpaForceAveraged(benchmark::State& s) {
  RunIpa(s, pneumid::IpaMode::kForce, pneumid::PwmMode::kAveraged);
}
void BM_IpaPositionSwitching(benchmark::State& s) {
  RunIpa(s, pneumid::IpaMode::kPosition, pneumid::PwmMode::kSwitching);
}
void BM_IpaPositionAveraged(benchmark::State& s) {
  RunIpa(s, pneumid::IpaMode::kPosition, pneumid::PwmMode::kAveraged);
}

void BM_LinearArxPaper(benchmark::State& state) {
  auto plant = pneumid::MakePlant("arx-paper", 0.01);
  const int n = 1000;
  for (auto _ : state) {
    plant->Reset();
    double y = 0.0;
    for (int k = 0; k < n; ++k) {
      y += plant->Measure();
      plant->Advance(k < 100 ? 0.61 : 82.0);
    }
    benchmark::DoNotOptimize(y);
  }
  state.counters["x_real_time"] = benchmark::Counter(
      n * 0.01 * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

BENCHMARK(BM_IpaForceSwitching)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IpaForceAveraged)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IpaPositionSwitching)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IpaPositionAveraged)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LinearArxPaper)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
