// pneumid step: step-response metrics of a model (MATLAB stepinfo definitions).
//
//   pneumid step --model arx-paper-ct [--json] [--t-final T]
//   pneumid step --num 1 --den 0.245,1 --delay 0.001
#include <cmath>
#include <iostream>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "model_options.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/lti/response.hpp"

namespace pneumid::cli {
namespace {

struct StepOptions {
  ModelOptions model;
  double t_final = 0.0;
  double dt = 0.0;
  double settling_threshold = 0.02;
  std::vector<double> rise_limits = {0.1, 0.9};
  bool json = false;
};

nlohmann::json Number(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

void Run(const StepOptions& o) {
  const TransferFunction g = ResolveModel(o.model);
  PNEUMID_CHECK(o.rise_limits.size() == 2, "--rise-limits takes two fractions LOW,HIGH, got {}",
                o.rise_limits.size());
  StepInfoOptions so;
  so.settling_threshold = o.settling_threshold;
  so.rise_low = o.rise_limits[0];
  so.rise_high = o.rise_limits[1];
  std::string error;
  PNEUMID_CHECK(so.IsValid(&error), "{}", error);
  StepInfo info;
  if (o.t_final == 0.0 && o.dt == 0.0) {
    info = ComputeStepInfo(g, so);
  } else {
    const TimeResponse r = Step(g, o.t_final, o.dt);
    so.y_initial = 0.0;
    if (g.IsStable()) so.y_final = g.DcGain();
    info = ComputeStepInfo(r.t, r.y, so);
  }
  if (o.json) {
    nlohmann::ordered_json j;
    j["rise_time"] = Number(info.rise_time);
    j["settling_time"] = Number(info.settling_time);
    j["settling_min"] = Number(info.settling_min);
    j["settling_max"] = Number(info.settling_max);
    j["overshoot"] = Number(info.overshoot);
    j["undershoot"] = Number(info.undershoot);
    j["peak"] = Number(info.peak);
    j["peak_time"] = Number(info.peak_time);
    j["steady_state"] = Number(info.steady_state);
    std::cout << j.dump() << "\n";
    return;
  }
  std::cout << "model:\n" << DescribeModel(g.Normalized(), "  ");
  std::cout << fmt::format("step response (unit step at t = 0, MATLAB stepinfo definitions):\n");
  const auto line = [](const char* name, double v, const char* unit) {
    std::cout << fmt::format("  {:<14} {:.6g}{}\n", name, v, unit);
  };
  line("rise_time", info.rise_time, " s");
  line("settling_time", info.settling_time, " s");
  line("settling_min", info.settling_min, "");
  line("settling_max", info.settling_max, "");
  line("overshoot", info.overshoot, " %");
  line("undershoot", info.undershoot, " %");
  line("peak", info.peak, "");
  line("peak_time", info.peak_time, " s");
  line("steady_state", info.steady_state, "");
  if (!g.IsStable()) std::cout << "  (the model is not stable: the metrics are undefined)\n";
}

const Registrar reg(
    "step", "Step-response metrics of a model (rise/settling time, overshoot, peak)",
    [](CLI::App& app) {
      auto o = std::make_shared<StepOptions>();
      AddModelOptions(app, o->model);
      app.add_option("--t-final", o->t_final,
                     "Simulated horizon in s (default 0: about 7 slowest time constants)")
          ->capture_default_str();
      app.add_option("--dt", o->dt,
                     "Time step in s (default 0: Ts, or 1/200 of the slowest time constant)")
          ->capture_default_str();
      app.add_option("--settling-threshold", o->settling_threshold,
                     "Settling band as a fraction of the step")
          ->capture_default_str();
      app.add_option("--rise-limits", o->rise_limits, "Rise-time fractions LOW,HIGH")
          ->delimiter(',')
          ->capture_default_str();
      app.add_flag("--json", o->json,
                   "Print {\"rise_time\", \"settling_time\", \"overshoot\", \"undershoot\", "
                   "\"peak\", \"peak_time\", \"steady_state\", ...} instead");
      app.callback([o] { Run(*o); });
    });

}  // namespace
}  // namespace pneumid::cli
