// Speed of the linear-model kernels that identification and tuning call in
// their inner loops: Lsim of a continuous model with delay (zoh discretization
// plus the simulation loop), c2d/d2c by zero-order hold, and stepinfo.
#include <benchmark/benchmark.h>

#include "pneumid/lti/conversion.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/lti/response.hpp"

namespace {

using pneumid::TransferFunction;

// Lsim of the paper's FOPDT (fractional delay: one extra state) on N samples.
void BM_LsimFopdt(benchmark::State& state) {
  const TransferFunction g = pneumid::PaperFopdtModel();
  const Eigen::VectorXd u = Eigen::VectorXd::Ones(state.range(0));
  for (auto _ : state) {
    Eigen::VectorXd y = pneumid::Lsim(g, u, 0.01);
    benchmark::DoNotOptimize(y.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_LsimFopdt)->Arg(500)->Arg(5000)->Arg(100000);

// Lsim of the third-order continuous ARX equivalent (Eq. 6).
void BM_LsimArxContinuous(benchmark::State& state) {
  const TransferFunction g = pneumid::D2C(pneumid::PaperArxModel());
  const Eigen::VectorXd u = Eigen::VectorXd::Ones(state.range(0));
  for (auto _ : state) {
    Eigen::VectorXd y = pneumid::Lsim(g, u, 0.01);
    benchmark::DoNotOptimize(y.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_LsimArxContinuous)->Arg(500)->Arg(100000);

void BM_C2dZohFopdt(benchmark::State& state) {
  const TransferFunction g = pneumid::PaperFopdtModel();
  for (auto _ : state) benchmark::DoNotOptimize(pneumid::C2D(g, 0.01));
}
BENCHMARK(BM_C2dZohFopdt);

void BM_D2cZohArx(benchmark::State& state) {
  const TransferFunction g = pneumid::PaperArxModel();
  for (auto _ : state) benchmark::DoNotOptimize(pneumid::D2C(g));
}
BENCHMARK(BM_D2cZohArx);

void BM_StepInfoArxContinuous(benchmark::State& state) {
  const TransferFunction g = pneumid::D2C(pneumid::PaperArxModel());
  for (auto _ : state) benchmark::DoNotOptimize(pneumid::ComputeStepInfo(g));
}
BENCHMARK(BM_StepInfoArxContinuous);

}  // namespace

BENCHMARK_MAIN();
