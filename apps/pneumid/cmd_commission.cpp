// pneumid commission: from a plant to a verified controller in one command
// (workflow/commission.hpp): experiment, identification, design to a
// specification, verification on the plant, and the files to run it.
//
//   pneumid commission --plant ipa -o out/ [--range 10:180] [--budget 120]
//       [--controller mpc] [--spec overshoot=5,settling=0.5] [--json]
//
// DIR receives data.csv (the whole experiment), models.json (every model,
// ranked on the held-out part), controller.toml (a complete configuration
// that control, run and codegen take with --config), verification.csv, the
// plots experiment.png, validation.png and verification.png, and c/ (the
// controller as C99, as `pneumid codegen --config DIR/controller.toml`).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <iostream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/spec.hpp"
#include "pneumid/plant/actuator.hpp"
#include "pneumid/plant/ipa_simulator.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/realtime/io_factory.hpp"
#include "pneumid/realtime/io_plant.hpp"
#include "pneumid/realtime/realtime_config.hpp"
#include "pneumid/workflow/commission.hpp"
#include "pneumid/workflow/commission_files.hpp"
#include "progress.hpp"
#include "validators.hpp"

namespace pneumid::cli {
namespace {

std::atomic<bool> g_stop{false};
extern "C" void OnStopSignal(int) { g_stop.store(true); }

struct CommissionArgs {
  std::string io = "sim";
  std::string config;
  bool fast = false;
  std::string input_gaps = "plant";
  std::string plant = "ipa";
  std::string plant_config;
  double Ts = 0.01;
  CLI::Option* ts_option = nullptr;  // --Ts, to tell a default from a given period
  std::uint64_t seed = 1;
  std::optional<double> noise;
  std::string range;
  std::string spec;
  std::string methods;
  CommissionOptions options;
  std::string directory;
  bool json = false;
  bool report = false;
  bool progress = false;
};

// "LO:HI" -> the two numbers.
void ParseRange(const std::string& text, double& lo, double& hi) {
  const auto colon = text.find(':');
  PNEUMID_CHECK(colon != std::string::npos, "--range: expected LO:HI, got '{}'", text);
  try {
    std::size_t used = 0;
    const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
    lo = std::stod(a, &used);
    PNEUMID_CHECK(used == a.size(), "--range: '{}' is not a number", a);
    hi = std::stod(b, &used);
    PNEUMID_CHECK(used == b.size(), "--range: '{}' is not a number", b);
  } catch (const std::logic_error&) {
    throw InvalidArgument(fmt::format("--range: expected LO:HI with numbers, got '{}'", text));
  }
  PNEUMID_CHECK(std::isfinite(lo) && std::isfinite(hi) && lo < hi,
                "--range: LO must be below HI, got '{}'", text);
}

// "overshoot=5,settling=0.5" -> the specification.
void ParseSpecification(const std::string& text, CommissionOptions& o) {
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const auto eq = item.find('=');
    PNEUMID_CHECK(eq != std::string::npos, "--spec: expected KEY=VALUE, got '{}'", item);
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    double v = 0.0;
    try {
      std::size_t used = 0;
      v = std::stod(value, &used);
      PNEUMID_CHECK(used == value.size(), "--spec: {}: '{}' is not a number", key, value);
    } catch (const std::logic_error&) {
      throw InvalidArgument(fmt::format("--spec: {}: '{}' is not a number", key, value));
    }
    if (key == "overshoot")
      o.overshoot = v;
    else if (key == "settling")
      o.settling = v;
    else
      throw InvalidArgument(
          fmt::format("--spec: unknown key '{}' (expected overshoot, settling)", key));
  }
}

// `value` formatted as `spec` with `unit`, or `none` when it is NaN (a
// quantity the run did not measure or that has no value: an unsettled step's
// settling time, an integrating plant's time constant).
std::string Measured(double value, const char* spec, const char* unit, const char* none) {
  return std::isnan(value) ? std::string(none)
                           : fmt::format(fmt::runtime(spec), value) + unit;
}

void PrintSummary(const CommissionResult& r, const std::string& dir, double spec_overshoot) {
  const auto& ex = r.experiment;
  std::cout << fmt::format("commission {}: {}\n", ToString(r.termination), r.message);
  if (!std::isfinite(ex.gain)) {
    // Stopped during the probe step: nothing was measured yet.
    std::cout << fmt::format("experiment: {:.1f} s of plant time; stopped in the probe step\n",
                             ex.duration);
  } else {
    const std::string reachable =
        std::isnan(ex.reachable_min) || std::isnan(ex.reachable_max)
            ? std::string("reachable range not measured")
            : fmt::format("reachable {:.4g}..{:.4g}", ex.reachable_min, ex.reachable_max);
    const std::string range = std::isnan(ex.range_min) || std::isnan(ex.range_max)
                                  ? std::string("no range")
                                  : fmt::format("range {:.4g}..{:.4g}", ex.range_min, ex.range_max);
    std::cout << fmt::format(
        "experiment: {:.1f} s of plant time; probe K = {:.4g}, tau = {}, theta = {}; {}, {}; "
        "{} + {} levels of {}\n",
        ex.duration, ex.gain, Measured(ex.time_constant, "{:.3g}", " s", "none (integrating)"),
        Measured(ex.dead_time, "{:.3g}", " s", "not measured"), reachable, range,
        ex.estimation_levels.size(), ex.validation_levels.size(),
        Measured(ex.dwell, "{:.3g}", " s", "no dwell yet"));
  }
  if (!r.identification.models.empty()) {
    std::cout << "models (ranked on the held-out part):\n";
    for (const IdentifiedModel& m : r.identification.models)
      std::cout << fmt::format("  {:<14} estimation {:7.2f} %  held-out {:7.2f} %{}\n", m.method,
                               m.fit_percent, m.validation_fit_percent,
                               m.method == r.chosen_model ? "  <- chosen" : "");
  }
  if (!r.chosen_model.empty()) std::cout << "chosen: " << r.chosen_reason << "\n";
  for (const CommissionAttempt& a : r.attempts) {
    const ClosedLoopMetrics& m = a.result.metrics;
    // A peak above the specification that the ripple explains: say what was judged.
    const std::string judged =
        m.overshoot_percent > spec_overshoot &&
                a.overshoot_judged_percent < m.overshoot_percent - 0.005
            ? fmt::format(" ({:.2f} % beyond half the ripple)", a.overshoot_judged_percent)
            : std::string();
    std::cout << fmt::format(
        "verification (aggressiveness {:g}): worst overshoot {:.2f} %{}, worst settling {}, "
        "IAE {:.4g}: {}\n",
        a.aggressiveness, m.overshoot_percent, judged,
        Measured(m.settling_time, "{:.3f}", " s", "not settled"), m.iae,
        a.passed ? "pass" : "fail");
    for (const std::string& f : a.failures) std::cout << "  - " << f << "\n";
  }
  for (const std::string& l : r.limits) std::cout << "limit: " << l << "\n";
  for (const std::string& s : r.suggestions) std::cout << "try: " << s << "\n";
  std::cout << fmt::format("plant time {:.1f} s; files in {}\n", r.plant_time, dir);
}

void Run(CommissionArgs& c) {
  PNEUMID_CHECK(c.Ts > 0.0 && std::isfinite(c.Ts), "--Ts must be positive, got {}", c.Ts);
  CommissionOptions& o = c.options;
  if (!c.range.empty()) ParseRange(c.range, o.range_min, o.range_max);
  if (!c.methods.empty()) o.methods = ParseMethodList(c.methods);
  std::filesystem::create_directories(c.directory);
  o.directory = c.directory;
  PlantOptions po;
  po.seed = c.seed;
  po.noise_sigma = c.noise;
  po.config_path = c.plant_config;
  // The plant: the simulator itself, or one behind an I/O backend (--io).
  const IoSpec io = ParseIoSpec(c.io);
  std::unique_ptr<Plant> plant;
  if (io.kind == IoKind::kSim) {
    // An IPA loop samples once per PWM period, the valves' fastest action
    // (docs/position.md, docs/commission.md): the duty modulation across the
    // valves' gaps then alternates per period, not per 10 ms.
    CommissionPlant made = MakeCommissionPlant(
        c.plant, c.ts_option->count() ? std::optional<double>(c.Ts) : std::nullopt, po, c.Ts);
    plant = std::move(made.plant);
    c.Ts = made.Ts;
    PNEUMID_CHECK(c.plant_config.empty() || dynamic_cast<IpaSimulator*>(plant.get()),
                  "--plant-config applies to the ipa plant only, not to '{}'", c.plant);
  } else {
    PNEUMID_CHECK(!c.fast || io.kind == IoKind::kUdp,
                  "--fast needs --io sim or udp://HOST:PORT (a plant server steps on request); "
                  "a comedi card runs in real time");
    RealtimeConfig config = c.config.empty() ? RealtimeConfig{} : LoadRealtimeConfig(c.config);
    config.loop.period = c.Ts;
    // Without --Ts the loop runs at the plant server's period (a card takes any).
    config.udp.adopt_server_period = !c.ts_option->count();
    if (c.fast) {
      // Not bound to the clock: wait for late replies (a loaded machine) rather
      // than count them as missed; a server silent for 100 periods is a fault.
      config.udp.reply_wait = 0.9;
      config.udp.max_missed = std::max(config.udp.max_missed, 100);
    }
    auto io_plant = std::make_unique<IoPlant>(MakeIoBackend(io, config, po), c.Ts, !c.fast);
    c.Ts = io_plant->Ts();
    o.actuator = io_plant->actuator();
    plant = std::move(io_plant);
  }
  // The plant's default specification (a positioning drive's is 2 % and 1 s),
  // unless --spec says otherwise.
  SetDefaultSpecification(o, PlantActuator(*plant));
  if (!c.spec.empty()) ParseSpecification(c.spec, o);
  SetInputGaps(o, *plant, c.input_gaps);
  // A plant behind a card (or a plant server older than the Info message)
  // does not report its valves' gaps: without them the experiment and the
  // loop hold inputs the valves cannot (docs/commission.md).
  if (io.kind != IoKind::kSim && c.input_gaps == "plant" && o.actuator &&
      o.actuator->input_gaps.empty())
    std::cerr << "pneumid commission: warning: the plant behind " << c.io
              << " reports no input gaps; a PWM valve's minimum pulse leaves some (the "
                 "IPA's at 300 Hz: --input-gaps 0:15,85:100), which are then not modulated "
                 "across\n";
  ProgressBar bar("commission", c.progress || StderrIsTerminal());
  o.progress = [&bar](const std::string& stage, double f) { bar(f, stage); };
  g_stop.store(false);
  o.stop = &g_stop;
  std::signal(SIGINT, OnStopSignal);
  std::signal(SIGTERM, OnStopSignal);
  const CommissionResult r = Commission(*plant, o);
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);

