// pneumid run: the closed loop (DMC, GPC, PID or MPC designed from a model) in real
// time on the simulator, a plant server (udp) or a comedi card, with a live
// status line, the full log, timing statistics and closed-loop metrics.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "command_json.hpp"
#include "controller_options.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/control/closed_loop.hpp"
#include "pneumid/control/controller.hpp"
#include "pneumid/control/controller_factory.hpp"
#include "pneumid/lti/model_io.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/plant/signal.hpp"
#include "pneumid/realtime/controller_adapter.hpp"
#include "pneumid/realtime/io_factory.hpp"
#include "pneumid/realtime/realtime_config.hpp"
#include "pneumid/realtime/realtime_session.hpp"
#include "pneumid/realtime/sim_backend.hpp"
#include "realtime_options.hpp"
#include "validators.hpp"

namespace pneumid::cli {
namespace {

// The control area's settings and factory (controller_factory.hpp).
BuiltController BuildController(const RunArgs& o, const TransferFunction& model, double Ts,
                                const InputLimits& limits, const IoBackend& io) {
  ControllerSettings c = o.controller;
  c.limits = limits;  // the safety layer's clamp
  ApplyPlantInputGaps(io.actuator(), io.Describe(), c.input_gaps);
  return MakeController(model, Ts, WithModelInputMap(ToControllerSpec(c), o.model));
}

}  // namespace

void ApplySafetyFlags(const RunArgs& o, RealtimeConfig& config) {
  auto& s = config.safety;
  if (o.u_min) s.u_min = *o.u_min;
  if (o.u_max) s.u_max = *o.u_max;
  if (o.rate_max) s.rate_max = *o.rate_max;
  if (o.y_min) s.y_min = *o.y_min;
  if (o.y_max) s.y_max = *o.y_max;
  if (o.frozen_samples) s.frozen_samples = *o.frozen_samples;
  std::string error;
  PNEUMID_CHECK(s.IsValid(&error), "invalid safety settings: {}", error);
}

RunOutcome RunRealtime(const RunArgs& o, const RealtimeConfig& config,
                       SpscRingBuffer<LogRecord>* live) {
  const auto& s = config.safety;

  const IoSpec spec = ParseIoSpec(config.io);
  const double Ts = config.loop.period;
  const TransferFunction model = ParseControllerModel(o.model);
  const PlantOptions plant_options = SimulatedPlantOptions(o.rt);
  auto io = MakeIoBackend(spec, config, plant_options);
  // Without a clamp from the flags or the file: the plant's input range where
  // it is finite (the position twin's -100..100 %), else the safety defaults.
  SafetyOptions safety = s;
  if (!o.u_min && !o.u_max && !config.safety_range_given) {
    const Actuator a = io->actuator();
    if (std::isfinite(a.u_min) && std::isfinite(a.u_max) && a.u_min < a.u_max) {
      safety.u_min = a.u_min;
      safety.u_max = a.u_max;
    }
  }
  InputLimits limits;
  limits.u_min = safety.u_min;
  limits.u_max = safety.u_max;
  BuiltController built = BuildController(o, model, Ts, limits, *io);
  const std::string controller_text = built.controller->Describe();
  ControllerAdapter controller(std::move(built.controller));

  const auto sp = ParseSignal(o.setpoint);
  const std::int64_t n = config.loop.Samples();
  const Eigen::VectorXd r = sp->Sample(Ts, n);
  const std::vector<double> setpoint(r.data(), r.data() + r.size());

  std::vector<LoadStep> loads;
  for (const std::string& l : o.load_steps) loads.push_back(ParseLoadStep("--load-step", l));
  if (auto* sim = dynamic_cast<SimBackend*>(io.get())) sim->SetLoadSteps(loads);

  SessionOptions so;
  so.loop = config.loop;
  so.safety = safety;
  so.log = config.log;
  so.log.live = live;
  so.log_path = o.rt.log;
  if (IsMatPath(o.rt.log)) so.log.format = LogFormat::kMat;
  so.keep_records = true;
  so.header.emplace_back("model", o.model);
  so.header.emplace_back("tuning", built.Summary());
  so.header.emplace_back("setpoint", sp->ToString());
  so.live_status = StderrIsTerminal() && !o.rt.json;
  const SessionResult res = RunSession(so, *io, controller, setpoint);
  const LoopSummary& sum = res.summary;

  // Closed-loop metrics of the run, by the control area's definitions.
  nlohmann::json metrics = nullptr;
  ClosedLoopOptions clo;
  clo.duration = config.loop.duration;
  clo.actuator = limits;
  clo.load_steps = loads;
  const auto m = static_cast<Eigen::Index>(res.records.size());
  if (m >= 2) {
    Eigen::VectorXd t(m), rr(m), y(m), u(m);
    for (Eigen::Index i = 0; i < m; ++i) {
      t[i] = res.records[i].t;
      rr[i] = res.records[i].r;
      y[i] = res.records[i].y;
      u[i] = res.records[i].u;
    }
    if (sum.termination == Termination::kSuccess)
      metrics = ComputeClosedLoopMetrics(t, rr, y, u, (*sp)(-Ts), 0.0, clo).ToJson();
  }
  nlohmann::json offline = nullptr;
  if (o.offline) {
    // The same scenario simulated offline (no real time, no network) for comparison.
    auto plant = MakePlant(config.plant, Ts, plant_options);
    BuiltController again = BuildController(o, model, Ts, limits, *io);
    const ClosedLoopResult ref = SimulateClosedLoop(*again.controller, *plant, *sp, clo);
    offline = ref.metrics.ToJson();
  }

  RunOutcome out;
  out.summary = sum;
  out.controller = controller_text;
  out.io = io->Describe();
  out.log_rows = res.log_rows;
  out.metrics = metrics;
  out.offline = offline;
  nlohmann::json& j = out.json;
  j = sum.ToJson();
  j["controller"] = controller_text;
  j["io"] = out.io;
  j["log"] = o.rt.log;
  j["log_rows"] = res.log_rows;
  j["metrics"] = metrics;
  if (o.offline) j["offline_metrics"] = offline;
  return out;
}

namespace {

void Run(const RunArgs& options, CLI::App& app) {
  RealtimeConfig config = ResolveRealtimeConfig(options.rt, app);
  RunArgs o = options;
  if (config.controller) ApplyControllerConfig(app, *config.controller, o.model, o.controller);
  ApplySafetyFlags(o, config);
  const RunOutcome out = RunRealtime(o, config);
  const LoopSummary& sum = out.summary;
  const std::string& controller_text = out.controller;
  const nlohmann::json& metrics = out.metrics;
  const nlohmann::json& offline = out.offline;
  const RunOutcome& res = out;
  if (o.rt.json) {
    std::cout << out.json.dump(2) << "\n";
  } else {
    std::cout << fmt::format("{} on {}\n{}\n{}\n{}\n", controller_text, out.io, sum.message,
                             sum.timing.BriefReport(), sum.scheduling);
    auto line = [](const char* name, const nlohmann::json& mj) {
      if (mj.is_null()) return std::string();
      auto v = [&](const char* k) {
        return mj[k].is_number() ? fmt::format("{:.4g}", mj[k].get<double>()) : std::string("-");
      };
      return fmt::format("{}: rise {} s, overshoot {} %, settling {} s, ss error {}, iae {}\n",
                         name, v("rise_time"), v("overshoot_percent"), v("settling_time"),
                         v("steady_state_error"), v("iae"));
    };
    std::cout << line("metrics", metrics) << line("offline", offline);
    if (!o.rt.log.empty()) std::cout << fmt::format("log: {} ({} rows)\n", o.rt.log, res.log_rows);
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
      app.add_option("--u-min", o->u_min,
                     "output clamp, lower (%; default: the plant's input range, IPA 0, position "
                     "twin -100)");
      app.add_option("--u-max", o->u_max, "output clamp, upper (%; default: the plant's, 100)");
      app.add_option("--rate-max", o->rate_max, "output rate limit (%/s; default none)");
      app.add_option("--y-min", o->y_min, "measurement range, lower (N): outside is a fault");
      app.add_option("--y-max", o->y_max, "measurement range, upper (N)");
      app.add_option("--frozen-samples", o->frozen_samples,
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
