// Speed of the parametric estimators on long records (single thread):
//   BM_Arx331          ARX(3,3,1) by blocked Householder QR, N samples in memory
//   BM_ArxStreamFile   ARX(3,3,1) streamed from a CSV file in constant memory
//                      (the file is generated once in /tmp; N from the argument)
//   BM_Subspace        PO-MOESP order 3 (4s x 4s triangular factor, no N x N matrix)
// Run: build/bench/arx_benchmark --benchmark_filter=BM_Arx331
// The 10^8-sample streaming run: PNEUMID_BENCH_STREAM=100000000 build/bench/arx_benchmark
//   --benchmark_filter=BM_ArxStreamFile
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "pneumid/data/load.hpp"
#include "pneumid/identify/parametric/arx.hpp"
#include "pneumid/identify/parametric/arx_streaming.hpp"
#include "pneumid/identify/parametric/subspace.hpp"

namespace {

using pneumid::PolynomialModel;

// Data of the paper's ARX(3,3,1) force model (Eq. 5) driven by a random binary
// signal held for 3 samples, with white equation noise.
struct Data {
  Eigen::VectorXd u, y;
};

Data MakeData(Eigen::Index n) {
  Data d;
  d.u.resize(n);
  d.y.resize(n);
  std::mt19937_64 gen(1);
  std::normal_distribution<double> noise(0.0, 0.5);
  const double a1 = -0.60870, a2 = -0.27020, a3 = -0.06021;
  const double b1 = 0.03938, b2 = 0.04506, b3 = 0.01286;
  double level = 10;
  for (Eigen::Index t = 0; t < n; ++t) {
    if (t % 3 == 0) level = (gen() & 1) ? 90.0 : 10.0;
    d.u[t] = level;
    double y = noise(gen);
    if (t >= 1) y += -a1 * d.y[t - 1] + b1 * d.u[t - 1];
    if (t >= 2) y += -a2 * d.y[t - 2] + b2 * d.u[t - 2];
    if (t >= 3) y += -a3 * d.y[t - 3] + b3 * d.u[t - 3];
    d.y[t] = y;
  }
  return d;
}

// PNEUMID_BENCH_DATA=file.csv (columns u, y) replaces the generated data, so
// that bench/arx_vs_octave.sh times both programs on the same samples.
Data BenchData(Eigen::Index n) {
  const char* path = std::getenv("PNEUMID_BENCH_DATA");
  if (path == nullptr) return MakeData(n);
  pneumid::LoadOptions lo;
  lo.sample_time = 0.01;
  const pneumid::Dataset ds = pneumid::LoadDataset(path, lo);
  return {ds.u(0), ds.y(0)};
}

void BM_Arx331(benchmark::State& state) {
  const Data d = BenchData(state.range(0));
  if (state.thread_index() == 0 && std::getenv("PNEUMID_BENCH_DATA") != nullptr) {
    const pneumid::ArxResult r =
        pneumid::EstimateArx(d.y, Eigen::MatrixXd(d.u), 0.01, pneumid::ArxOptions{});
    state.SetLabel(fmt::format("N={} a=[{:.5f} {:.5f} {:.5f}] b=[{:.5f} {:.5f} {:.5f}]", d.y.size(),
                               r.model.a[1], r.model.a[2], r.model.a[3], r.model.b[0][1],
                               r.model.b[0][2], r.model.b[0][3]));
  }
  const Eigen::MatrixXd u = d.u;
  pneumid::ArxOptions o;  // na = nb = 3, nk = 1
  for (auto _ : state) {
    pneumid::ArxResult r = pneumid::EstimateArx(d.y, u, 0.01, o);
    benchmark::DoNotOptimize(r.model.a.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_Arx331)->Arg(10000)->Arg(1000000)->Unit(benchmark::kMillisecond);

void BM_Subspace(benchmark::State& state) {
  const Data d = MakeData(state.range(0));
  pneumid::SubspaceOptions o;
  o.order = 3;
  for (auto _ : state) {
    pneumid::SubspaceResult r = pneumid::EstimateSubspace(d.y, d.u, 0.01, o);
    benchmark::DoNotOptimize(r.model.A().data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_Subspace)->Arg(1000000)->Unit(benchmark::kMillisecond)->Iterations(3);

std::string StreamFile(long long n) {
  const std::string path = fmt::format("/tmp/pneumid_arx_stream_{}.csv", n);
  if (std::FILE* f = std::fopen(path.c_str(), "rb")) {
    std::fclose(f);
    return path;
  }
  std::FILE* f = std::fopen((path + ".part").c_str(), "wb");
  if (!f) return {};
  std::fputs("u,y\n", f);
  const Eigen::Index block = 1 << 20;
  std::string buf;
  Data d = MakeData(block);  // the same block repeated (the estimate does not matter here)
  for (long long done = 0; done < n; done += block) {
    buf.clear();
    const Eigen::Index m = static_cast<Eigen::Index>(std::min<long long>(block, n - done));
    for (Eigen::Index t = 0; t < m; ++t)
      fmt::format_to(std::back_inserter(buf), "{:g},{:.6g}\n", d.u[t], d.y[t]);
    std::fwrite(buf.data(), 1, buf.size(), f);
  }
  std::fclose(f);
  std::rename((path + ".part").c_str(), path.c_str());
  return path;
}

void BM_ArxStreamFile(benchmark::State& state) {
  const char* env = std::getenv("PNEUMID_BENCH_STREAM");
  const long long n = env ? std::atoll(env) : state.range(0);
  const std::string path = StreamFile(n);
  if (path.empty()) {
    state.SkipWithError("cannot write the data file in /tmp");
    return;
  }
  pneumid::StreamingArxOptions o;
  o.sample_time = 0.01;
  double bytes = 0;
  for (auto _ : state) {
    pneumid::StreamingArxResult r = pneumid::EstimateArxFromFile(path, o);
    bytes = r.bytes;
    benchmark::DoNotOptimize(r.arx.model.a.data());
  }
  state.SetItemsProcessed(state.iterations() * n);
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * bytes));
  state.counters["samples"] = static_cast<double>(n);
}
BENCHMARK(BM_ArxStreamFile)->Arg(10000000)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
