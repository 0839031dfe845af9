// pneumid control: closed-loop simulation of a predictive (DMC, GPC) or PID
// controller designed from MODEL against PLANT, with its metrics.
//
//   pneumid control --controller dmc --model fopdt-paper --plant arx-paper --Ts 0.01
//       --rule shridhar-cooper --setpoint step:from=0,to=1,at=0 --duration 2 [--json]
//   pneumid control --controller dmc --model fopdt-paper --plant ipa --Ts 0.01
//       --u-min 0 --u-max 100 --constrained --setpoint "staircase:levels=0 40 80 40,dwell=2"
//       --duration 8 --load-step at=7,size=-10 -o loop.csv --plot loop.png
//   pneumid control ... --compare [shridhar-cooper,paper-modified]    (the paper's Figure 6)
#include <cctype>
#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "command_json.hpp"
#include "controller_options.hpp"
#include "output_options.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/spec.hpp"
#include "pneumid/control/closed_loop.hpp"
#include "pneumid/control/controller_factory.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/plant/signal.hpp"
#include "pneumid/realtime/realtime_config.hpp"
#include "pneumid/report/figures.hpp"
#include "validators.hpp"

namespace pneumid::cli {
namespace {

using Run = ControlRun;

std::string Fmt(double v, const char* unit = "") {
  if (!std::isfinite(v)) return "-";
  return fmt::format("{:.4g}{}", v, unit);
}

void PrintTable(const std::vector<Run>& runs) {
  std::vector<std::pair<std::string, std::function<std::string(const Run&)>>> rows = {
      {"controller", [](const Run& r) { return r.result.controller; }},
      {"first move", [](const Run& r) { return Fmt(r.result.metrics.first_move); }},
      {"first step: rise time 10-90 %",
       [](const Run& r) { return Fmt(r.result.metrics.rise_time, " s"); }},
      {"overshoot (worst step)",
       [](const Run& r) { return Fmt(r.result.metrics.overshoot_percent, " %"); }},
      {"overshoot beyond ripple",
       [](const Run& r) { return Fmt(r.result.metrics.overshoot_beyond_ripple_percent, " %"); }},
      {"settling time (worst step)",
       [](const Run& r) { return Fmt(r.result.metrics.settling_time, " s"); }},
      {"settling band (2 % or ripple)",
       [](const Run& r) { return "+-" + Fmt(r.result.metrics.settling_band); }},
      {"steady-state error", [](const Run& r) { return Fmt(r.result.metrics.steady_state_error); }},
      {"steady-state error (worst step)",
       [](const Run& r) { return Fmt(r.result.metrics.worst_steady_state_error); }},
      {"IAE", [](const Run& r) { return Fmt(r.result.metrics.iae); }},
      {"ISE", [](const Run& r) { return Fmt(r.result.metrics.ise); }},
      {"ITAE", [](const Run& r) { return Fmt(r.result.metrics.itae); }},
      {"TV(u)", [](const Run& r) { return Fmt(r.result.metrics.tv_u); }},
      {"u min", [](const Run& r) { return Fmt(r.result.metrics.u_min); }},
      {"u max", [](const Run& r) { return Fmt(r.result.metrics.u_max); }},
      {"load peak deviation",
       [](const Run& r) { return Fmt(r.result.metrics.load_peak_deviation); }},
      {"load recovery time",
       [](const Run& r) { return Fmt(r.result.metrics.load_recovery_time, " s"); }},
  };
  std::size_t w0 = 20;
  for (const auto& row : rows) w0 = std::max(w0, row.first.size() + 2);
  std::vector<std::size_t> widths;
  for (const Run& r : runs) {
    std::size_t w = r.label.size();
    for (const auto& row : rows) w = std::max(w, row.second(r).size());
    widths.push_back(w + 2);
  }
  std::cout << fmt::format("{:<{}}", "", w0);
  for (std::size_t i = 0; i < runs.size(); ++i)
    std::cout << fmt::format("{:>{}}", runs[i].label, widths[i]);
  std::cout << "\n";
  for (const auto& row : rows) {
    std::cout << fmt::format("{:<{}}", row.first, w0);
    for (std::size_t i = 0; i < runs.size(); ++i)
      std::cout << fmt::format("{:>{}}", row.second(runs[i]), widths[i]);
    std::cout << "\n";
  }
  std::cout << "plant: " << runs[0].result.plant << "\n";
}

void WriteCsv(const std::string& path, const std::vector<Run>& runs) {
  std::ofstream out(path);
  if (!out) throw DataError(fmt::format("{}: cannot open for writing", path));
  const bool one = runs.size() == 1;
  out << "t,r";
  for (const Run& r : runs) {
    const std::string s = one ? "" : "_" + r.label;
    out << ",y" << s << ",y_meas" << s << ",u" << s << ",d" << s;
  }
  out << "\n";
  const auto& t = runs[0].result.t;
  for (Eigen::Index k = 0; k < t.size(); ++k) {
    // Values in their shortest exact form: a replay of the trace (through
    // a generated module, say) sees what the controller saw.
    out << fmt::format("{:.6g},{}", t(k), runs[0].result.r(k));
    for (const Run& r : runs) {
      out << fmt::format(",{},{},{},{}", r.result.y(k), r.result.y_meas(k), r.result.u(k),
                         r.result.d(k));
    }
    out << "\n";
  }
  if (!out) throw DataError(fmt::format("{}: write failed", path));
}

// "DMC", "GPC", "PID", "MPC".
std::string TypeName(ControllerType type) {
  std::string name = ToString(type);
  for (char& ch : name) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  return name;
}

// Legend entry of a run: the controller and its settings.
std::string ControllerLabel(const Run& r) {
  const BuiltController& b = r.built;
  if (b.type == ControllerType::kPid) {
    return fmt::format("PID {} (Kc={:.3g}, Ti={:.3g} s, Td={:.3g} s{})",
                       b.auto_summary.empty() ? ToString(b.pid_rule) : std::string("auto"),
                       b.pid_gains.Kc, b.pid_gains.Ti, b.pid_gains.Td,
                       b.pid_setpoint_weight != 1.0
                           ? fmt::format(", b={:.3g}", b.pid_setpoint_weight)
                           : std::string());
  }
  return fmt::format("{} {} (P={}, M={}, lambda={:.3g})", TypeName(b.type), r.label, b.tuning.P,
                     b.tuning.M, b.tuning.lambda);
}

// Output and input (units of the plant: force N or position m and duty % for
// the IPA, none for a linear model), the set-point, one legend entry per
// controller, and a title naming controller, plant, model and sample time.
void WritePlot(const std::string& path, const std::vector<Run>& runs, const ControlArgs& c,
               const std::string& plant_spec, const Actuator& actuator) {
  const Channel in = actuator.input, out = actuator.output;
  ClosedLoopFigureOptions options;
  options.labels.time = "Time t [s]";
  options.labels.output = out.unit == "N"   ? "Force F [N]"
                          : out.unit == "m" ? "Position x [m]"
                                            : "Output y";
  options.labels.input = in.unit == "%" ? "Duty cycle u [%]" : "Input u";
  options.title = fmt::format("{} on {} (model {}, Ts = {:g} s)", TypeName(runs[0].built.type),
                              PlotLiteral(plant_spec), PlotLiteral(c.model), c.Ts);
  if (!c.load_steps.empty())
    options.disturbance_time = ParseLoadStep("--load-step", c.load_steps[0]).at;
  std::vector<ClosedLoopTrace> traces;
  for (const Run& r : runs) traces.push_back({ControllerLabel(r), r.result.y, r.result.u});
  ClosedLoopFigure(runs[0].result.t, runs[0].result.r, traces, options).Save(path);
}

}  // namespace

ControlScenarioOptions ToScenarioOptions(const ControlArgs& c) {
  ControlScenarioOptions o;
  o.model = c.model;
  o.controller = c.controller;
  o.plant = c.plant;
  o.Ts = c.Ts;
  o.setpoint = c.setpoint;
  o.duration = c.duration;
  o.noise = c.noise;
  o.seed = c.seed;
  o.stop = c.stop;
  for (const std::string& l : c.load_steps) o.load_steps.push_back(ParseLoadStep("--load-step", l));
  // --compare: the same controller with each rule's own settings.
  if (c.compare_given) {
    const bool pid = c.controller.controller == "pid";
    std::stringstream in(c.compare.empty() ? (pid ? "simc,imc" : "shridhar-cooper,paper-modified")
                                           : c.compare);
    std::string item;
    while (std::getline(in, item, ',')) o.compare_rules.push_back(item);
    PNEUMID_CHECK(!o.compare_rules.empty(), "--compare: no settings given");
  }
  return o;
}

std::vector<ControlRun> SimulateControl(const ControlArgs& c, std::vector<std::string>* warnings) {
  ControlScenarioResult scenario = RunControlScenario(ToScenarioOptions(c));
  if (warnings != nullptr) *warnings = scenario.warnings;
  if (!c.output.empty()) WriteCsv(c.output, scenario.runs);
  if (!c.plot.empty()) WritePlot(c.plot, scenario.runs, c, scenario.plant_spec, scenario.actuator);
  return std::move(scenario.runs);
}

nlohmann::ordered_json ControlJson(const std::vector<ControlRun>& runs,
                                   const std::vector<std::string>& warnings) {
  return ControlScenarioJson(runs, warnings);
}

namespace {

void Execute(const ControlArgs& c) {
  std::vector<std::string> warnings;
  const std::vector<Run> runs = SimulateControl(c, &warnings);
  for (const std::string& w : warnings) std::cerr << "pneumid control: warning: " << w << "\n";
  if (c.json) {
    std::cout << ControlJson(runs, warnings).dump(2) << "\n";
    return;
  }
  PrintTable(runs);
  for (const Run& r : runs) {
    if (r.built.type != ControllerType::kPid)
      std::cout << r.label << ": " << r.built.tuning.formula << "\n";
  }
}

const Registrar reg(
    "control", "Closed-loop simulation of DMC, GPC, PID or MPC against a plant, with metrics",
    [](CLI::App& app) {
      auto c = std::make_shared<ControlArgs>();
      app.add_option("--model", c->model,
                     "Controller's model: fopdt-paper, arx-paper, fopdt:K=..,tau=..,theta=.., "
                     "tf:..., FILE.json (required unless --config has [controller] model)");
      app.add_option("--config", c->config,
                     "Controller configuration (TOML, e.g. the controller.toml of `pneumid "
                     "commission`): its [controller] section, [loop] period and [io] plant; "
                     "flags given override it");
      app.add_option("--plant", c->plant,
                     "Plant: ipa, ipa-position, or any model spec (default: the model itself)");
      AddSampleTimeOption(app, c->Ts, "Sample time in s");
      AddControllerOptions(app, c->controller);
      app.add_option("--setpoint", c->setpoint, SignalSyntaxHelp())->required();
      app.add_option("--duration", c->duration, "Simulated time in s")
          ->required()
          ->check(Positive());
      app.add_option("--u-min", c->controller.limits.u_min,
                     "Lower input limit (default: the plant's input range, IPA 0 % duty)");
      app.add_option("--u-max", c->controller.limits.u_max,
                     "Upper input limit (default: the plant's input range, IPA 100 % duty)");
      app.add_option("--du-max", c->controller.limits.du_max, "Largest input change per sample");
      app.add_option("--y-min", c->controller.y_min,
                     "Soft lower output bound (with --constrained)");
      app.add_option("--y-max", c->controller.y_max,
                     "Soft upper output bound (with --constrained)");
      app.add_option("--noise", c->noise, "Measurement noise standard deviation (output units)")
          ->check(NonNegative());
      app.add_option("--seed", c->seed, "Noise seed")->capture_default_str();
      app.add_option("--load-step", c->load_steps,
                     "Load disturbance on the output: at=T,size=D (repeatable)");
      app.add_option("--t-filter", c->controller.t_filter,
                     "GPC observer polynomial T: 1, A, or coefficients '1 -0.8'")
          ->capture_default_str();
      app.add_option("--tau-c", c->controller.tau_c,
                     "PID closed-loop time constant in s (0 = rule default)")
          ->check(NonNegative());
      AddPidGainOptions(app, c->controller);
      app.add_flag("--json", c->json, "Print the metrics as JSON");
      AddPlotOption(app, c->plot, "set-point, output and input with units");
      app.add_option("-o,--output", c->output, "Write the trajectories to a CSV file");
      app.add_option("--compare", c->compare,
                     "Run several tuning rules on the same scenario, side by side (default: "
                     "shridhar-cooper,paper-modified; auto for the design tuned to the "
                     "specification; a pid: simc, imc, auto, default simc,imc)")
          ->expected(0, 1);
      app.callback([c, &app] {
        c->compare_given = app.count("--compare") > 0;
        if (!c->config.empty()) {
          const RealtimeConfig config = LoadRealtimeConfig(c->config);
          if (config.controller)
            ApplyControllerConfig(app, *config.controller, c->model, c->controller);
          if (app.count("--Ts") == 0) c->Ts = config.loop.period;
          if (app.count("--plant") == 0 && config.io == "sim" && config.plant_given)
            c->plant = config.plant;
        }
        PNEUMID_CHECK(!c->model.empty(),
                      "--model is required (or a --config file with [controller] model)");
        Execute(*c);
      });
    });

}  // namespace
}  // namespace pneumid::cli
