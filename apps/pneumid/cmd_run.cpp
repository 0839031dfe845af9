// pneumid run: the closed loop (DMC, GPC, PID or MPC designed from a model) in real
// time on the simulator, a plant server (udp) or a comedi card, with a live
// status line, the full log, timing statistics and closed-loop metrics.
#include <iostream>
#include <memory>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "command_json.hpp"
#include "controller_options.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/control/closed_loop.hpp"
#include "pneumid/plant/signal.hpp"
#include "pneumid/realtime/realtime_config.hpp"
#include "pneumid/workflow/run_workflow.hpp"
#include "realtime_options.hpp"

namespace pneumid::cli {

RunWorkflowOptions ToWorkflowOptions(const RunArgs& o) {
  RunWorkflowOptions w;
  w.controller = o.controller;
  w.model = o.model;
  w.model_document = o.model_document;
  w.setpoint = o.setpoint;
  for (const std::string& l : o.load_steps) w.load_steps.push_back(ParseLoadStep("--load-step", l));
  w.offline = o.offline;
  w.plant_options = SimulatedPlantOptions(o.rt);
  w.safety = o.safety;
  w.log = o.rt.log;
  w.live_status = StderrIsTerminal() && !o.rt.json;
  w.warn = [](const std::string& message) {
    std::cerr << "pneumid run: warning: " << message << "\n";
  };
  return w;
}

namespace {

// The metrics of a run as one line, or nothing when there are none.
std::string MetricsLine(const char* name, const nlohmann::json& mj) {
  if (mj.is_null()) return std::string();
  auto v = [&](const char* k) {
    return mj[k].is_number() ? fmt::format("{:.4g}", mj[k].get<double>()) : std::string("-");
  };
  return fmt::format("{}: rise {} s, overshoot {} %, settling {} s, ss error {}, iae {}\n", name,
                     v("rise_time"), v("overshoot_percent"), v("settling_time"),
                     v("steady_state_error"), v("iae"));
}

void Run(const RunArgs& options, CLI::App& app) {
  const RealtimeConfig config = ResolveRealtimeConfig(options.rt, app);
  RunArgs o = options;
  if (config.controller) ApplyControllerConfig(app, *config.controller, o.model, o.controller);
  const RunWorkflowResult out = RunRealtimeWorkflow(ToWorkflowOptions(o), config);
  const LoopSummary& sum = out.summary;
  if (o.rt.json) {
    std::cout << out.ToJson().dump(2) << "\n";
  } else {
    std::cout << fmt::format("{} on {}\n{}\n{}\n{}\n", out.controller, out.io, sum.message,
                             sum.timing.BriefReport(), sum.scheduling);
    std::cout << MetricsLine("metrics", out.metrics) << MetricsLine("offline", out.offline);
    if (!o.rt.log.empty()) std::cout << fmt::format("log: {} ({} rows)\n", o.rt.log, out.log_rows);
  }
  FinishSession("run", sum);
}

}  // namespace

static Registrar reg(
    "run",
    "Run a DMC, GPC, PID or MPC loop in real time on the simulator, a plant server (udp) or a "
    "comedi card, with safety limits, a log and timing statistics",
    [](CLI::App& app) {
      auto o = std::make_shared<RunArgs>();
      AddControllerOptions(app, o->controller);
      AddPidGainOptions(app, o->controller);
      app.add_option("--model", o->model,
                     "controller model: built-in name, inline spec or model JSON")
          ->capture_default_str();
      app.add_option("--setpoint", o->setpoint, "set-point signal (N)\n" + SignalSyntaxHelp())
          ->capture_default_str();
      RealtimeHelp help;
      help.plant = "plant of the sim backend and of --offline (default ipa)";
      help.json = "print samples, overruns, jitter_p99_us, jitter_max_us, ... and metrics as JSON";
      AddRealtimeOptions(app, o->rt, help);
      app.add_option("--u-min", o->safety.u_min,
                     "output clamp, lower (%; default: the plant's input range, IPA 0, position "
                     "twin -100)");
      app.add_option("--u-max", o->safety.u_max,
                     "output clamp, upper (%; default: the plant's, 100)");
      app.add_option("--rate-max", o->safety.rate_max, "output rate limit (%/s; default none)");
      app.add_option("--y-min", o->safety.y_min,
                     "measurement range, lower (N): outside is a fault");
      app.add_option("--y-max", o->safety.y_max, "measurement range, upper (N)");
      app.add_option("--frozen-samples", o->safety.frozen_samples,
                     "unchanged readings that count as a frozen sensor (0 = off)");
      app.add_option("--load-step", o->load_steps,
                     "load disturbance on the output at=T,size=D (repeatable): applied to the "
                     "sim backend and --offline; with udp or comedi it states when the plant's "
                     "load changes (plant-server --load-step), for the metrics");
      app.add_flag("--offline", o->offline,
                   "also simulate the same scenario offline on --plant and print its metrics");
      app.callback([o, &app] { Run(*o, app); });
    });

}  // namespace pneumid::cli
