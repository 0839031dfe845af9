// Cost of one step of the state-space MPC (mpc.hpp), P = 150, M = 10
// (Google Benchmark). Two models, both at Ts = 0.01 s:
//   fopdt  the paper's 1.6 exp(-0.001 s)/(0.245 s + 1): 2 states (the
//          fractional delay is one) + the output disturbance, nz = 3
//   ninth  1.6 exp(-0.04 s) / ((0.2 s + 1)(0.1 s + 1)(0.05 s + 1)(0.03 s + 1)
//          (0.02 s + 1)): 5 states + 4 delay states = 9, nz = 10
//
//   BM_MpcUnconstrainedStep/<model>  Kalman correction, target, precomputed
//                                    gain, prediction: O(nz^2)
//   BM_MpcConstrainedLoop/<model>/<soft>  bounds u in [0, 0.9], |du| <= 0.15
//                                    (soft = 1: also a soft y_max = 1.25, 150
//                                    more QP rows), 10,000-step closed loop
//                                    against the model with 20 % more gain
//                                    and a square-wave set-point that drives
//                                    the input into its bounds; counters: the
//                                    median, 99th percentile and worst step
//                                    (us, wall clock), the share of steps with
//                                    an active constraint, the median and 99th
//                                    percentile over those steps alone (they
//                                    solve the QP; the others take the
//                                    unconstrained moves), QP failures and
//                                    active-set changes (p99, max)
//
//   build-<dir>/bench/mpc_benchmark
#include <algorithm>
#include <chrono>
#include <vector>

#include <benchmark/benchmark.h>

#include "pneumid/control/mpc.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/plant/linear_plant.hpp"

namespace {

using namespace pneumid;

TransferFunction Model(int which, double gain = 1.6) {
  if (which == 0) return TransferFunction::Fopdt(gain, 0.245, 0.001);
  Eigen::VectorXd den = Eigen::VectorXd::Ones(1);
  for (double tau : {0.2, 0.1, 0.05, 0.03, 0.02})
    den = poly::Multiply(den, Eigen::Vector2d(tau, 1.0));
  return TransferFunction(Eigen::VectorXd::Constant(1, gain), den, 0.0, 0.04);
}

MpcOptions Options() {
  MpcOptions o;
  o.P = 150;
  o.M = 10;
  o.lambda = 2.0;
  return o;
}

void BM_MpcUnconstrainedStep(benchmark::State& state) {
  MpcController mpc(Model(static_cast<int>(state.range(0))), 0.01, Options());
  double y = 0.0, u = 0.0;
  long k = 0;
  for (auto _ : state) {
    const double r = (k++ / 200) % 2 ? 1.0 : 0.0;
    u = mpc.Update(r, y);
    y = 0.96 * y + 0.064 * u;  // a first-order lag keeps the measurement moving
    benchmark::DoNotOptimize(u);
  }
  state.counters["nz"] = static_cast<double>(mpc.Az().rows());
}
BENCHMARK(BM_MpcUnconstrainedStep)->Arg(0)->Arg(1);

void BM_MpcConstrainedLoop(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  MpcOptions o = Options();
  o.limits.u_min = 0.0;
  o.limits.u_max = 0.9;
  o.limits.du_max = 0.15;
  if (state.range(1)) o.y_max = 1.25;
  constexpr int kSteps = 10000;
  std::vector<double> times(kSteps), iterations(kSteps);
  double median = 0, p99 = 0, worst = 0, active_fraction = 0, failures = 0, nz = 0;
  double iterations_p99 = 0, iterations_max = 0, median_qp = 0, p99_qp = 0;
  std::vector<double> qp_times;
  qp_times.reserve(kSteps);
  for (auto _ : state) {
    MpcController mpc(Model(which), 0.01, o);
    LinearPlant plant(Model(which, 1.6 * 1.2), 0.01);
    nz = static_cast<double>(mpc.Az().rows());
    int active = 0;
    qp_times.clear();
    for (int k = 0; k < kSteps; ++k) {
      const double r =
          (k / 150) % 2 ? 1.2 : 0.1;  // 1.2 needs u = 0.63: more than du allows at once
      const double y = plant.Measure();
      const auto start = std::chrono::steady_clock::now();
      const double u = mpc.Update(r, y);
      const auto stop = std::chrono::steady_clock::now();
      times[k] = std::chrono::duration<double, std::micro>(stop - start).count();
      active += mpc.last_step_constrained() ? 1 : 0;
      iterations[k] = mpc.last_step_constrained() ? mpc.last_qp_summary().iterations : 0;
      if (mpc.last_step_constrained()) qp_times.push_back(times[k]);
      plant.Advance(u);
    }
    std::vector<double> sorted = times;
    std::sort(sorted.begin(), sorted.end());
    median = sorted[kSteps / 2];
    p99 = sorted[kSteps * 99 / 100];
    worst = sorted.back();
    active_fraction = static_cast<double>(active) / kSteps;
    failures = mpc.qp_failures();
    std::sort(iterations.begin(), iterations.end());
    iterations_p99 = iterations[kSteps * 99 / 100];
    iterations_max = iterations.back();
    std::sort(qp_times.begin(), qp_times.end());
    if (!qp_times.empty()) {
      median_qp = qp_times[qp_times.size() / 2];
      p99_qp = qp_times[qp_times.size() * 99 / 100];
    }
  }
  state.counters["median_us"] = median;
  state.counters["p99_us"] = p99;
  state.counters["worst_us"] = worst;
  state.counters["steps_with_active_constraints"] = active_fraction;
  state.counters["qp_failures"] = failures;
  state.counters["nz"] = nz;
  state.counters["qp_step_median_us"] = median_qp;
  state.counters["qp_step_p99_us"] = p99_qp;
  state.counters["qp_iterations_p99"] = iterations_p99;
  state.counters["qp_iterations_max"] = iterations_max;
}
BENCHMARK(BM_MpcConstrainedLoop)
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
