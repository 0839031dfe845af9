// pneumid control: closed-loop simulation of a predictive (DMC, GPC) or PID
// controller designed from MODEL against PLANT, with its metrics.
//
//   pneumid control --controller dmc --model fopdt-paper --plant arx-paper --Ts 0.01
//       --rule shridhar-cooper --setpoint step:from=0,to=1,at=0 --duration 2 [--json]
//   pneumid control --controller dmc --model fopdt-paper --plant ipa --Ts 0.01
//       --u-min 0 --u-max 100 --constrained --setpoint "staircase:levels=0 40 80 40,dwell=2"
//       --duration 8 --load-step at=7,size=-10 -o loop.csv --plot loop.png
//   pneumid control ... --compare [shridhar-cooper,paper-modified]    (the paper's Figure 6)
#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/spec.hpp"
#include "pneumid/control/closed_loop.hpp"
#include "pneumid/control/controller_factory.hpp"
#include "pneumid/control/dmc.hpp"
#include "pneumid/lti/model_io.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/plant/signal.hpp"
#include "pneumid/report/plot.hpp"

namespace pneumid::cli {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct ControlCli {
  std::string controller = "dmc";
  std::string model;
  std::string plant;
  double Ts = 0.01;
  std::string rule;
  int P = 0, M = 0;
  double lambda = kNaN;
  std::string setpoint;
  double duration = 0.0;
  double u_min = -kInf, u_max = kInf, du_max = kInf;
  bool constrained = false;
  double y_min = -kInf, y_max = kInf;
  double noise = 0.0;
  std::uint64_t seed = 1;
  std::vector<std::string> load_steps;
  std::string t_filter = "1";
  std::string pid_rule = "simc";
  double tau_c = 0.0;
  bool json = false;
  std::string plot;
  std::string output;
  bool compare_given = false;
  std::string compare;
};

LoadStep ParseLoadStep(const std::string& text) {
  Spec fields("--load-step", text, {.has_kind = false});
  LoadStep l;
  l.at = fields.Number("at");
  l.size = fields.Number("size");
  fields.Finish();
  return l;
}

nlohmann::json Number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

struct Run {
  std::string label;
  BuiltController built;
  ClosedLoopResult result;
  ControllerSpec spec;
};

nlohmann::ordered_json RunJson(const Run& run) {
  const ClosedLoopMetrics& m = run.result.metrics;
  nlohmann::ordered_json j;
  j["label"] = run.label;
  j["controller"] = run.result.controller;
  j["plant"] = run.result.plant;
  if (run.spec.type == ControllerType::kPid) {
    j["settings"] = {{"Kc", run.built.pid_gains.Kc},
                     {"Ti", Number(run.built.pid_gains.Ti)},
                     {"Td", run.built.pid_gains.Td},
                     {"rule", ToString(run.spec.pid_rule)}};
  } else {
    j["settings"] = {{"rule", ToString(run.built.tuning.rule)},
                     {"P", run.built.tuning.P},
                     {"M", run.built.tuning.M},
                     {"lambda", run.built.tuning.lambda},
                     {"formula", run.built.tuning.formula}};
  }
  j["rise_time"] = Number(m.rise_time);
  j["overshoot_percent"] = Number(m.overshoot_percent);
  j["settling_time"] = Number(m.settling_time);
  j["steady_state_error"] = Number(m.steady_state_error);
  j["first_move"] = Number(m.first_move);
  j["iae"] = m.iae;
  j["ise"] = m.ise;
  j["itae"] = m.itae;
  j["tv_u"] = m.tv_u;
  j["u_min"] = m.u_min;
  j["u_max"] = m.u_max;
  j["load_peak_deviation"] = Number(m.load_peak_deviation);
  j["load_recovery_time"] = Number(m.load_recovery_time);
  nlohmann::json steps = nlohmann::json::array();
  for (const StepMetrics& s : m.steps) {
    steps.push_back({{"time", s.time},
                     {"from", s.from},
                     {"to", s.to},
                     {"rise_time", Number(s.rise_time)},
                     {"overshoot_percent", Number(s.overshoot_percent)},
                     {"settling_time", Number(s.settling_time)},
                     {"steady_state_error", Number(s.steady_state_error)},
                     {"first_move", Number(s.first_move)}});
  }
  j["steps"] = steps;
  return j;
}

std::string Fmt(double v, const char* unit = "") {
  if (!std::isfinite(v)) return "-";
  return fmt::format("{:.4g}{}", v, unit);
}

void PrintTable(const std::vector<Run>& runs) {
  std::vector<std::pair<std::string, std::function<std::string(const Run&)>>> rows = {
      {"controller", [](const Run& r) { return r.result.controller; }},
      {"first move", [](const Run& r) { return Fmt(r.result.metrics.first_move); }},
      {"rise time 10-90 %", [](const Run& r) { return Fmt(r.result.metrics.rise_time, " s"); }},
      {"overshoot", [](const Run& r) { return Fmt(r.result.metrics.overshoot_percent, " %"); }},
      {"settling time 2 %", [](const Run& r) { return Fmt(r.result.metrics.settling_time, " s"); }},
      {"steady-state error", [](const Run& r) { return Fmt(r.result.metrics.steady_state_error); }},
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
    out << fmt::format("{:.6g},{:.10g}", t(k), runs[0].result.r(k));
    for (const Run& r : runs) {
      out << fmt::format(",{:.10g},{:.10g},{:.10g},{:.10g}", r.result.y(k), r.result.y_meas(k),
                         r.result.u(k), r.result.d(k));
    }
    out << "\n";
  }
  if (!out) throw DataError(fmt::format("{}: write failed", path));
}

void WritePlot(const std::string& path, const std::vector<Run>& runs) {
  Figure fig(2);
  fig.title = "Closed loop";
  Axes& ay = fig.axes(0);
  ay.ylabel = "Output y";
  Curve& sp = ay.AddStairs(runs[0].result.t, runs[0].result.r, "set-point");
  sp.color = Color{90, 90, 90};
  sp.style = LineStyle::kDashed;
  for (std::size_t i = 0; i < runs.size(); ++i)
    ay.AddLine(runs[i].result.t, runs[i].result.y, runs[i].label).color =
        PaletteColor(static_cast<int>(i));
  Axes& au = fig.axes(1);
  au.xlabel = "Time t [s]";
  au.ylabel = "Input u";
  for (std::size_t i = 0; i < runs.size(); ++i)
    au.AddStairs(runs[i].result.t, runs[i].result.u, runs[i].label).color =
        PaletteColor(static_cast<int>(i));
  fig.Save(path);
}

void Execute(const ControlCli& c) {
  PNEUMID_CHECK(c.Ts > 0.0 && std::isfinite(c.Ts), "--Ts must be positive, got {}", c.Ts);
  PNEUMID_CHECK(c.duration > 0.0, "--duration must be positive, got {}", c.duration);
  const TransferFunction model = ParseModelSpec(c.model);
  auto setpoint = ParseSignal(c.setpoint);
  ClosedLoopOptions cl;
  cl.duration = c.duration;
  cl.noise_std = c.noise;
  cl.seed = c.seed;
  for (const std::string& l : c.load_steps) cl.load_steps.push_back(ParseLoadStep(l));
  cl.actuator.u_min = c.u_min;
  cl.actuator.u_max = c.u_max;

  ControllerSpec base;
  base.type = ControllerTypeFromString(c.controller);
  base.limits.u_min = c.u_min;
  base.limits.u_max = c.u_max;
  base.limits.du_max = c.du_max;
  base.constrained = c.constrained;
  base.y_min = c.y_min;
  base.y_max = c.y_max;
  base.t_filter = c.t_filter;
  base.pid_rule = PidTuningRuleFromString(c.pid_rule);
  base.tau_c = c.tau_c;
  base.tuning.P = c.P;
  base.tuning.M = c.M;
  base.tuning.lambda = c.lambda;
  const bool explicit_settings = c.P > 0 || c.M > 0 || !std::isnan(c.lambda);
  if (!c.rule.empty()) {
    base.tuning.rule = TuningRuleFromString(c.rule);
  } else {
    base.tuning.rule = explicit_settings && c.P > 0 && c.M > 0 && !std::isnan(c.lambda)
                           ? TuningRule::kExplicit
                           : TuningRule::kShridharCooper;
  }

  std::vector<ControllerSpec> specs;
  std::vector<std::string> labels;
  if (c.compare_given) {
    std::string list = c.compare.empty() ? "shridhar-cooper,paper-modified" : c.compare;
    std::stringstream in(list);
    std::string item;
    while (std::getline(in, item, ',')) {
      ControllerSpec s = base;
      s.tuning = TuningOptions{};
      s.tuning.rule = TuningRuleFromString(item);
      specs.push_back(s);
      labels.push_back(ToString(s.tuning.rule));
    }
    PNEUMID_CHECK(!specs.empty(), "--compare: no settings given");
  } else {
    specs.push_back(base);
    labels.push_back(base.type == ControllerType::kPid ? "pid" : ToString(base.tuning.rule));
  }

  PlantOptions po;
  po.seed = c.seed;
  const std::string plant_spec = c.plant.empty() ? c.model : c.plant;
  std::vector<Run> runs;
  for (std::size_t i = 0; i < specs.size(); ++i) {
    Run run;
    run.label = labels[i];
    run.spec = specs[i];
    run.built = MakeController(model, c.Ts, specs[i]);
    auto plant = MakePlant(plant_spec, c.Ts, po);
    run.result = SimulateClosedLoop(*run.built.controller, *plant, *setpoint, cl);
    runs.push_back(std::move(run));
  }
  if (!c.output.empty()) WriteCsv(c.output, runs);
  if (!c.plot.empty()) WritePlot(c.plot, runs);
  if (c.json) {
    if (runs.size() == 1) {
      std::cout << RunJson(runs[0]).dump(2) << "\n";
    } else {
      nlohmann::ordered_json j;
      j["compare"] = nlohmann::json::array();
      for (const Run& r : runs) j["compare"].push_back(RunJson(r));
      std::cout << j.dump(2) << "\n";
    }
    return;
  }
  PrintTable(runs);
  for (const Run& r : runs) {
    if (r.spec.type != ControllerType::kPid)
      std::cout << r.label << ": " << r.built.tuning.formula << "\n";
  }
}

const Registrar reg(
    "control", "Closed-loop simulation of DMC, GPC or PID against a plant, with metrics",
    [](CLI::App& app) {
      auto c = std::make_shared<ControlCli>();
      app.add_option("--controller", c->controller, "dmc, gpc or pid")->capture_default_str();
      app.add_option("--model", c->model,
                     "Controller's model: fopdt-paper, arx-paper, fopdt:K=..,tau=..,theta=.., "
                     "tf:..., FILE.json")
          ->required();
      app.add_option("--plant", c->plant,
                     "Plant: ipa, ipa-position, or any model spec (default: the model itself)");
      app.add_option("--Ts", c->Ts, "Sample time in s")->capture_default_str();
      app.add_option("--rule", c->rule,
                     "Tuning rule: shridhar-cooper (conventional), paper-modified, explicit "
                     "(default: shridhar-cooper, or explicit when --P --M --lambda are all given)");
      app.add_option("--P", c->P, "Prediction horizon (samples)");
      app.add_option("--M", c->M, "Control horizon (samples)");
      app.add_option("--lambda", c->lambda, "Move suppression");
      app.add_option("--setpoint", c->setpoint, SignalSyntaxHelp())->required();
      app.add_option("--duration", c->duration, "Simulated time in s")->required();
      app.add_option("--u-min", c->u_min, "Lower input limit (e.g. 0 % duty)");
      app.add_option("--u-max", c->u_max, "Upper input limit (e.g. 100 % duty)");
      app.add_option("--du-max", c->du_max, "Largest input change per sample");
      app.add_flag("--constrained", c->constrained,
                   "DMC: optimize the moves under the limits (QDMC, QP solver) instead of "
                   "clipping");
      app.add_option("--y-min", c->y_min, "Soft lower output bound (with --constrained)");
      app.add_option("--y-max", c->y_max, "Soft upper output bound (with --constrained)");
      app.add_option("--noise", c->noise, "Measurement noise standard deviation (output units)");
      app.add_option("--seed", c->seed, "Noise seed")->capture_default_str();
      app.add_option("--load-step", c->load_steps,
                     "Load disturbance on the output: at=T,size=D (repeatable)");
      app.add_option("--t-filter", c->t_filter,
                     "GPC observer polynomial T: 1, A, or coefficients '1 -0.8'")
          ->capture_default_str();
      app.add_option("--pid-rule", c->pid_rule, "PID tuning: simc or imc")->capture_default_str();
      app.add_option("--tau-c", c->tau_c, "PID closed-loop time constant in s (0 = rule default)");
      app.add_flag("--json", c->json, "Print the metrics as JSON");
      app.add_option("--plot", c->plot, "Write a plot of output and input (.png or .svg)");
      app.add_option("-o,--output", c->output, "Write the trajectories to a CSV file");
      app.add_option("--compare", c->compare,
                     "Run several tuning rules on the same scenario, side by side (default: "
                     "shridhar-cooper,paper-modified)")
          ->expected(0, 1);
      app.callback([c, &app] {
        c->compare_given = app.count("--compare") > 0;
        Execute(*c);
      });
    });

}  // namespace
}  // namespace pneumid::cli
