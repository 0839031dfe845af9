// Speed of the IPA calibration (include/pneumid/identify/nonlinear/ipa_calibration.hpp):
// six free parameters (the force-mode valve and cylinder defaults, without the
// sensor filter the default twin adds to them) from one 3 s step test at
// Ts = 0.01 s, started from the default twin, the data made by a twin with
// every free parameter perturbed by 4-40 %. The target: <= 10 s wall
// on 2 cores.
//   build/bench/calibration_benchmark
#include <benchmark/benchmark.h>

#include "pneumid/identify/nonlinear/ipa_calibration.hpp"
#include "pneumid/plant/experiment.hpp"
#include "pneumid/plant/signal.hpp"

namespace {

void CalibrateStep(benchmark::State& state, pneumid::PwmMode pwm) {
  pneumid::IpaParameters start;
  start.pwm_mode = pwm;
  pneumid::IpaParameters truth = start;
  truth.inlet_conductance *= 1.10;
  truth.exhaust_conductance *= 0.92;
  truth.bore *= 1.04;
  truth.inlet_critical_ratio *= 0.9;
  truth.exhaust_critical_ratio *= 1.15;
  truth.open_delay *= 1.4;
  pneumid::IpaSimulator sim(truth, 0.01, 7);
  const auto data =
      pneumid::RunExperiment(sim, *pneumid::ParseSignal("step:from=0.61,to=82,at=0.5"), 3.0).data;
  pneumid::IpaCalibrationOptions options;
  options.start = start;
  options.free = pneumid::DefaultCalibrationParameters(start.mode);
  options.num_threads = static_cast<int>(state.range(0));
  double fit = 0.0, iterations = 0.0, simulations = 0.0;
  for (auto _ : state) {
    const auto s = pneumid::CalibrateIpa({{data, "step"}}, options);
    fit = s.experiments[0].fit_percent;
    iterations = s.iterations;
    simulations = static_cast<double>(s.simulations);
  }
  state.counters["fit_percent"] = fit;
  state.counters["iterations"] = iterations;
  state.counters["simulations"] = simulations;
}

BENCHMARK_CAPTURE(CalibrateStep, switching, pneumid::PwmMode::kSwitching)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(CalibrateStep, averaged, pneumid::PwmMode::kAveraged)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
