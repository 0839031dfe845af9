// pneumid codegen: a controller designed as for `pneumid control`, written as
// an embedded C99 module (NAME.h, NAME.c, README.md) for a microcontroller.
//
//   pneumid codegen --controller dmc --model fopdt-paper --plant ipa --Ts 0.01
//       --P 126 --M 5 --lambda 2.25 --precision float --prefix ipa_dmc -o firmware/
//   pneumid codegen --controller mpc --model fopdt-paper --Ts 0.01 --u-min 0 --u-max 100
//       --du-max 4 --max-ram 8192 -o out/ --json
//   --with-plant NAME also writes the controller's model as a linear plant
//   module NAME.h/NAME.c (plant_codegen.hpp), for closed-loop runs on a board
//   or in an emulator (examples/cortex-m4).
#include <cmath>
#include <iostream>
#include <memory>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "controller_options.hpp"
#include "pneumid/codegen/c_codegen.hpp"
#include "pneumid/codegen/plant_codegen.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/control/controller_factory.hpp"
#include "pneumid/control/mpc.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "validators.hpp"

namespace pneumid::cli {
namespace {

struct CodegenArgs {
  ControllerSettings controller;
  std::string model;
  std::string config;
  std::string plant;
  double Ts = 0.01;
  std::string precision = "double";
  std::string prefix = "pneumid_ctrl";
  std::string output;
  std::size_t max_ram = 0;
  int qp_max_iterations = -1;
  double cpu_mhz = 0.0;
  double period = 0.0;
  double utilization = 0.5;
  double cycles_per_instruction = 1.5;
  std::string with_plant;
  bool json = false;
};

void Execute(const CodegenArgs& c) {
  PNEUMID_CHECK(c.Ts > 0.0 && std::isfinite(c.Ts), "--Ts must be positive, got {}", c.Ts);
  CodegenOptions options;
  options.precision = CodegenPrecisionFromString(c.precision);
  options.prefix = c.prefix;
  options.max_ram_bytes = c.max_ram;
  options.qp_max_iterations = c.qp_max_iterations;
  options.cpu_mhz = c.cpu_mhz;
  options.period = c.period;
  options.utilization = c.utilization;
  options.cycles_per_instruction = c.cycles_per_instruction;
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "--prefix: {}", error);
  // The model as `pneumid control` reads it: a Hammerstein, Wiener or
  // input-affine NARX model file brings its map or linearization, which the
  // module carries (c_codegen.hpp).
  const TransferFunction model = ParseControllerModel(c.model);
  // As `pneumid control`: the plant's input range (IPA: duty 0..100 %) unless
  // --u-min/--u-max say otherwise.
  ControllerSettings settings = c.controller;
  if (!c.plant.empty()) {
    const auto plant = MakePlant(c.plant, c.Ts, PlantOptions{});
    ApplyPlantInputRange(*plant, settings.limits.u_min, settings.limits.u_max);
    ApplyPlantInputGaps(*plant, settings.input_gaps);
  }
  PNEUMID_CHECK(!(settings.limits.u_min > settings.limits.u_max), "--u-min {} is above --u-max {}",
                settings.limits.u_min, settings.limits.u_max);
  // Options the chosen controller would silently ignore are errors here: the
  // generated code is to do what the command line says.
  const std::string& type = settings.controller;
  PNEUMID_CHECK(!settings.constrained || type == "dmc",
                "--constrained selects QDMC for dmc (mpc is constrained whenever a limit is "
                "set); {} clips its input",
                type);
  const bool soft = std::isfinite(settings.y_min) || std::isfinite(settings.y_max);
  PNEUMID_CHECK(!soft || type == "mpc" || (type == "dmc" && settings.constrained),
                "--y-min/--y-max are soft output bounds of mpc and of dmc with --constrained, "
                "not of {}",
                type == "dmc" ? "dmc without --constrained" : type);
  const BuiltController built =
      MakeController(model, c.Ts, WithModelInputMap(ToControllerSpec(settings), c.model));
  const CodegenResult result = GenerateC(*built.controller, options);
  std::vector<std::string> paths = WriteCodegenFiles(result, c.output);
  if (!c.with_plant.empty()) {
    CodegenOptions po = options;
    po.prefix = c.with_plant;
    po.max_ram_bytes = 0;
    PNEUMID_CHECK(po.IsValid(&error), "--with-plant: {}", error);
    PNEUMID_CHECK(po.prefix != options.prefix, "--with-plant needs another name than --prefix ({})",
                  options.prefix);
    // The plant module is the linear part only: refuse rather than drop a map.
    const bool input_map = ParseModelInputMap(c.model).has_value();
    PNEUMID_CHECK(!input_map && !ParseModelOutputMap(c.model),
                  "--with-plant writes a linear plant, and the model '{}' has a static {} map; "
                  "give a linear model for the plant, or simulate the loop with `pneumid "
                  "control --plant {}`",
                  c.model, input_map ? "input" : "output", c.model);
    CodegenResult plant = GenerateLinearPlantC(SampledStateSpace(model, c.Ts), po);
    plant.readme.clear();
    for (const std::string& p : WriteCodegenFiles(plant, c.output)) paths.push_back(p);
  }
  if (c.json) {
    nlohmann::ordered_json j = result.ToJson();
    j["settings"] = built.SettingsToJson();
    j["Ts"] = c.Ts;
    j["paths"] = paths;
    std::cout << j.dump(2) << "\n";
    return;
  }
  std::cout << fmt::format("{} ({} precision)\n", result.description, ToString(options.precision));
  std::cout << fmt::format("design: {}\n", built.Summary());
  std::cout << fmt::format("state (RAM): {} bytes; constant tables: {} bytes{}\n", result.ram_bytes,
                           result.const_bytes,
                           result.constrained ? "; with the embedded QP solver" : "");
  const RealTimeCertificate& rt = result.certificate;
  std::cout << fmt::format(
      "worst step: {:.0f} instructions{}{}\n", rt.max_instructions,
      rt.qp_max_iterations > 0 ? fmt::format(" with {} QP iterations", rt.qp_max_iterations)
                               : std::string(),
      rt.present ? fmt::format(" = {:.0f} cycles = {:.3g} ms at {:g} MHz, "
                               "budget {:.0f} cycles ({:g} of {:g} ms)",
                               rt.max_cycles, 1e3 * rt.max_time, rt.cpu_mhz, rt.budget_cycles,
                               rt.utilization, 1e3 * rt.period)
                 : std::string());
  if (!result.layers.empty())
    std::cout << fmt::format("layers in front of the {}: {}\n", ToString(result.type),
                             fmt::join(result.layers, ", "));
  for (const std::string& p : paths) std::cout << "wrote " << p << "\n";
}

const Registrar reg(
    "codegen",
    "Write a designed controller (dmc, gpc, pid, mpc) as embedded C99 code for a microcontroller",
    [](CLI::App& app) {
      auto c = std::make_shared<CodegenArgs>();
      app.add_option("--model", c->model,
                     "Controller's model: fopdt-paper, arx-paper, fopdt:K=..,tau=..,theta=.., "
                     "tf:..., FILE.json (required unless --config has [controller] model)");
      app.add_option("--config", c->config,
                     "Controller configuration (TOML, e.g. the controller.toml of `pneumid "
                     "commission`): its [controller] section and [loop] period; flags given "
                     "override it");
      app.add_option("--plant", c->plant,
                     "Plant whose input range bounds the input when --u-min/--u-max are not "
                     "given (ipa: 0..100 % duty); default: none")
          ->capture_default_str();
      AddSampleTimeOption(app, c->Ts, "Sample time in s");
      AddControllerOptions(app, c->controller);
      app.add_option("--u-min", c->controller.limits.u_min,
                     "Lower input limit (default: the plant's input range, or none)");
      app.add_option("--u-max", c->controller.limits.u_max,
                     "Upper input limit (default: the plant's input range, or none)");
      app.add_option("--du-max", c->controller.limits.du_max, "Largest input change per sample");
      app.add_option("--y-min", c->controller.y_min, "Soft lower output bound (QDMC, mpc)");
      app.add_option("--y-max", c->controller.y_max, "Soft upper output bound (QDMC, mpc)");
      app.add_option("--t-filter", c->controller.t_filter,
                     "GPC observer polynomial T: 1, A, or coefficients '1 -0.8'")
          ->capture_default_str();
      app.add_option("--tau-c", c->controller.tau_c,
                     "PID closed-loop time constant in s (0 = rule default)")
          ->check(NonNegative());
      AddPidGainOptions(app, c->controller);
      app.add_option("--precision", c->precision,
                     "Arithmetic of the generated code: double or float (Cortex-M4F: float)")
          ->capture_default_str();
      app.add_option("--prefix", c->prefix,
                     "Name of the files and prefix of every C symbol (a C identifier)")
          ->capture_default_str();
      app.add_option("--max-ram", c->max_ram,
                     "RAM budget in bytes for the controller's state; a larger one is an error "
                     "(0 = none)")
          ->capture_default_str();
      app.add_option("--qp-max-iterations", c->qp_max_iterations,
                     "Iteration cap of the constrained controllers' QP in the module "
                     "(QP_MAX_ITERATIONS, overridable with -D); -1: the design's, 0: 10 (n + "
                     "finite sides) + 10")
          ->capture_default_str()
          ->check(CLI::Range(-1, 1000000));
      app.add_option("--cpu-mhz", c->cpu_mhz,
                     "Target clock in MHz for the real-time certificate: the QP's iteration cap "
                     "becomes the largest whose worst step fits the budget (0: no certificate)")
          ->capture_default_str()
          ->check(NonNegative());
      app.add_option("--period", c->period, "Control period in s for the certificate (0: --Ts)")
          ->capture_default_str()
          ->check(NonNegative());
      app.add_option("--utilization", c->utilization,
                     "Fraction of the period the controller may take")
          ->capture_default_str()
          ->check(InRange(1e-6, 1.0));
      app.add_option("--cycles-per-instruction", c->cycles_per_instruction,
                     "Cycles per instruction assumed on the target (>= 1)")
          ->capture_default_str()
          ->check(InRange(1.0, 100.0));
      app.add_option("-o,--output", c->output, "Directory to write NAME.h, NAME.c, README.md into")
          ->required();
      app.add_option("--with-plant", c->with_plant,
                     "Also write the model as a linear plant module NAME.h/NAME.c (closed-loop "
                     "runs on a board or an emulator)");
      app.add_flag("--json", c->json, "Print the result (sizes, files, design) as JSON");
      app.callback([c, &app] {
        if (!c->config.empty()) {
          const RealtimeConfig config = LoadRealtimeConfig(c->config);
          if (config.controller)
            ApplyControllerConfig(app, *config.controller, c->model, c->controller);
          if (app.count("--Ts") == 0) c->Ts = config.loop.period;
        }
        PNEUMID_CHECK(!c->model.empty(),
                      "--model is required (or a --config file with [controller] model)");
        Execute(*c);
      });
    });

}  // namespace
}  // namespace pneumid::cli
