// pneumid run: the closed loop (DMC, GPC or PID designed from a model) in real
// time on the simulator, a plant server (udp) or a comedi card, with a live
// status line, the full log, timing statistics and closed-loop metrics.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
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

namespace pneumid::cli {
namespace {

struct RunOptions {
  std::string controller = "dmc";
  std::string model = "fopdt-paper";
  std::string rule;
  int P = 0;
  int M = 0;
  double lambda = std::numeric_limits<double>::quiet_NaN();
  bool constrained = false;
  std::string pid_rule = "simc";
  std::string setpoint = "step:from=0,to=100,at=0.5";
  std::string io = "sim";
  std::string config;
  std::string plant;
  std::uint64_t seed = 1;
  std::optional<double> noise;
  double duration = 10.0;
  double period = 0.01;
  bool fast = false;
  bool no_realtime = false;
  std::string safe_state;
  int max_overruns = 10;
  std::optional<double> u_min, u_max, rate_max, y_min, y_max;
  std::optional<int> frozen_samples;
  std::string log;
  bool json = false;
  bool offline = false;
};

struct Built {
  std::unique_ptr<Controller> controller;
  std::string tuning;  // what was used, for the log header
};

// The control area's factory (controller_factory.hpp) from the command-line settings.
Built BuildController(const RunOptions& o, const TransferFunction& model, double Ts,
                      const InputLimits& limits) {
  ControllerSpec spec;
  spec.type = ControllerTypeFromString(o.controller);
  if (!o.rule.empty()) {
    spec.tuning.rule = TuningRuleFromString(o.rule);
  } else if (o.P > 0 && o.M > 0 && std::isfinite(o.lambda)) {
    spec.tuning.rule = TuningRule::kExplicit;
  }
  spec.tuning.P = o.P;
  spec.tuning.M = o.M;
  spec.tuning.lambda = o.lambda;
  spec.limits = limits;
  spec.constrained = o.constrained;
  spec.pid_rule = PidTuningRuleFromString(o.pid_rule);
  BuiltController bc = MakeController(model, Ts, spec);
  Built b;
  b.controller = std::move(bc.controller);
  if (spec.type == ControllerType::kPid) {
    b.tuning =
        fmt::format("pid {} from FOPDT K={:g} tau={:g} theta={:g} ({}): Kc={:g} Ti={:g} Td={:g}",
                    o.pid_rule, bc.fopdt.K, bc.fopdt.tau, bc.fopdt.theta, bc.fopdt.method,
                    bc.pid_gains.Kc, bc.pid_gains.Ti, bc.pid_gains.Td);
  } else {
    b.tuning = fmt::format("{}: P={} M={} lambda={:g}; {}", ToString(bc.tuning.rule), bc.tuning.P,
                           bc.tuning.M, bc.tuning.lambda, bc.tuning.formula);
  }
  return b;
}

nlohmann::json MetricsJson(const ClosedLoopMetrics& m) {
  return {{"rise_time", m.rise_time},
          {"overshoot_percent", m.overshoot_percent},
          {"settling_time", m.settling_time},
          {"steady_state_error", m.steady_state_error},
          {"first_move", m.first_move},
          {"iae", m.iae},
          {"ise", m.ise},
          {"itae", m.itae},
          {"tv_u", m.tv_u},
          {"u_min", m.u_min},
          {"u_max", m.u_max}};
}

void Run(const RunOptions& o, CLI::App& app) {
  RealtimeConfig config = o.config.empty() ? RealtimeConfig{} : LoadRealtimeConfig(o.config);
  if (app.count("--io") || o.config.empty()) config.io = o.io;
  if (!o.plant.empty()) config.plant = o.plant;
  if (app.count("--duration") || o.config.empty()) config.loop.duration = o.duration;
  if (app.count("--period") || o.config.empty()) config.loop.period = o.period;
  if (o.fast) config.loop.fast = true;
  if (o.no_realtime) config.loop.realtime = false;
  auto& s = config.safety;
  if (!o.safe_state.empty()) s.safe_state = SafeStateFromString(o.safe_state);
  if (app.count("--max-overruns")) s.max_overruns = o.max_overruns;
  if (o.u_min) s.u_min = *o.u_min;
  if (o.u_max) s.u_max = *o.u_max;
  if (o.rate_max) s.rate_max = *o.rate_max;
  if (o.y_min) s.y_min = *o.y_min;
  if (o.y_max) s.y_max = *o.y_max;
  if (o.frozen_samples) s.frozen_samples = *o.frozen_samples;
  std::string error;
  PNEUMID_CHECK(s.IsValid(&error), "invalid safety settings: {}", error);
  PNEUMID_CHECK(config.loop.IsValid(&error), "{}", error);

  const IoSpec spec = ParseIoSpec(config.io);
  PNEUMID_CHECK(!config.loop.fast || spec.kind == IoKind::kSim,
                "--fast runs the simulator as fast as possible; it needs --io sim, got '{}'",
                config.io);
  const double Ts = config.loop.period;
  const TransferFunction model = ParseModelSpec(o.model);
  InputLimits limits;
  limits.u_min = s.u_min;
  limits.u_max = s.u_max;
  Built built = BuildController(o, model, Ts, limits);
  const std::string controller_text = built.controller->Describe();
  ControllerAdapter controller(std::move(built.controller));

  const auto sp = ParseSignal(o.setpoint);
  const std::int64_t n = config.loop.Samples();
  const Eigen::VectorXd r = sp->Sample(Ts, n);
  const std::vector<double> setpoint(r.data(), r.data() + r.size());

  PlantOptions plant_options;
  plant_options.seed = o.seed;
  plant_options.noise_sigma = o.noise;
  auto io = MakeIoBackend(spec, config, plant_options);

  SessionOptions so;
  so.loop = config.loop;
  so.safety = s;
  so.log = config.log;
  so.log_path = o.log;
  if (o.log.size() > 4 && o.log.substr(o.log.size() - 4) == ".mat") so.log.format = LogFormat::kMat;
  so.keep_records = true;
  so.header.emplace_back("model", o.model);
  so.header.emplace_back("tuning", built.tuning);
  so.header.emplace_back("setpoint", sp->ToString());
  so.live_status = StderrIsTerminal() && !o.json;
  const SessionResult res = RunSession(so, *io, controller, setpoint);
  const LoopSummary& sum = res.summary;

  // Closed-loop metrics of the run, by the control area's definitions.
  nlohmann::json metrics = nullptr;
  ClosedLoopOptions clo;
  clo.duration = config.loop.duration;
  clo.actuator = limits;
  const auto m = static_cast<Eigen::Index>(res.records.size());
  if (m >= 2) {
    Eigen::VectorXd t(m), rr(m), y(m), u(m);
    for (Eigen::Index i = 0; i < m; ++i) {
      t[i] = res.records[i].t;
      rr[i] = res.records[i].r;
      y[i] = res.records[i].y;
      u[i] = res.records[i].u;
    }
    if (sum.termination == LoopTermination::kSuccess)
      metrics = MetricsJson(ComputeClosedLoopMetrics(t, rr, y, u, (*sp)(-Ts), 0.0, clo));
  }
  nlohmann::json offline = nullptr;
  if (o.offline) {
    // The same scenario simulated offline (no real time, no network) for comparison.
    auto plant = MakePlant(o.plant.empty() ? config.plant : o.plant, Ts, plant_options);
    Built again = BuildController(o, model, Ts, limits);
    const ClosedLoopResult ref = SimulateClosedLoop(*again.controller, *plant, *sp, clo);
    offline = MetricsJson(ref.metrics);
  }

  if (o.json) {
    nlohmann::json j = sum.ToJson();
    j["controller"] = controller_text;
    j["io"] = io->Describe();
    j["log"] = o.log;
    j["log_rows"] = res.log_rows;
    j["metrics"] = metrics;
    if (o.offline) j["offline_metrics"] = offline;
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << fmt::format("{} on {}\n{}\n{}\n{}\n", controller_text, io->Describe(), sum.message,
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
    if (!o.log.empty()) std::cout << fmt::format("log: {} ({} rows)\n", o.log, res.log_rows);
  }
  if (sum.termination != LoopTermination::kSuccess) {
    std::cerr << "pneumid run: " << ToString(sum.termination) << ": " << sum.message << "\n";
    throw ExitCode{sum.ExitStatus()};
  }
}

}  // namespace

static Registrar reg(
    "run",
    "Run a DMC, GPC or PID loop in real time on the simulator, a plant server (udp) or a "
    "comedi card, with safety limits, a log and timing statistics",
    [](CLI::App& app) {
      auto o = std::make_shared<RunOptions>();
      app.add_option("--controller", o->controller, "dmc, gpc or pid")
          ->check(CLI::IsMember({"dmc", "gpc", "pid"}))
          ->capture_default_str();
      app.add_option("--model", o->model,
                     "controller model: built-in name, inline spec or model JSON")
          ->capture_default_str();
      app.add_option("--rule", o->rule,
                     "tuning rule: shridhar-cooper (conventional), paper-modified, explicit");
      app.add_option("--P", o->P, "prediction horizon (samples)");
      app.add_option("--M", o->M, "control horizon (samples)");
      app.add_option("--lambda", o->lambda, "move suppression");
      app.add_flag("--constrained", o->constrained, "dmc: QDMC with the input limits");
      app.add_option("--pid-rule", o->pid_rule, "pid tuning: simc or imc")->capture_default_str();
      app.add_option("--setpoint", o->setpoint, "set-point signal (N)\n" + SignalSyntaxHelp())
          ->capture_default_str();
      app.add_option("--io", o->io, "backend: sim, comedi:/dev/comediN or udp://HOST:PORT")
          ->capture_default_str();
      app.add_option("--config", o->config, "real-time TOML configuration (flags override it)");
      app.add_option("--plant", o->plant,
                     "plant of the sim backend and of --offline (default ipa)");
      app.add_option("--seed", o->seed, "noise seed of the simulated plant")->capture_default_str();
      app.add_option("--noise", o->noise,
                     "measurement noise of the simulated plant (output units)");
      app.add_option("--duration", o->duration, "s")->capture_default_str();
      app.add_option("--period", o->period, "loop period (s), 0.0001 .. 10 (default 10 ms)")
          ->capture_default_str();
      app.add_flag("--fast", o->fast, "sim only: as fast as possible instead of real time");
      app.add_flag("--no-realtime", o->no_realtime,
                   "do not ask for SCHED_FIFO/mlockall/pinning (normal priority)");
      app.add_option("--safe-state", o->safe_state, "valves-closed (default) or exhaust-open")
          ->check(CLI::IsMember({"valves-closed", "exhaust-open"}));
      app.add_option("--max-overruns", o->max_overruns,
                     "deadline overruns tolerated before the fault stop (-1: never)")
          ->capture_default_str();
      app.add_option("--u-min", o->u_min, "output clamp, lower (%; default 0)");
      app.add_option("--u-max", o->u_max, "output clamp, upper (%; default 100)");
      app.add_option("--rate-max", o->rate_max, "output rate limit (%/s; default none)");
      app.add_option("--y-min", o->y_min, "measurement range, lower (N): outside is a fault");
      app.add_option("--y-max", o->y_max, "measurement range, upper (N)");
      app.add_option("--frozen-samples", o->frozen_samples,
                     "unchanged readings that count as a frozen sensor (0 = off)");
      app.add_option("--log", o->log, "log file (.csv streamed, .mat written at the end)");
      app.add_flag(
          "--json", o->json,
          "print samples, overruns, jitter_p99_us, jitter_max_us, ... and metrics as JSON");
      app.add_flag("--offline", o->offline,
                   "also simulate the same scenario offline on --plant and print its metrics");
      app.callback([o, &app] { Run(*o, app); });
    });

}  // namespace pneumid::cli
