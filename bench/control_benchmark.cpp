// Cost of one control step of the predictive controllers (Google Benchmark).
//
//   BM_DmcUnconstrainedStep   DMC P = 126, M = 10 (paper's modified settings):
//                             free-response update plus a dot product
//   BM_GpcStep                GPC N2 = 126, Nu = 10 on the paper's ARX model
//   BM_QdmcClosedLoop         QDMC P = 126, M = 10 with bounds on u and delta u,
//                             10,000-step closed loop against the FOPDT plant
//                             with a square-wave set-point that drives the
//                             input into its bounds; counters report the
//                             median, 99th percentile and worst step (us) in
//                             wall-clock time (includes preemption by other
//                             processes) and the worst step in thread CPU time
//
//   build-<dir>/bench/control_benchmark --benchmark_min_time=0.5
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <memory>
#include <vector>

#include <benchmark/benchmark.h>

#include "pneumid/control/dmc.hpp"
#include "pneumid/control/gpc.hpp"
#include "pneumid/control/inverse_map_controller.hpp"
#include "pneumid/control/mpc.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/plant/linear_plant.hpp"

namespace {

using namespace pneumid;

double ThreadCpuMicroseconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e6 + static_cast<double>(ts.tv_nsec) * 1e-3;
}

DmcOptions PaperModified() {
  DmcOptions o;
  o.P = 126;
  o.M = 10;
  o.lambda = 1.92;
  return o;
}

void BM_DmcUnconstrainedStep(benchmark::State& state) {
  DmcController dmc(PaperFopdtModel(), 0.01, PaperModified());
  // A first-order lag standing in for the plant keeps the measurement moving.
  double y = 0.0, u = 0.0;
  long k = 0;
  for (auto _ : state) {
    const double r = (k++ / 200) % 2 ? 1.0 : 0.0;
    u = dmc.Update(r, y);
    y = 0.96 * y + 0.064 * u;
    benchmark::DoNotOptimize(u);
  }
}
BENCHMARK(BM_DmcUnconstrainedStep);

// The cost the inverse static map adds to a controller step (issue target:
// <= 0.2 us): the same unconstrained MPC alone (arg 0) and behind the inverse
// of a 21-knot S-shaped map (arg 1), on the same lag plant.
void BM_InverseMapStep(benchmark::State& state) {
  std::vector<double> u, y;
  for (int i = 0; i <= 20; ++i) {
    u.push_back(5.0 * i);
    const double x = (5.0 * i - 50.0) / 15.0;
    y.push_back(i <= 2 ? 0.0 : 140.0 / (1.0 + std::exp(-x)));
  }
  const StaticMap map(u, y);
  MpcOptions o;
  o.P = 126;
  o.M = 5;
  o.lambda = 1.0;
  auto mpc = std::make_unique<MpcController>(PaperFopdtModel(), 0.01, o);
  std::unique_ptr<Controller> c;
  if (state.range(0) == 1)
    c = std::make_unique<InverseMapController>(std::move(mpc), map);
  else
    c = std::move(mpc);
  double yk = 0.0, uk = 0.0;
  long k = 0;
  for (auto _ : state) {
    const double r = (k++ / 200) % 2 ? 100.0 : 20.0;
    uk = c->Update(r, yk);
    yk = 0.96 * yk + 0.04 * (state.range(0) == 1 ? map.Evaluate(uk) : 1.6 * uk);
    benchmark::DoNotOptimize(uk);
  }
}
BENCHMARK(BM_InverseMapStep)->Arg(0)->Arg(1);

void BM_GpcStep(benchmark::State& state) {
  GpcOptions o;
  o.N2 = 126;
  o.Nu = 10;
  o.lambda = 1.92;
  GpcController gpc(PaperArxModel(), 0.01, o);
  double y = 0.0, u = 0.0;
  long k = 0;
  for (auto _ : state) {
    const double r = (k++ / 200) % 2 ? 1.0 : 0.0;
    u = gpc.Update(r, y);
    y = 0.96 * y + 0.064 * u;
    benchmark::DoNotOptimize(u);
  }
}
BENCHMARK(BM_GpcStep);

void BM_QdmcClosedLoop(benchmark::State& state) {
  DmcOptions o = PaperModified();
  o.constrained = true;
  o.limits.u_min = 0.0;
  o.limits.u_max = 0.9;
  o.limits.du_max = 0.15;
  constexpr int kSteps = 10000;
  std::vector<double> times(kSteps);
  double median = 0, p99 = 0, worst = 0, worst_cpu = 0, active_fraction = 0;
  for (auto _ : state) {
    DmcController dmc(PaperFopdtModel(), 0.01, o);
    LinearPlant plant(PaperFopdtModel(), 0.01);
    int active = 0;
    worst_cpu = 0.0;
    for (int k = 0; k < kSteps; ++k) {
      const double r = (k / 150) % 2 ? 1.2 : 0.1;  // 1.2 needs u = 0.75 > what du allows at once
      const double y = plant.Measure();
      const double cpu_start = ThreadCpuMicroseconds();
      const auto start = std::chrono::steady_clock::now();
      const double u = dmc.Update(r, y);
      const auto stop = std::chrono::steady_clock::now();
      worst_cpu = std::max(worst_cpu, ThreadCpuMicroseconds() - cpu_start);
      times[k] = std::chrono::duration<double, std::micro>(stop - start).count();
      active += dmc.last_qp_summary().num_active > 0 ? 1 : 0;
      plant.Advance(u);
    }
    std::vector<double> sorted = times;
    std::sort(sorted.begin(), sorted.end());
    median = sorted[kSteps / 2];
    p99 = sorted[kSteps * 99 / 100];
    worst = sorted.back();
    active_fraction = static_cast<double>(active) / kSteps;
  }
  state.counters["median_us"] = median;
  state.counters["p99_us"] = p99;
  state.counters["worst_us"] = worst;
  state.counters["worst_cpu_us"] = worst_cpu;
  state.counters["steps_with_active_constraints"] = active_fraction;
}
BENCHMARK(BM_QdmcClosedLoop)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
