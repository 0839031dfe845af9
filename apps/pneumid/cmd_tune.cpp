// pneumid tune: prediction horizon P, control horizon M and move suppression
// lambda of a predictive controller from a model, or (--rule auto) the settings
// of an MPC, DMC or PID for a specification (control/auto_tuning.hpp).
//
//   pneumid tune --model fopdt:K=1.6,tau=0.245,theta=0.001 --Ts 0.01
//                --rule shridhar-cooper [--M 5] [--json]
//   -> {"rule": "shridhar-cooper", "P": 126, "M": 5, "lambda": 2.2508, ...,
//       "formula": "..."}
//   pneumid tune --model fopdt-paper --Ts 0.01 --rule auto [--controller mpc|dmc|pid]
//                [--response-time T] [--overshoot PCT] [--aggressiveness A]
//                [--u-min U --u-max U] [--plant PLANT] [--json]
//   -> {"rule": "auto", "controller": "mpc", "P": 126, "M": 5, "lambda": ...,
//       "predicted": {...}, "robustness": [...], "review": [...],
//       "termination": "converged", "message": "..."}
#include <cmath>
#include <iostream>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "command_json.hpp"
#include "pneumid/control/auto_tuning.hpp"
#include "pneumid/control/tuning.hpp"
#include "pneumid/workflow/tune_workflow.hpp"
#include "validators.hpp"

namespace pneumid::cli {


namespace {

void Run(const TuneArgs& c) {
  const TuneWorkflowResult result = RunTuneWorkflow(c.options);
  if (c.json) {
    std::cout << result.ToJson().dump(2) << "\n";
    return;
  }
  if (result.automatic) {
    std::cout << result.automatic->FullReport();
    return;
  }
  const TuningResult& r = *result.tuning;
  std::cout << fmt::format("rule    {}\nP       {}\nM       {}\nlambda  {:.6g}\n", ToString(r.rule),
                           r.P, r.M, r.lambda);
  if (r.rule == TuningRule::kShridharCooper) {
    std::cout << fmt::format(
        "FOPDT   K = {:.6g}, tau = {:.6g} s, theta = {:.6g} s ({})\n"
        "lambda_condition  {:.6g}  (lambda_max(A'A)/500, used{})\n"
        "lambda_formula    {:.6g}  ((M/500) K^2 (3.5 tau/Ts + 2 - (M-1)/2), tau = {:g} s)\n",
        r.fopdt.K, r.fopdt.tau, r.fopdt.theta, r.fopdt.method, r.lambda_condition,
        std::isnan(c.options.lambda) ? "" : " unless --lambda", r.lambda_formula, r.tau_used);
  }
  std::cout << "formula: " << r.formula << "\n";
}

const Registrar reg(
    "tune", "Horizons and move suppression (P, M, lambda) of DMC/GPC from a model",
    [](CLI::App& app) {
      auto args = std::make_shared<TuneArgs>();
      TuneWorkflowOptions* c = &args->options;
      app.add_option("--model", c->model,
                     "Model spec: fopdt:K=..,tau=..,theta=.., arx-paper, tf:..., FILE.json")
          ->required();
      AddSampleTimeOption(app, c->Ts, "Controller sample time in s")->required();
      app.add_option("--rule", c->rule,
                     "shridhar-cooper (conventional), paper-modified (P=126, M=10, lambda=1.92), "
                     "explicit (needs --P --M --lambda), auto (to a specification: see "
                     "--controller, --response-time, --overshoot, --aggressiveness)")
          ->capture_default_str();
      app.add_option("--M", c->M,
                     "Control horizon (default: 5 shridhar-cooper, 10 paper-modified)");
      app.add_option("--P", c->P, "Prediction horizon (overrides the rule)")->check(AtLeast(1));
      app.add_option("--lambda", c->lambda, "Move suppression (overrides the rule)");
      app.add_option("--tau-digits", c->tau_digits,
                     "Significant digits tau is rounded to in the P formula (0 = none)")
          ->capture_default_str();
      app.add_option("--controller", c->controller,
                     "auto: controller to design, mpc (default), dmc or pid");
      app.add_option("--response-time", c->response_time,
                     "auto: target response time in s (default: about the model's time "
                     "constant, tau + theta)")
          ->check(Positive());
      app.add_option("--measure", c->measure,
                     "auto: what --response-time measures, rise (10-90 %, default) or settling "
                     "(2 %)");
      app.add_option("--overshoot", c->overshoot, "auto: maximum overshoot in percent (default 5)")
          ->check(NonNegative());
      app.add_option("--aggressiveness", c->aggressiveness,
                     "auto: 0 robust .. 1 aggressive (default 0.5)")
          ->check(InRange(0.0, 1.0));
      app.add_option("--u-min", c->u_min, "auto: lower input limit");
      app.add_option("--u-max", c->u_max, "auto: upper input limit");
      app.add_option("--du-max", c->du_max, "auto: largest input change per sample");
      app.add_option("--plant", c->plant,
                     "auto: plant whose physical input range (ipa: duty 0..100 %) sets the "
                     "limits --u-min/--u-max leave open, as control --plant does");
      app.add_option("--measurement-noise", c->measurement_noise,
                     "auto, mpc: the Kalman filter's measurement noise variance, output units "
                     "squared, as control's (default 1)");
      app.add_option("--state-noise", c->state_noise,
                     "auto, mpc: process noise variance on each model state (default 0)");
      app.add_option("--disturbance-noise", c->disturbance_noise,
                     "auto, mpc: process noise variance on the disturbance (default 1)");
      app.add_flag("--json", args->json, "Print a JSON object");
      app.callback([args] { Run(*args); });
    });

}  // namespace
}  // namespace pneumid::cli
