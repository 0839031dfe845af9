// Speed of the step-response methods and of the Ceres process-model fits on
// the recorded synthetic step tests (tests/identify/data, 600-1000 samples)
// and on the ten-step SOPDT record (15000 samples).
//   build/bench/process_fit_benchmark
#include <string>

#include <benchmark/benchmark.h>

#include "pneumid/data/load.hpp"
#include "pneumid/identify/parametric/process_model.hpp"
#include "pneumid/identify/step/reaction_curve.hpp"
#include "pneumid/identify/step/step_methods.hpp"

namespace {

// The repository root, given by the build (PNEUMID_SOURCE_DIR), so that the
// benchmark runs from any working directory.
std::string SourceDir() { return PNEUMID_SOURCE_DIR; }

pneumid::Dataset Load(const std::string& name) {
  return pneumid::LoadDataset(SourceDir() + "/tests/identify/data/" + name + ".csv");
}

void BM_ReactionCurve(benchmark::State& state) {
  const pneumid::Dataset d = Load("sopdt");
  for (auto _ : state) {
    benchmark::DoNotOptimize(pneumid::ReactionCurve(pneumid::AnalyzeStep(d)));
  }
}
BENCHMARK(BM_ReactionCurve)->Unit(benchmark::kMicrosecond);

void Fit(benchmark::State& state, const std::string& data, pneumid::ProcessStructure s) {
  const pneumid::Dataset d = Load(data);
  pneumid::ProcessFitOptions o;
  o.structure = s;
  for (auto _ : state) benchmark::DoNotOptimize(pneumid::FitProcessModel(d, 0, 0, o));
  state.SetItemsProcessed(state.iterations() * d.size());
}

void BM_FitP1dFopdt(benchmark::State& state) {
  Fit(state, "fopdt", pneumid::ProcessStructure::kP1D);
}
void BM_FitP2dSopdt(benchmark::State& state) {
  Fit(state, "sopdt", pneumid::ProcessStructure::kP2D);
}
void BM_FitP3dHighOrder(benchmark::State& state) {
  Fit(state, "high_order", pneumid::ProcessStructure::kP3D);
}
void BM_FitP2dTenSteps(benchmark::State& state) {
  Fit(state, "sopdt_steps", pneumid::ProcessStructure::kP2D);
}
BENCHMARK(BM_FitP1dFopdt)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitP2dSopdt)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitP3dHighOrder)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitP2dTenSteps)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
