#include "pneumid/workflow/commission_report.hpp"

#include <cmath>
#include <memory>

#include <fmt/format.h>

#include "pneumid/report/figures.hpp"
#include "pneumid/report/html.hpp"

namespace pneumid {
namespace {

std::string Num(double v, const char* unit = "") {
  return std::isfinite(v) ? fmt::format("{:.4g}{}", v, unit) : std::string("-");
}

std::string Label(const Channel& c, const char* fallback) {
  if (c.unit == "N") return "Force F [N]";
  if (c.unit == "%") return "Duty cycle u [%]";
  return c.unit.empty() ? fallback : fmt::format("{} [{}]", c.name, c.unit);
}

void AddExperiment(HtmlDocument& doc, const CommissionResult& r) {
  const CommissionExperiment& ex = r.experiment;
  doc.AddHeading("Experiment");
  Table t;
  t.caption = "What the probe step and the sweep measured";
  t.header = {"quantity", "value"};
  t.rows = {{"plant time of the experiment", Num(ex.duration, " s")},
            {"gain K (probe step)", Num(ex.gain)},
            {"time constant tau (two-point method)", Num(ex.time_constant, " s")},
            {"dead time theta", Num(ex.dead_time, " s")},
            {"reachable output", Num(ex.reachable_min) + " .. " + Num(ex.reachable_max)},
            {"range served", Num(ex.range_min) + " .. " + Num(ex.range_max)},
            {"output peak to peak at rest (sensor noise)", Num(ex.noise_peak_to_peak)},
            {"levels (estimation + held out)",
             fmt::format("{} + {} of {:.3g} s", ex.estimation_levels.size(),
                         ex.validation_levels.size(), ex.dwell)}};
  doc.AddTable(t);
}

void AddModels(HtmlDocument& doc, const CommissionResult& r, const SignalLabels& labels) {
  doc.AddHeading("Models");
  Table t;
  t.caption = "Ranked by their simulation fit on the held-out sequence";
  t.header = {"method", "estimation fit [%]", "held-out fit [%]", "flags", "chosen"};
  for (const IdentifiedModel& m : r.identification.models) {
    std::string flags;
    for (const auto& f : m.flags) flags += (flags.empty() ? "" : ", ") + ToString(f.flag);
    t.rows.push_back({m.method, Num(m.fit_percent), Num(m.validation_fit_percent), flags,
                      m.method == r.chosen_model ? "yes" : ""});
  }
  doc.AddTable(t);
  if (!r.chosen_reason.empty()) doc.AddParagraph("Chosen: " + r.chosen_reason + ".");
  for (const IdentifiedModel& m : r.identification.models) {
    if (m.method != r.chosen_model) continue;
    NamedModel nm{m.method + " (" + m.structure + ")", m.discrete ? *m.discrete : m.tf, m.u0, m.y0,
                  std::make_shared<const IdentifiedModel>(m)};
    ComparisonFigureOptions fo;
    fo.labels = labels;
    fo.title = "Estimation sequence and the chosen model";
    doc.AddFigure(ModelComparisonFigure(r.experiment.estimation, {nm}, fo),
                  "The estimation sequence and the chosen model simulated on its input.");
    fo.title = "Held-out sequence and the chosen model";
    doc.AddFigure(ModelComparisonFigure(r.experiment.validation, {nm}, fo),
                  "The held-out sequence (levels between the estimation levels) and the chosen "
                  "model simulated on its input: the ranking's evidence.");
  }
}

void AddVerification(HtmlDocument& doc, const CommissionResult& r, const SignalLabels& labels) {
  doc.AddHeading("Verification on the plant");
  for (const CommissionAttempt& a : r.attempts) {
    doc.AddHeading(
        fmt::format("Aggressiveness {:g}: {}", a.aggressiveness, a.passed ? "pass" : "fail"), 3);
    doc.AddParagraph(a.design);
    ClosedLoopFigureOptions options;
    options.labels = labels;
    options.title = fmt::format("verification, aggressiveness {:g}", a.aggressiveness);
    if (!a.result.metrics.steps.empty() && a.result.d.size() > 0) {
      for (Eigen::Index k = 1; k < a.result.d.size(); ++k) {
        if (a.result.d(k) != a.result.d(k - 1)) {
          options.disturbance_time = a.result.t(k);
          break;
        }
      }
    }
    doc.AddFigure(ClosedLoopFigure(a.result.t, a.result.r,
                                   {{r.settings.controller, a.result.y, a.result.u}}, options),
                  "Set-point (dashed), output and input of the verification run.");
    Table t;
    t.caption = "Per step (settling band: 2 % of the step or the measured ripple)";
    t.header = {"time [s]",           "from",         "to",
                "overshoot [%]",      "settling [s]", "ripple (p-p)",
                "steady-state error", "steady input"};
    for (const StepMetrics& s : a.result.metrics.steps)
      t.rows.push_back({Num(s.time), Num(s.from), Num(s.to), Num(s.overshoot_percent),
                        s.settled ? Num(s.settling_time) : "not settled", Num(s.ripple),
                        Num(s.steady_state_error), Num(s.steady_input)});
    doc.AddTable(t);
    if (!a.failures.empty()) doc.AddList(a.failures);
  }
  if (!r.limits.empty()) {
    doc.AddHeading("What limits the loop", 3);
    doc.AddList(r.limits);
  }
  if (!r.suggestions.empty()) {
    doc.AddHeading("What to try", 3);
    doc.AddList(r.suggestions);
  }
}

}  // namespace

void WriteCommissionReport(const CommissionResult& r, const std::string& plant,
                           const Channel& input, const Channel& output, const std::string& path) {
  HtmlDocument doc("pneumid commission: " + plant);
  doc.AddParagraph(fmt::format("{}: {}", ToString(r.termination), r.message));
  doc.AddParagraph(fmt::format("Plant time in all stages: {:.1f} s.", r.plant_time));
  SignalLabels labels;
  labels.output = Label(output, "Output y");
  labels.input = Label(input, "Input u");
  if (r.experiment.data.size() > 0) AddExperiment(doc, r);
  if (!r.identification.models.empty()) AddModels(doc, r, labels);
  if (!r.attempts.empty()) AddVerification(doc, r, labels);
  doc.Write(path);
}

}  // namespace pneumid
