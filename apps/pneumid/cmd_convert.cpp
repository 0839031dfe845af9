// pneumid convert: a linear model between time domains and discretization methods.
//
//   pneumid convert --num 0,0.03938,0.04506,0.01286 --den 1,-0.60870,-0.27020,-0.06021
//                   --Ts 0.01 --to continuous --method zoh [--json]
//   pneumid convert --model fopdt-paper --to discrete --Ts 0.01 [--method tustin --prewarp W]
//
// With --to continuous, --Ts is the sample time of the model given by
// --num/--den; with --to discrete it is the target sample time (the model is
// then continuous, or discrete and resampled through its zoh equivalent).
#include <cmath>
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "validators.hpp"
#include "model_options.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/lti/conversion.hpp"
#include "pneumid/models/model_file.hpp"

namespace pneumid::cli {
namespace {

struct ConvertArgs {
  ModelOptions model;
  std::string to;
  std::string method = "zoh";
  double Ts = 0.0;
  double prewarp = 0.0;
  bool json = false;
};

void Run(ConvertArgs o) {
  PNEUMID_CHECK(o.to == "continuous" || o.to == "discrete",
                "--to must be 'continuous' or 'discrete', got '{}'", o.to);
  PNEUMID_CHECK(std::isfinite(o.Ts) && o.Ts >= 0.0, "--Ts must be >= 0 s, got {}", o.Ts);
  const DiscretizationMethod method = DiscretizationMethodFromString(o.method);
  TransferFunction result;
  TransferFunction input;
  std::string how;
  if (o.to == "continuous") {
    if (o.model.model.empty()) {
      PNEUMID_CHECK(o.Ts > 0.0,
                    "--to continuous converts a discrete model: give its sample time with --Ts");
      o.model.Ts = o.Ts;
    } else {
      PNEUMID_CHECK(o.Ts == 0.0,
                    "--Ts applies to --num/--den; the model spec '{}' carries its own sample time",
                    o.model.model);
    }
    input = ResolveModel(o.model);
    PNEUMID_CHECK(input.IsDiscrete(), "--to continuous: the model is already continuous");
    result = D2C(input, method, o.prewarp);
    how = fmt::format("d2c {} from Ts = {:g} s", ToString(method), input.Ts());
  } else {
    PNEUMID_CHECK(o.Ts > 0.0, "--to discrete needs the target sample time --Ts > 0, got {}", o.Ts);
    o.model.Ts = 0.0;
    input = ResolveModel(o.model);
    TransferFunction continuous = input;
    if (input.IsDiscrete()) {
      continuous = D2C(input, DiscretizationMethod::kZoh);
      how = fmt::format("resampled from Ts = {:g} s through its zoh equivalent, then ", input.Ts());
    }
    result = C2D(continuous, o.Ts, method, o.prewarp);
    how += fmt::format("c2d {}{} with Ts = {:g} s", ToString(method),
                       o.prewarp > 0 ? fmt::format(" (prewarp {:g} rad/s)", o.prewarp) : "", o.Ts);
  }
  if (o.json) {
    // Keys in the documented order: num, den, Ts, delay.
    const nlohmann::json j = ToJson(result);
    nlohmann::ordered_json out;
    for (const char* key : {"num", "den", "Ts", "delay"}) out[key] = j.at(key);
    std::cout << out.dump() << "\n";
    return;
  }
  std::cout << "input:\n" << DescribeModel(input.Normalized(), "  ");
  std::cout << "result (" << how << "):\n" << DescribeModel(result.Normalized(), "  ");
}

const Registrar reg(
    "convert", "Convert a linear model between continuous and discrete time", [](CLI::App& app) {
      auto o = std::make_shared<ConvertArgs>();
      AddModelOptions(app, o->model, /*with_ts=*/false);
      app.add_option("--to", o->to, "Target domain: continuous or discrete")
          ->required()
          ->check(CLI::IsMember({"continuous", "discrete"}));
      app.add_option("-m,--method,--methods", o->method,
                     "zoh, foh, tustin (bilinear), euler (forward_diff), backward_diff, matched; "
                     "d2c: zoh or tustin")
          ->capture_default_str();
      app.add_option("--Ts", o->Ts,
                     "Sample time in s: of the --num/--den model for --to continuous, the target "
                     "for --to discrete")
          ->check(NonNegative());
      app.add_option("--prewarp", o->prewarp, "Tustin prewarp frequency in rad/s (0 = none)")
          ->capture_default_str()
          ->check(NonNegative());
      app.add_flag("--json", o->json,
                   "Print {\"num\", \"den\", \"Ts\", \"delay\"} (monic denominator) instead");
      app.callback([o] { Run(*o); });
    });

}  // namespace
}  // namespace pneumid::cli
