// pneumid simulate: run an open-loop experiment on a simulated plant and write
// the data (time, input, output, and the plant's extra signals) to CSV or MAT.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/data/csv.hpp"
#include "pneumid/plant/experiment.hpp"
#include "pneumid/plant/ipa_simulator.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/plant/signal.hpp"
#include "progress.hpp"
#include "validators.hpp"

namespace pneumid::cli {
namespace {

struct SimulateArgs {
  std::string plant = "ipa";
  std::string input = "step:from=0.61,to=82,at=1.0";
  double duration = 4.0;
  double Ts = 0.01;
  std::uint64_t seed = 1;
  std::optional<double> noise;
  std::string plant_config;
  std::string mode;
  std::string output;
  bool json = false;
  bool progress = false;
};

void Run(const SimulateArgs& o) {
  PNEUMID_CHECK(o.Ts > 0.0 && std::isfinite(o.Ts), "--Ts must be positive, got {}", o.Ts);
  PNEUMID_CHECK(std::isfinite(o.duration) && o.duration >= o.Ts,
                "--duration must be at least one sample period (--Ts {}), got {}", o.Ts,
                o.duration);
  PlantOptions plant_options;
  plant_options.seed = o.seed;
  plant_options.noise_sigma = o.noise;
  plant_options.config_path = o.plant_config;
  if (!o.mode.empty()) plant_options.pwm_mode = PwmModeFromString(o.mode);
  auto plant = MakePlant(o.plant, o.Ts, plant_options);
  PNEUMID_CHECK(o.plant_config.empty() || dynamic_cast<IpaSimulator*>(plant.get()),
                "--plant-config applies to the ipa plant only, not to '{}'", o.plant);
  PNEUMID_CHECK(o.mode.empty() || dynamic_cast<IpaSimulator*>(plant.get()),
                "--mode applies to the ipa plant only, not to '{}'", o.plant);
  auto input = ParseSignal(o.input);

  ExperimentOptions options;
  options.input_channel = PlantInputChannel(*plant);
  options.output_channel = PlantOutputChannel(*plant);
  ProgressBar bar("simulating", o.progress || StderrIsTerminal());
  options.progress = [&bar](double f) { bar(f); };
  const auto start = std::chrono::steady_clock::now();
  const Experiment e = RunExperiment(*plant, *input, o.duration, options);
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  if (!o.output.empty()) {
    SaveExperiment(e, o.output);
  } else if (!o.json) {
    // No file: the data as CSV on stdout.
    CsvWriteOptions csv;
    csv.comments = {"plant: " + e.plant, "input: " + e.signal};
    WriteCsv(e.data, "/dev/stdout", e.extras, csv);
    return;
  }
  const Eigen::VectorXd y = e.data.y();
  const Eigen::VectorXd u = e.data.u();
  const double simulated = e.data.time()[e.data.size() - 1] - e.data.time()[0];
  if (o.json) {
    nlohmann::json j;
    j["plant"] = e.plant;
    j["input"] = e.signal;
    j["Ts"] = o.Ts;
    j["duration"] = simulated;
    j["samples"] = e.data.size();
    j["seed"] = o.seed;
    j["output_file"] = o.output.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.output);
    j["columns"] = nlohmann::json::array();
    j["columns"].push_back({{"name", "t"}, {"unit", "s"}});
    j["columns"].push_back(
        {{"name", options.input_channel.name}, {"unit", options.input_channel.unit}});
    j["columns"].push_back(
        {{"name", options.output_channel.name}, {"unit", options.output_channel.unit}});
    for (const auto& c : e.extras)
      j["columns"].push_back({{"name", c.channel.name}, {"unit", c.channel.unit}});
    j["y"] = {{"initial", y[0]},
              {"final", y[y.size() - 1]},
              {"min", y.minCoeff()},
              {"max", y.maxCoeff()},
              {"unit", options.output_channel.unit}};
    j["u"] = {{"min", u.minCoeff()}, {"max", u.maxCoeff()}, {"unit", options.input_channel.unit}};
    j["wall_time_s"] = wall;
    j["x_real_time"] = wall > 0 ? nlohmann::json(simulated / wall) : nlohmann::json(nullptr);
    std::cout << j.dump(2) << "\n";
    return;
  }
  const std::string yu =
      options.output_channel.unit.empty() ? "" : " " + options.output_channel.unit;
  std::cout << fmt::format("plant:   {}\n", e.plant);
  std::cout << fmt::format("input:   {}\n", e.signal);
  std::cout << fmt::format("samples: {} (Ts = {:g} s, {:g} s)\n", e.data.size(), o.Ts, simulated);
  std::cout << fmt::format("output:  y from {:.6g}{} to {:.6g}{} (min {:.6g}, max {:.6g})\n", y[0],
                           yu, y[y.size() - 1], yu, y.minCoeff(), y.maxCoeff());
  std::cout << fmt::format("written: {}\n", o.output);
  std::cout << fmt::format("speed:   {:.0f}x real time ({:.3g} s wall)\n",
                           wall > 0 ? simulated / wall : 0.0, wall);
}

static Registrar reg(
    "simulate", "Run an open-loop experiment on a simulated plant (IPA physics or a linear model)",
    [](CLI::App& app) {
      auto o = std::make_shared<SimulateArgs>();
      app.add_option("--plant", o->plant,
                     "Plant: ipa, ipa-position, ipa:config=FILE.toml, arx-paper, MODEL.json, "
                     "fopdt:K=..,tau=..,theta=.. (see below)")
          ->capture_default_str();
      app.add_option("--input", o->input, "Input signal spec (see below)")->capture_default_str();
      app.add_option("--duration", o->duration, "Length of the experiment in s")
          ->capture_default_str()
          ->check(Positive());
      AddSampleTimeOption(app, o->Ts, "Sample period in s");
      app.add_option("--seed", o->seed, "Seed of the noise generators (runs are reproducible)")
          ->capture_default_str();
      app.add_option("--noise", o->noise,
                     "Measurement noise standard deviation in output units (N or m for the IPA, "
                     "replacing its configured sensor noise; default: none for linear models)")
          ->check(NonNegative());
      app.add_option("--plant-config", o->plant_config,
                     "IPA parameter file (TOML, see config/ipa_default.toml)");
      app.add_option("--mode", o->mode,
                     "IPA PWM simulation: pwm (every valve switching event, the default) or "
                     "averaged (mean valve flows, faster)")
          ->check(CLI::IsMember({"pwm", "switching", "averaged"}));
      app.add_option("-o,--output", o->output,
                     "Data file to write: .csv (t, u, y and extra columns such as p_a, p_b) or "
                     ".mat (variables t, u, y, p_a, ...); without it the CSV goes to stdout");
      app.add_flag("--json", o->json, "Print a JSON summary on stdout");
      app.add_flag("--progress", o->progress,
                   "Draw the progress bar even when stderr is not a terminal");
      app.footer(SignalSyntaxHelp() + "\n" + PlantSpecHelp() +
                 "\nExample:\n  pneumid simulate --plant ipa --input step:from=0.61,to=82,at=1.0 "
                 "--duration 4 --Ts 0.01 -o data.csv\n");
      app.callback([o]() { Run(*o); });
    });

}  // namespace
}  // namespace pneumid::cli
