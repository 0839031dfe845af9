// pneumid step: step-response metrics of a model (MATLAB stepinfo definitions).
//
//   pneumid step --model arx-paper-ct [--json] [--t-final T] [--plot step.png]
//   pneumid step --num 1 --den 0.245,1 --delay 0.001
//   pneumid step --model models.json#arx --confidence 3 --plot step.png
#include <cmath>
#include <complex>
#include <iostream>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "model_options.hpp"
#include "identified_spec.hpp"
#include "output_options.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/identify/evaluation/model_uncertainty.hpp"
#include "pneumid/lti/response.hpp"
#include "pneumid/report/figures.hpp"

namespace pneumid::cli {
namespace {

struct StepArgs {
  ModelOptions model;
  double t_final = 0.0;
  double dt = 0.0;
  double settling_threshold = 0.02;
  std::vector<double> rise_limits = {0.1, 0.9};
  double confidence = 0.0;  ///< band of +-K standard deviations; 0 = none
  bool json = false;
  std::string plot;
};

// "Step response of MODEL" on a generic output axis.
// With `identified`, a band of o.confidence standard deviations around it.
void WritePlot(const StepArgs& o, const TransferFunction& g,
               const std::optional<IdentifiedModel>& identified) {
  StepFigureOptions fo;
  fo.t_final = o.t_final;
  fo.dt = o.dt;
  fo.title = "Step response of " + ModelLabel(o.model, g);
  fo.labels.output = "Output y (unit step input)";
  fo.confidence = o.confidence;
  NamedModel nm{ModelLabel(o.model, g), g};
  if (identified) nm.identified = std::make_shared<const IdentifiedModel>(*identified);
  StepResponseFigure({nm}, fo).Save(o.plot);
}

// "pole 1.2 outside the unit circle" / "pole 0.5 in the closed right half-plane".
std::string UnstablePole(const TransferFunction& g) {
  const Eigen::VectorXcd p = g.Poles();
  Eigen::Index worst = 0;
  for (Eigen::Index i = 1; i < p.size(); ++i) {
    const bool worse = g.IsDiscrete() ? std::abs(p[i]) > std::abs(p[worst])
                                      : p[i].real() > p[worst].real();
    if (worse) worst = i;
  }
  if (p.size() == 0) return "no poles";
  const std::string hint =
      g.Order() > 20 ? fmt::format("; the roots of a polynomial of order {} are ill-conditioned: "
                                   "give the model in factored or state-space form",
                                   g.Order())
                     : "";
  if (!p.allFinite()) return "its poles cannot be computed" + hint;
  const std::complex<double> z = p[worst];
  const std::string value = std::abs(z.imag()) > 1e-12 * std::max(1.0, std::abs(z))
                                ? fmt::format("{:.6g}{:+.6g}j", z.real(), z.imag())
                                : fmt::format("{:.6g}", z.real());
  return (g.IsDiscrete() ? fmt::format("pole {} with |z| = {:.6g} >= 1", value, std::abs(z))
                         : fmt::format("pole {} with real part >= 0", value)) +
         hint;
}

void Run(const StepArgs& o) {
  const TransferFunction g = ResolveModel(o.model);
  const std::optional<IdentifiedModel> identified = ModelForConfidence(o.model.model, o.confidence);
  PNEUMID_CHECK(o.rise_limits.size() == 2, "--rise-limits takes two fractions LOW,HIGH, got {}",
                o.rise_limits.size());
  StepInfoOptions so;
  so.settling_threshold = o.settling_threshold;
  so.rise_low = o.rise_limits[0];
  so.rise_high = o.rise_limits[1];
  std::string error;
  PNEUMID_CHECK(so.IsValid(&error), "{}", error);
  if (!g.IsStable()) {
    // A growing response has no rise or settling time; a finite horizon can still be drawn.
    const bool plotted = !o.plot.empty() && o.t_final > 0.0;
    if (plotted) WritePlot(o, g, identified);
    throw InvalidArgument(fmt::format(
        "the model is not stable ({}): its step response does not settle and the step "
        "metrics are undefined{}",
        UnstablePole(g),
        plotted ? fmt::format(" (the response up to {} s is plotted in {})", o.t_final, o.plot)
                : "; --t-final T --plot FILE draws the response over a finite horizon"));
  }
  StepInfo info;
  if (o.t_final == 0.0 && o.dt == 0.0) {
    info = ComputeStepInfo(g, so);
  } else {
    const TimeResponse r = Step(g, o.t_final, o.dt);
    so.y_initial = 0.0;
    so.y_final = g.DcGain();  // stable here: unstable models were refused above
    info = ComputeStepInfo(r.t, r.y, so);
  }
  if (!o.plot.empty()) WritePlot(o, g, identified);
  PNEUMID_CHECK(!std::isnan(info.settling_time) || g.DcGain() == 0.0,
                "the step response has not settled within the simulated horizon{}: the "
                "metrics are undefined; give a longer --t-final",
                o.t_final > 0.0 ? fmt::format(" of {} s", o.t_final) : "");
  // The response and its standard deviation on the simulation grid.
  TimeResponse band;
  Eigen::VectorXd sd;
  if (identified) {
    UncertaintyOptions uo;
    uo.discrete = g.IsDiscrete();  // the form drawn: "tf" of the file, discrete when it is
    band = Step(g, o.t_final, o.dt);
    sd = StepResponseStd(*identified, band.t, uo);
  }
  if (o.json) {
    nlohmann::ordered_json j;
    j["rise_time"] = JsonNumber(info.rise_time);
    j["settling_time"] = JsonNumber(info.settling_time);
    j["settling_min"] = JsonNumber(info.settling_min);
    j["settling_max"] = JsonNumber(info.settling_max);
    j["overshoot"] = JsonNumber(info.overshoot);
    j["undershoot"] = JsonNumber(info.undershoot);
    j["peak"] = JsonNumber(info.peak);
    j["peak_time"] = JsonNumber(info.peak_time);
    j["steady_state"] = JsonNumber(info.steady_state);
    if (identified) {
      j["confidence"] = o.confidence;
      j["t"] = JsonNumbers(band.t);
      j["y"] = JsonNumbers(band.y);
      j["std"] = JsonNumbers(sd);
    }
    if (!o.plot.empty()) j["plot"] = o.plot;
    std::cout << j.dump() << "\n";
    return;
  }
  std::cout << "model:\n" << DescribeModel(g.Normalized(), "  ");
  std::cout << fmt::format("step response (unit step at t = 0, MATLAB stepinfo definitions):\n");
  const auto line = [](const char* name, double v, const char* unit) {
    std::cout << fmt::format("  {:<14} {:.6g}{}\n", name, v, unit);
  };
  line("rise_time", info.rise_time, " s");
  line("settling_time", info.settling_time, " s");
  line("settling_min", info.settling_min, "");
  line("settling_max", info.settling_max, "");
  line("overshoot", info.overshoot, " %");
  line("undershoot", info.undershoot, " %");
  line("peak", info.peak, "");
  line("peak_time", info.peak_time, " s");
  line("steady_state", info.steady_state, "");
  if (identified) {
    const Eigen::Index last = band.t.size() - 1;
    std::cout << fmt::format("  {:<14} +-{:.6g} at t = {:.6g} s (+-{:g} sd, max +-{:.6g})\n",
                             "band", o.confidence * sd[last], band.t[last], o.confidence,
                             o.confidence * sd.maxCoeff());
  }
  if (!o.plot.empty()) std::cout << "plot written to " << o.plot << "\n";
}

const Registrar reg(
    "step", "Step-response metrics of a model (rise/settling time, overshoot, peak)",
    [](CLI::App& app) {
      auto o = std::make_shared<StepArgs>();
      AddModelOptions(app, o->model);
      AddTimeGridOptions(app, o->t_final, o->dt);
      app.add_option("--settling-threshold", o->settling_threshold,
                     "Settling band as a fraction of the step")
          ->capture_default_str();
      app.add_option("--rise-limits", o->rise_limits, "Rise-time fractions LOW,HIGH")
          ->delimiter(',')
          ->capture_default_str();
      AddConfidenceOption(app, o->confidence, "the step response");
      app.add_flag("--json", o->json,
                   "Print {\"rise_time\", \"settling_time\", \"overshoot\", \"undershoot\", "
                   "\"peak\", \"peak_time\", \"steady_state\", ...} instead (with --confidence "
                   "also \"confidence\" and the response \"t\", \"y\" and its \"std\")");
      AddPlotOption(app, o->plot, "the step response");
      app.callback([o] { Run(*o); });
    });

}  // namespace
}  // namespace pneumid::cli
