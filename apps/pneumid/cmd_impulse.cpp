// pneumid impulse: response of a model to a unit impulse at t = 0 (the unit
// pulse u[0] = 1 for discrete models), with its peak, settling time and area
// (the DC gain for a stable model).
//
//   pneumid impulse --model fopdt-paper [--t-final T] [--json] [--plot impulse.png]
//   pneumid impulse --num 1 --den 1,2,1
#include <cmath>
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "model_options.hpp"
#include "output_options.hpp"
#include "pneumid/lti/response.hpp"
#include "pneumid/report/figures.hpp"
#include "validators.hpp"

namespace pneumid::cli {
namespace {

struct ImpulseArgs {
  ModelOptions model;
  double t_final = 0.0;
  double dt = 0.0;
  double settling_threshold = 0.02;
  bool json = false;
  std::string plot;
};

struct ImpulseInfo {
  double peak = 0.0;                    ///< y at the largest |y|
  double peak_time = 0.0;               ///< s
  double settling_time = std::nan("");  ///< last time |y| > threshold * |peak|
  double area = 0.0;  ///< integral of y over the horizon (discrete: sum of the samples)
};

ImpulseInfo ComputeImpulseInfo(const TimeResponse& r, bool discrete, double threshold) {
  ImpulseInfo info;
  const Eigen::Index n = r.y.size();
  Eigen::Index k_peak = 0;
  r.y.cwiseAbs().maxCoeff(&k_peak);
  info.peak = r.y[k_peak];
  info.peak_time = r.t[k_peak];
  const double band = threshold * std::abs(info.peak);
  Eigen::Index last = -1;
  for (Eigen::Index k = 0; k < n; ++k)
    if (std::abs(r.y[k]) > band) last = k;
  // Settled when the response stays in the band up to the end of the horizon.
  if (last >= 0 && last + 1 < n) info.settling_time = r.t[last + 1];
  if (discrete) {
    // The response to the unit pulse u[0] = 1: its sum is the DC gain.
    info.area = r.y.sum();
  } else {
    for (Eigen::Index k = 1; k < n; ++k)
      info.area += 0.5 * (r.y[k] + r.y[k - 1]) * (r.t[k] - r.t[k - 1]);
  }
  return info;
}

void Run(const ImpulseArgs& o) {
  const TransferFunction g = ResolveModel(o.model);
  const TimeResponse r = Impulse(g, o.t_final, o.dt);
  const ImpulseInfo info = ComputeImpulseInfo(r, g.IsDiscrete(), o.settling_threshold);
  const bool stable = g.IsStable();
  if (!o.plot.empty()) {
    StepFigureOptions fo;
    fo.t_final = r.t[r.t.size() - 1];
    fo.dt = g.IsDiscrete() ? 0.0 : r.t[1] - r.t[0];
    fo.title = "Impulse response of " + ModelLabel(o.model, g);
    fo.labels.output = "Output y (unit impulse input)";
    ImpulseResponseFigure({{ModelLabel(o.model, g), g}}, fo).Save(o.plot);
  }
  if (o.json) {
    nlohmann::ordered_json j;
    j["peak"] = JsonNumber(info.peak);
    j["peak_time"] = JsonNumber(info.peak_time);
    j["settling_time"] = stable ? JsonNumber(info.settling_time) : nlohmann::json(nullptr);
    j["area"] = stable ? JsonNumber(info.area) : nlohmann::json(nullptr);
    j["stable"] = stable;
    j["t"] = std::vector<double>(r.t.data(), r.t.data() + r.t.size());
    j["y"] = std::vector<double>(r.y.data(), r.y.data() + r.y.size());
    if (!o.plot.empty()) j["plot"] = o.plot;
    std::cout << j.dump() << "\n";
    return;
  }
  std::cout << "model:\n" << DescribeModel(g.Normalized(), "  ");
  std::cout << fmt::format("impulse response (unit impulse at t = 0, {} samples to {:g} s):\n",
                           r.t.size(), r.t[r.t.size() - 1]);
  std::cout << fmt::format("  {:<14} {:.6g}\n", "peak", info.peak);
  std::cout << fmt::format("  {:<14} {:.6g} s\n", "peak_time", info.peak_time);
  if (stable) {
    std::cout << fmt::format("  {:<14} {:.6g} s\n", "settling_time", info.settling_time);
    std::cout << fmt::format("  {:<14} {:.6g} (DC gain {:.6g})\n", "area", info.area, g.DcGain());
  } else {
    std::cout << "  (the model is not stable: the response grows without bound)\n";
  }
  if (!o.plot.empty()) std::cout << "plot written to " << o.plot << "\n";
}

const Registrar reg(
    "impulse", "Impulse response of a model (peak, settling time, area; --plot, --json)",
    [](CLI::App& app) {
      auto o = std::make_shared<ImpulseArgs>();
      AddModelOptions(app, o->model);
      AddTimeGridOptions(app, o->t_final, o->dt);
      app.add_option("--settling-threshold", o->settling_threshold,
                     "Settling band as a fraction of the peak")
          ->capture_default_str()
          ->check(InRange(0.0, 1.0));
      app.add_flag("--json", o->json,
                   "Print {\"peak\", \"peak_time\", \"settling_time\", \"area\", \"stable\", "
                   "\"t\", \"y\"} instead");
      AddPlotOption(app, o->plot, "the impulse response");
      app.callback([o] { Run(*o); });
    });

}  // namespace
}  // namespace pneumid::cli
