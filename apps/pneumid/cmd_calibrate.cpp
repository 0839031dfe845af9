// pneumid calibrate DATA [DATA ...]: grey-box identification of the IPA
// simulator's physical parameters from measured experiments (the digital twin
// of one actuator); writes a parameter TOML for --plant-config / ipa:config=.
#include <algorithm>
#include <fstream>
#include <iostream>
#include <memory>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "data_options.hpp"
#include "output_options.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/strings.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/nonlinear/ipa_calibration.hpp"
#include "pneumid/report/plot.hpp"
#include "progress.hpp"

namespace pneumid::cli {
namespace {

struct CalibrateArgs {
  std::vector<std::string> files;
  std::vector<std::string> validation;
  std::vector<double> weights;
  DataOptions data;
  std::string plant_config;
  std::string mode;      // force|position; empty: the config's
  std::string pwm_mode;  // switching|averaged; empty: the config's
  std::string free;
  std::vector<std::string> bounds;
  std::string initial_state = "measured";
  int max_iterations = 100;
  int threads = 2;
  std::string output;
  std::string plot;
  bool json = false;
  bool progress = false;
};

std::pair<std::string, std::pair<double, double>> ParseBound(const std::string& text) {
  const auto eq = text.find('=');
  const auto colon = text.find(':', eq == std::string::npos ? 0 : eq);
  PNEUMID_CHECK(eq != std::string::npos && colon != std::string::npos,
                "--bound '{}': expected NAME=LOWER:UPPER, e.g. bore=0.01:0.03", Excerpt(text));
  const auto lo = ParseDouble(text.substr(eq + 1, colon - eq - 1));
  const auto hi = ParseDouble(text.substr(colon + 1));
  PNEUMID_CHECK(lo && hi, "--bound '{}': LOWER and UPPER must be numbers", Excerpt(text));
  return {text.substr(0, eq), {*lo, *hi}};
}

std::string FormatValue(double v, double sd, const std::string& unit) {
  if (std::isfinite(sd)) return fmt::format("{:.6g} +- {:.2g} {}", v, sd, unit);
  return fmt::format("{:.6g} {} (std n/a)", v, unit);
}

/// The calibration options of the command line (without progress callback).
IpaCalibrationOptions CalibrationOptions(const CalibrateArgs& args) {
  IpaCalibrationOptions options;
  // --mode position starts from the position rig's defaults (a file's keys
  // replace them), as `--plant ipa-position` does.
  const IpaMode mode = args.mode.empty() ? IpaMode::kForce : IpaModeFromString(args.mode);
  options.start = args.plant_config.empty() ? DefaultIpaParameters(mode)
                                            : LoadIpaParameters(args.plant_config, mode);
  if (!args.mode.empty()) options.start.mode = mode;
  if (!args.pwm_mode.empty()) options.start.pwm_mode = PwmModeFromString(args.pwm_mode);
  if (!args.free.empty())
    for (const auto& name : Split(args.free, ','))
      if (!Trim(name).empty()) options.free.emplace_back(Trim(name));
  for (const auto& bound : args.bounds) options.bounds.insert(ParseBound(bound));
  options.initial_state = CalibrationInitialStateFromString(args.initial_state);
  options.max_iterations = args.max_iterations;
  options.num_threads = args.threads;
  return options;
}

/// The data file `path`, read with the command's data options.
Dataset LoadDataFile(const CalibrateArgs& args, const std::string& path) {
  DataOptions data = args.data;
  data.path = path;
  Dataset loaded = LoadFromOptions(data);
  RequireSingleInputOutput(loaded, data, "calibrate");
  return loaded;
}

/// The experiments to calibrate on, each with its weight.
std::vector<CalibrationExperiment> LoadExperiments(const CalibrateArgs& args) {
  PNEUMID_CHECK(args.weights.empty() || args.weights.size() == args.files.size(),
                "--weights: {} weights for {} data files; give one per file, in their order",
                args.weights.size(), args.files.size());
  std::vector<CalibrationExperiment> experiments;
  for (std::size_t i = 0; i < args.files.size(); ++i) {
    experiments.push_back({LoadDataFile(args, args.files[i]), args.files[i],
                           args.weights.empty() ? 1.0 : args.weights[i]});
  }
  return experiments;
}

/// The calibrated twin on the held-out experiments.
struct HeldOutResults {
  std::vector<Dataset> data;               ///< one per --validation file
  std::vector<double> fit;                 ///< NRMSE fit in %, when the calibration succeeded
  std::vector<Eigen::VectorXd> simulated;  ///< the twin's output, likewise
};

/// Simulates the calibrated twin on the held-out experiments (none when the
/// calibration failed).
void SimulateHeldOut(const IpaCalibrationOptions& options, const IpaCalibrationSummary& summary,
                     HeldOutResults& held_out) {
  if (summary.termination == Termination::kFailure) return;
  for (const auto& data : held_out.data) {
    held_out.simulated.push_back(SimulateIpaOnData(summary.parameters, data, options.initial_state,
                                                   options.warmup, options.integration_tolerance));
    held_out.fit.push_back(NrmseFit(data.y(0), held_out.simulated.back()));
  }
}

/// Writes the calibrated parameters as TOML, with a comment saying where they come from.
void WriteTwin(const std::string& path, const IpaCalibrationSummary& summary) {
  std::string comment =
      fmt::format("IPA parameters calibrated by `pneumid calibrate` ({}, {} iterations) from:",
                  ToString(summary.termination), summary.iterations);
  for (const auto& e : summary.experiments)
    comment += fmt::format("\n  {} (fit {:.2f} %)", e.name, e.fit_percent);
  std::string free;
  for (const auto& e : summary.estimates) free += (free.empty() ? "" : ", ") + e.name;
  comment += "\nfree parameters: " + free;
  std::ofstream out(path);
  if (!out) throw DataError(fmt::format("{}: cannot open for writing", path));
  out << IpaParametersToToml(summary.parameters, comment);
  if (!out) throw DataError(fmt::format("{}: write failed", path));
}

/// Plots measured and simulated output: one panel per experiment, then the
/// held-out ones, at most four panels.
void PlotCalibration(const CalibrateArgs& args, const IpaCalibrationOptions& options,
                     const IpaCalibrationSummary& summary,
                     const std::vector<CalibrationExperiment>& experiments,
                     const HeldOutResults& held_out) {
  const std::size_t fitted = std::min<std::size_t>(summary.experiments.size(), 3);
  const std::size_t shown_held_out = std::min<std::size_t>(held_out.simulated.size(), 4 - fitted);
  Figure fig(static_cast<int>(fitted + shown_held_out));
  fig.title = "IPA twin calibration: measured and simulated output";
  const std::string ylabel =
      options.start.mode == IpaMode::kForce ? "Force F [N]" : "Position x [m]";
  auto panel = [&](std::size_t i, const std::string& title, const Dataset& data,
                   const Eigen::VectorXd& simulated) {
    auto& ax = fig.axes(static_cast<int>(i));
    ax.title = title;
    ax.xlabel = "Time t [s]";
    ax.ylabel = ylabel;
    ax.AddLine(data.time(), data.y(0), "measured");
    if (simulated.size() == data.size()) ax.AddLine(data.time(), simulated, "calibrated twin");
  };
  for (std::size_t i = 0; i < fitted; ++i) {
    const auto& e = summary.experiments[i];
    panel(i,
          fmt::format("{}: fit {:.2f} % (start {:.2f} %)", e.name, e.fit_percent,
                      e.initial_fit_percent),
          experiments[i].data, e.simulated);
  }
  for (std::size_t i = 0; i < shown_held_out; ++i)
    panel(fitted + i,
          fmt::format("{} (held out): fit {:.2f} %", args.validation[i], held_out.fit[i]),
          held_out.data[i], held_out.simulated[i]);
  fig.Save(args.plot);
}

void PrintJson(const CalibrateArgs& args, const IpaCalibrationOptions& options,
               const IpaCalibrationSummary& summary, const std::vector<double>& validation_fit) {
  nlohmann::ordered_json j;
  nlohmann::ordered_json params = nlohmann::ordered_json::object();
  for (const auto& e : summary.estimates)
    params[e.name] = {{"value", e.value},           {"std", JsonNumber(e.std)}, {"unit", e.unit},
                      {"start", e.start},           {"lower", e.lower},         {"upper", e.upper},
                      {"determined", e.determined}, {"at_bound", e.at_bound}};
  j["parameters"] = params;
  nlohmann::ordered_json experiments = nlohmann::ordered_json::array();
  for (const auto& e : summary.experiments)
    experiments.push_back({{"file", e.name},
                           {"samples", e.samples},
                           {"fit_percent", JsonNumber(e.fit_percent)},
                           {"initial_fit_percent", JsonNumber(e.initial_fit_percent)}});
  j["experiments"] = experiments;
  nlohmann::ordered_json validation = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < validation_fit.size(); ++i)
    validation.push_back(
        {{"file", args.validation[i]}, {"fit_percent", JsonNumber(validation_fit[i])}});
  j["validation"] = validation;
  nlohmann::ordered_json correlations = nlohmann::ordered_json::array();
  for (const auto& c : summary.correlations)
    correlations.push_back(
        {{"first", c.first}, {"second", c.second}, {"correlation", c.correlation}});
  j["correlations"] = correlations;
  j["warnings"] = summary.warnings;
  j["termination"] = ToString(summary.termination);
  j["message"] = summary.message;
  j["iterations"] = summary.iterations;
  j["initial_cost"] = JsonNumber(summary.initial_cost);
  j["final_cost"] = JsonNumber(summary.final_cost);
  j["simulations"] = summary.simulations;
  j["seconds"] = summary.seconds;
  j["mode"] = ToString(options.start.mode);
  j["pwm_mode"] = ToString(options.start.pwm_mode);
  j["initial_state"] = ToString(options.initial_state);
  if (!args.output.empty() && summary.termination != Termination::kFailure)
    j["output"] = args.output;
  if (!args.plot.empty()) j["plot"] = args.plot;
  std::cout << j.dump(2) << "\n";
}

void PrintText(const CalibrateArgs& args, const IpaCalibrationOptions& options,
               const IpaCalibrationSummary& summary, const std::vector<double>& validation_fit) {
  std::cout << fmt::format(
      "IPA calibration ({} mode, {} PWM): {} after {} iterations, "
      "{} simulations, {:.2f} s\n",
      ToString(options.start.mode), ToString(options.start.pwm_mode), ToString(summary.termination),
      summary.iterations, summary.simulations, summary.seconds);
  if (!summary.message.empty()) std::cout << "  " << summary.message << "\n";
  if (!summary.experiments.empty()) std::cout << "experiments (NRMSE fit, start -> calibrated):\n";
  for (const auto& e : summary.experiments)
    std::cout << fmt::format("  {:<30} {:>7} samples  {:7.2f} % -> {:7.2f} %\n", e.name, e.samples,
                             e.initial_fit_percent, e.fit_percent);
  for (std::size_t i = 0; i < validation_fit.size(); ++i)
    std::cout << fmt::format("  {:<30} validation          {:7.2f} %\n", args.validation[i],
                             validation_fit[i]);
  if (!summary.estimates.empty()) std::cout << "parameters (value +- standard deviation):\n";
  for (const auto& e : summary.estimates)
    std::cout << fmt::format("  {:<32} {}{}\n", e.name, FormatValue(e.value, e.std, e.unit),
                             e.determined ? "" : "  (not determined by the data)");
  for (const auto& c : summary.correlations)
    std::cout << fmt::format("correlated: {} and {}: {:+.3f}\n", c.first, c.second, c.correlation);
  if (!args.output.empty() && summary.termination != Termination::kFailure)
    std::cout << "twin written to " << args.output << "\n";
  if (!args.plot.empty()) std::cout << "plot written to " << args.plot << "\n";
}

void Run(const CalibrateArgs& args) {
  IpaCalibrationOptions options = CalibrationOptions(args);
  const std::vector<CalibrationExperiment> experiments = LoadExperiments(args);
  ProgressBar bar("calibrate", args.progress || StderrIsTerminal());
  options.progress = [&](int iteration, double cost) {
    bar(std::min(1.0, static_cast<double>(iteration) / std::max(1, args.max_iterations)),
        fmt::format("iteration {}, cost {:.4g}", iteration, cost));
  };
  HeldOutResults held_out;
  for (const auto& file : args.validation) held_out.data.push_back(LoadDataFile(args, file));
  const IpaCalibrationSummary summary = CalibrateIpa(experiments, options);
  options.progress = nullptr;
  SimulateHeldOut(options, summary, held_out);

  if (summary.termination != Termination::kFailure && !args.output.empty()) {
    WriteTwin(args.output, summary);
  }
  if (!args.plot.empty() && !summary.experiments.empty()) {
    PlotCalibration(args, options, summary, experiments, held_out);
  }
  if (args.json) {
    PrintJson(args, options, summary, held_out.fit);
  } else {
    PrintText(args, options, summary, held_out.fit);
  }
  for (const auto& w : summary.warnings) std::cerr << "pneumid calibrate: warning: " << w << "\n";
  if (summary.termination == Termination::kFailure) {
    std::cerr << "pneumid calibrate: error: " << summary.message << "\n";
    throw ExitCode{1};
  }
}

static Registrar reg(
    "calibrate",
    "Calibrate the IPA simulator's physical parameters to measured experiments (grey-box "
    "identification) and write the twin's parameter TOML",
    [](CLI::App& app) {
      auto args = std::make_shared<CalibrateArgs>();
      app.add_option("DATA", args->files,
                     "Measured experiments (CSV or .mat; steps, staircases, PRBS), each with its "
                     "own initial state; input: PWM duty in %, output: force in N (or position "
                     "in m)")
          ->required()
          ->check(CLI::ExistingFile);
      app.add_option("--validation", args->validation,
                     "Held-out experiments (repeatable): the calibrated twin's fit on each is "
                     "reported, they are not used for the estimate")
          ->check(CLI::ExistingFile);
      AddDataOptions(app, args->data, /*positional=*/false);
      app.add_option("--plant-config", args->plant_config,
                     "Starting parameters and fixed values (TOML as config/ipa_default.toml); "
                     "default: the built-in twin")
          ->check(CLI::ExistingFile);
      app.add_option("--mode", args->mode,
                     "force or position (default: the config's; position starts from the position "
                     "rig's defaults)")
          ->check(CLI::IsMember({"force", "position"}));
      app.add_option("--pwm", args->pwm_mode,
                     "PWM simulation: switching or averaged (default: the config's)")
          ->check(CLI::IsMember({"switching", "averaged", "pwm", "average"}));
      app.add_option("--free", args->free,
                     "Comma-separated parameters to estimate (TOML keys such as "
                     "valves.inlet_conductance or unique last parts such as bore); default "
                     "force mode: inlet/exhaust conductance and critical ratio, bore, open "
                     "delay, and the sensor filter's time constant when the starting twin has "
                     "one, as the default twin does (position mode adds mass, viscous and "
                     "Coulomb friction)");
      app.add_option("--weights", args->weights,
                     "Weight of each experiment in the cost, one per DATA file in their order "
                     "(comma-separated; default 1 each: every experiment counts by its fit)")
          ->delimiter(',')
          ->check(CLI::PositiveNumber);
      app.add_option("--bound", args->bounds,
                     "NAME=LOWER:UPPER replaces the physical range of a free parameter "
                     "(repeatable)");
      app.add_option("--initial-state", args->initial_state,
                     "Start of each experiment's simulation: measured (the state the first "
                     "output shows) or steady (the steady state of the first input)")
          ->capture_default_str()
          ->check(CLI::IsMember({"measured", "steady"}));
      app.add_option("--max-iterations", args->max_iterations, "Levenberg-Marquardt iterations")
          ->capture_default_str()
          ->check(CLI::Range(0, 100000));
      app.add_option("--threads", args->threads, "Threads for the simulations of the Jacobian")
          ->capture_default_str()
          ->check(CLI::Range(1, 256));
      app.add_option("-o,--output", args->output,
                     "Write the calibrated twin as TOML (for --plant-config / ipa:config=FILE)");
      AddPlotOption(app, args->plot, "measured and simulated output of each experiment");
      app.add_flag("--json", args->json, "Print the results as JSON");
      app.add_flag("--progress", args->progress,
                   "Draw the progress bar on stderr even when it is not a terminal");
      app.callback([args] { Run(*args); });
    });

}  // namespace
}  // namespace pneumid::cli
