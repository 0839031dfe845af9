// Speed of `pneumid identify -m all` on a long record: every method of
// IdentifyMethodNames() through Identify() on 2e5 samples of the simulated IPA
// (step 0.61 -> 82 % at 100 s, 2000 s at Ts = 0.01 s, as made by
// `pneumid simulate --input step:from=0.61,to=82,at=100 --duration 2000`).
// One benchmark per method and one for the whole list; the data are made once.
// Environment: PNEUMID_BENCH_DATA=FILE reads that record instead,
// PNEUMID_BENCH_DURATION=S simulates S seconds (10000 for 1e6 samples),
// PNEUMID_BENCH_NOTES=1 prints each model's fit and notes.
//   build/bench/identify_all_benchmark [--benchmark_filter=all]
#include <cstdio>
#include <cstdlib>
#include <string>

#include <benchmark/benchmark.h>

#include "pneumid/data/load.hpp"
#include "pneumid/identify/identify.hpp"
#include "pneumid/plant/experiment.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/plant/signal.hpp"

namespace {

const pneumid::Dataset& LongRecord() {
  static const pneumid::Dataset data = [] {
    // PNEUMID_BENCH_DATA=FILE: that record instead (e.g. a CSV written by simulate).
    if (const char* file = std::getenv("PNEUMID_BENCH_DATA")) return pneumid::LoadDataset(file);
    auto plant = pneumid::MakePlant("ipa", 0.01);
    const auto input = pneumid::ParseSignal("step:from=0.61,to=82,at=100");
    pneumid::ExperimentOptions o;
    o.input_channel = pneumid::PlantInputChannel(*plant);
    o.output_channel = pneumid::PlantOutputChannel(*plant);
    // PNEUMID_BENCH_DURATION=S: S seconds (S / 0.01 samples), e.g. 10000 for 1e6.
    const char* duration = std::getenv("PNEUMID_BENCH_DURATION");
    return pneumid::RunExperiment(*plant, *input, duration ? std::atof(duration) : 2000.0, o).data;
  }();
  return data;
}

void BM_IdentifyMethod(benchmark::State& state, const std::string& method) {
  const pneumid::Dataset& d = LongRecord();
  double fit = 0.0;
  for (auto _ : state) {
    const pneumid::IdentifiedModel m = pneumid::Identify(method, d);
    fit = m.fit_percent;
    if (std::getenv("PNEUMID_BENCH_NOTES")) {
      std::fprintf(stderr, "%s: fit %.3f %%\n", method.c_str(), fit);
      for (const auto& n : m.notes) std::fprintf(stderr, "  %s\n", n.c_str());
    }
    benchmark::DoNotOptimize(fit);
  }
  state.counters["fit_percent"] = fit;
  state.SetItemsProcessed(state.iterations() * d.size());
}

void BM_IdentifyAll(benchmark::State& state) {
  const pneumid::Dataset& d = LongRecord();
  int failed = 0;
  for (auto _ : state) {
    failed = 0;
    for (const std::string& method : pneumid::IdentifyMethodNames()) {
      try {
        benchmark::DoNotOptimize(pneumid::Identify(method, d));
      } catch (const std::exception&) {
        ++failed;
      }
    }
  }
  state.counters["failed"] = failed;
  state.SetItemsProcessed(state.iterations() * d.size());
}

const bool kRegistered = [] {
  for (const std::string& method : pneumid::IdentifyMethodNames()) {
    benchmark::RegisterBenchmark(("BM_Identify/" + method).c_str(), BM_IdentifyMethod, method)
        ->Unit(benchmark::kMillisecond);
  }
  benchmark::RegisterBenchmark("BM_IdentifyAll", BM_IdentifyAll)
      ->Unit(benchmark::kMillisecond)
      ->Iterations(1);
  return true;
}();

}  // namespace

BENCHMARK_MAIN();