  const Actuator act = o.actuator ? *o.actuator : PlantActuator(*plant);
  CommissionFilesOptions fo;
  fo.directory = c.directory;
  fo.Ts = c.Ts;
  fo.io = c.io;
  fo.plant = c.plant_config.empty()
                 ? c.plant
                 : c.plant + ":config=" + std::filesystem::absolute(c.plant_config).string();
  fo.plant_description = plant->Describe();
  fo.report = c.report;
  const CommissionFiles files = WriteCommissionFiles(r, act, fo);
  const std::string& c_module = files.c_module;
  if (c.json) {
    nlohmann::ordered_json j = r.ToJson();
    j["directory"] = c.directory;
    j["c_module"] = c_module;
    std::cout << j.dump(2) << "\n";
  } else {
    PrintSummary(r, c.directory, o.overshoot);
    if (!c_module.empty()) std::cout << "C module: " << c_module << "\n";
  }
  if (r.termination == Termination::kStopped) throw ExitCode{130};
  if (r.termination == Termination::kFailure) {
    std::cerr << "pneumid commission: error: " << r.message << "\n";
    throw ExitCode{1};
  }
  if (!r.passed()) throw ExitCode{4};
}

const Registrar reg(
    "commission",
    "From a plant to a verified controller: experiment, identification, design, verification",
    [](CLI::App& app) {
      auto c = std::make_shared<CommissionArgs>();
      app.add_option("--plant", c->plant,
                     "Plant of the simulator (--io sim): ipa, ipa:config=FILE.toml or a model "
                     "spec")
          ->capture_default_str();
      app.add_option("--io", c->io,
                     "Where the plant is: sim (the simulator, --plant), udp://HOST:PORT (a plant "
                     "server) or comedi[:/dev/comediN] (the rig)")
          ->capture_default_str();
      app.add_option("--config", c->config,
                     "Real-time configuration (TOML) of the udp or comedi backend");
      app.add_flag("--fast", c->fast,
                   "udp: step the plant server as fast as it answers instead of in real time "
                   "(late replies are waited for, up to 0.9 period, and 100 missed in a row "
                   "are a fault)");
      app.add_option("--input-gaps", c->input_gaps,
                     "Inputs the actuator cannot hold, modulated across: plant (the plant's own, "
                     "IPA 0:15,85:100 from its valves), none, or LO:HI[,LO:HI]")
          ->capture_default_str();
      app.add_option("--plant-config", c->plant_config,
                     "IPA parameter file (TOML, see config/ipa_default.toml)");
      c->ts_option =
          AddSampleTimeOption(app, c->Ts,
                              "Sample period in s (default 0.01; an IPA: its PWM period, or the "
                              "smallest multiple of it of at least 3 ms; udp: the plant "
                              "server's)");
      app.add_option("--range", c->range,
                     "Output range LO:HI the controller must serve (default: the reachable "
                     "range found by the sweep, less 5 % at each end)");
      app.add_option("--budget", c->options.budget,
                     "Plant time in s for the experiment and the verification runs (the first "
                     "design's and the redesigns')")
          ->capture_default_str()
          ->check(Positive());
      app.add_option("--controller", c->options.controller, "Controller: mpc, dmc, gpc or pid")
          ->capture_default_str()
          ->check(CLI::IsMember({"mpc", "dmc", "gpc", "pid"}));
      app.add_option("--spec", c->spec,
                     "Specification: overshoot=PERCENT,settling=SECONDS (default "
                     "overshoot=5,settling=0.5; an integrating plant, such as the IPA in position "
                     "mode: overshoot=2,settling=1)");
      app.add_option("--aggressiveness", c->options.aggressiveness,
                     "First design's aggressiveness, 0 robust .. 1 aggressive")
          ->capture_default_str();
      app.add_option("-m,--method,--methods", c->methods,
                     "Candidate identification methods (default arx,oe,n4sid,hammerstein,"
                     "affine-narx)");
      app.add_option("--u-min", c->options.u_min, "Lowest input (default: the plant's range)");
      app.add_option("--u-max", c->options.u_max, "Highest input (default: the plant's range)");
      app.add_option("--y-min", c->options.y_min, "Safety: lowest output allowed");
      app.add_option("--y-max", c->options.y_max, "Safety: highest output allowed");
      app.add_option("--seed", c->seed, "Seed of the plant's noise and of the level order")
          ->capture_default_str();
      app.add_option("--noise", c->noise, "Measurement noise of the simulated plant")
          ->check(NonNegative());
      app.add_option("-o,--output", c->directory,
                     "Directory for data.csv, models.json, controller.toml, verification.csv "
                     "and the plots")
          ->required();
      app.add_flag("--json", c->json, "Print the result as JSON");
      app.add_flag("--report", c->report,
                   "Also write DIR/report.html: the experiment, the models, every verification "
                   "with its figure and per-step table, what limits the loop");
      app.add_flag("--progress", c->progress,
                   "Draw the progress bar even when stderr is not a terminal");
      app.callback([c] {
        c->options.seed = c->seed;
        Run(*c);
      });
    });

}  // namespace
}  // namespace pneumid::cli
