#include "pneumid/report/identification_report.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/identify/identify.hpp"
#include "pneumid/identify/nonlinear/nonlinear.hpp"
#include "pneumid/identify/step/step_analysis.hpp"
#include "pneumid/report/figures.hpp"
#include "pneumid/report/html.hpp"

namespace pneumid {

namespace {

std::string Num(double v) {
  if (!std::isfinite(v)) return std::isnan(v) ? "n/a" : (v > 0 ? "inf" : "-inf");
  return fmt::format("{:.5g}", v);
}

// Compact text of a parameter value: numbers with 5 significant digits,
// arrays in brackets.
std::string ParamText(double v) { return Num(v); }
template <typename T>
std::string ParamText(const std::vector<T>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + ParamText(v[i]);
  return s + "]";
}
std::string ParamText(const ParamValue& v) {
  return std::visit([](const auto& x) { return ParamText(x); }, v);
}

std::string ChannelLabel(const Channel& c, const std::string& fallback) {
  std::string name = c.name.empty() ? fallback : c.name;
  return c.unit.empty() ? name : name + " [" + c.unit + "]";
}

}  // namespace

bool ReportOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (methods.empty()) return fail("ReportOptions::methods is empty");
  for (const auto& m : methods) {
    if (!IsIdentifyMethod(m))
      return fail(fmt::format("unknown identification method '{}' (valid: {})", m,
                              fmt::join(IdentifyMethodNames(), ", ")));
  }
  if (!request.IsValid(error)) return false;
  if (residual_max_lag < 1 || residual_max_lag > 10000)
    return fail(fmt::format("ReportOptions::residual_max_lag must be in [1, 10000], got {}",
                            residual_max_lag));
  if (!(residual_confidence > 0.0 && residual_confidence < 1.0))
    return fail(fmt::format("ReportOptions::residual_confidence must be in (0, 1), got {}",
                            residual_confidence));
  if (!(confidence >= 0.0) || !std::isfinite(confidence))
    return fail(fmt::format("ReportOptions::confidence must be >= 0 standard deviations, got {}",
                            confidence));
  return true;
}

std::string ReportSummary::BriefReport() const {
  return fmt::format("report {}: {} model(s), {} failed, {} figure(s), {} table(s) -> {}",
                     ToString(termination), models.size(), failures.size(), num_figures, num_tables,
                     html_path);
}

ReportSummary WriteIdentificationReport(const Dataset& data, const ReportOptions& options,
                                        const std::string& dir) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "{}", error);
  const int in = options.request.input, out = options.request.output;
  PNEUMID_CHECK(in >= 0 && in < data.num_inputs(),
                "input channel {} does not exist (the data have {} input(s))", in,
                data.num_inputs());
  PNEUMID_CHECK(out >= 0 && out < data.num_outputs(),
                "output channel {} does not exist (the data have {} output(s))", out,
                data.num_outputs());
  data.RequireSamples(4, "the identification report");
  data.RequireUniform();

  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw DataError(dir + ": cannot create the directory: " + ec.message());

  ReportSummary summary;
  {
    const IdentificationSummary ids =
        IdentifyModels(options.methods, data, options.request, {}, nullptr, options.progress);
    summary.models = ids.models;
    summary.failures = ids.failures;
    if (options.preprocessing)
      for (IdentifiedModel& m : summary.models) m.preprocessing = options.preprocessing;
  }

  const std::string source = data.source().empty() ? "(in-memory data)" : data.source();
  HtmlDocument doc(options.title.empty() ? "Identification report: " +
                                               std::filesystem::path(source).filename().string()
                                         : options.title);
  const Channel uc = in < static_cast<int>(data.input_channels().size()) ? data.input_channels()[in]
                                                                         : Channel{"u", ""};
  const Channel yc = out < static_cast<int>(data.output_channels().size())
                         ? data.output_channels()[out]
                         : Channel{"y", ""};
  SignalLabels labels;
  labels.time = ChannelLabel(data.time_channel(), "t");
  if (data.time_channel().unit.empty()) labels.time = "Time t [s]";
  labels.input = ChannelLabel(uc, "u");
  labels.output = ChannelLabel(yc, "y");

  // Data section.
  doc.AddHeading("Data");
  Table dt;
  dt.caption = "Dataset";
  dt.header = {"property", "value"};
  dt.rows = {{"source", source},
             {"samples", std::to_string(data.size())},
             {"sample time [s]", Num(data.SampleTime())},
             {"duration [s]", Num(data.time()[data.size() - 1] - data.time()[0])},
             {"input", labels.input},
             {"output", labels.output}};
  if (options.preprocessing)
    for (const std::string& step : options.preprocessing->steps)
      dt.rows.push_back({"preprocessing", step});
  try {
    const StepAnalysis s = AnalyzeStep(data, in, out);
    dt.rows.push_back({"step", s.BriefReport()});
  } catch (const DataError& e) {
    dt.rows.push_back({"step", std::string("no single step: ") + e.what()});
  }
  doc.AddTable(dt);

  // Models.
  doc.AddHeading("Models");
  if (!summary.models.empty()) {
    Table pt;
    pt.caption = "Identified parameters";
    pt.header = {"method", "structure", "parameters", "transfer function"};
    for (const auto& m : summary.models) {
      std::string params;
      for (const auto& [k, v] : m.params) {
        if (!params.empty()) params += ", ";
        params += k + " = " + ParamText(v);
        if (m.param_std.contains(k)) params += " ± " + ParamText(m.param_std.at(k));
      }
      pt.rows.push_back({m.method, m.structure, params, m.tf.ToString(5)});
    }
    doc.AddTable(pt);

    Table mt;
    mt.caption = "Fit to the data (model simulated on the measured input)";
    mt.header = {"method", "NRMSE fit [%]", "IAE [" + (yc.unit.empty() ? "" : yc.unit + " ") + "s]",
                 "RMSE",   "max |error|",   "flags",
                 "notes"};
    for (const auto& m : summary.models) {
      FitMetrics fm;
      fm.fit_percent = m.fit_percent;
      fm.iae = m.iae;
      fm.rmse = fm.max_abs_error = std::numeric_limits<double>::quiet_NaN();
      try {
        fm = EvaluateModel(m, data, in, out);
      } catch (const InvalidArgument&) {
      }
      std::string flags, notes;
      for (const auto& f : m.flags)
        flags += (flags.empty() ? "" : "; ") + ToString(f.flag) + ": " + f.reason;
      for (const auto& n : m.notes) notes += (notes.empty() ? "" : "; ") + n;
      mt.rows.push_back({m.method, Num(fm.fit_percent), Num(fm.iae), Num(fm.rmse),
                         Num(fm.max_abs_error), flags.empty() ? "-" : flags, notes});
    }
    doc.AddTable(mt);
  }
  if (!summary.failures.empty()) {
    doc.AddHeading("Methods that gave no model", 3);
    std::vector<std::string> items;
    for (const auto& [m, e] : summary.failures) items.push_back(m + ": " + e);
    doc.AddList(items);
  }

  // Figures.
  if (!summary.models.empty()) {
    // Every model is compared with the data; the step and frequency responses
    // leave out models flagged unstable, not finite or with a Nyquist pole,
    // whose responses are not the plant's (and would set the axes).
    std::vector<NamedModel> named, trusted;
    std::vector<std::string> left_out, nonlinear;
    std::vector<NamedStaticMap> maps;
    for (const auto& m : summary.models) {
      NamedModel nm{m.method + " (" + m.structure + ")", m.discrete ? *m.discrete : m.tf, m.u0,
                    m.y0};
      // The comparison simulates nonlinear models as they are; the bands need it too.
      if (options.confidence > 0.0 || IsNonlinearModel(m))
        nm.identified = std::make_shared<const IdentifiedModel>(m);
      named.push_back(nm);
      if (m.input_map) maps.push_back({m.method, *m.input_map, m.narx.has_value()});
      if (IsNonlinearModel(m)) {
        nonlinear.push_back(m.method);  // no single step or frequency response
      } else if (RankGroup(m) == 0) {
        trusted.push_back(nm);
      } else {
        left_out.push_back(m.method);
      }
    }
    std::string left_out_text =
        left_out.empty()
            ? ""
            : fmt::format(" Left out (flagged, see the fit table): {}.", fmt::join(left_out, ", "));
    if (!nonlinear.empty())
      left_out_text += fmt::format(
          " Not drawn: the nonlinear models ({}), whose responses depend on the operating "
          "point (their static maps are drawn below).",
          fmt::join(nonlinear, ", "));
    doc.AddHeading("Figures");
    ComparisonFigureOptions co;
    co.labels = labels;
    co.input = in;
    co.output = out;
    co.title = "Measured data and simulated models";
    doc.AddFigure(ModelComparisonFigure(data, named, co),
                  "Measured output and each model driven by the measured input (deviation "
                  "from the initial operating point), with the input below.");

    StepFigureOptions so;
    so.labels = labels;
    so.title = "Step responses of the models";
    double du = 1.0;
    try {
      du = AnalyzeStep(data, in, out).du;
    } catch (const DataError&) {
    }
    so.amplitude = du;
    so.t_final = data.time()[data.size() - 1] - data.time()[0];
    so.confidence = options.confidence;
    const std::string band_text =
        options.confidence > 0.0
            ? fmt::format(
                  " Shaded: \u00b1{:g} standard deviations of the models with a parameter "
                  "covariance (first-order propagation).",
                  options.confidence)
            : "";
    if (!trusted.empty()) {
      doc.AddFigure(StepResponseFigure(trusted, so),
                    fmt::format("Responses of the models to an input step of {} (input units).{}{}",
                                Num(du), band_text, left_out_text));
      doc.AddFigure(BodeFigure(trusted, Eigen::VectorXd(), "Bode diagram", options.confidence),
                    "Frequency responses of the models." + band_text + left_out_text);
    }

    if (!maps.empty()) {
      doc.AddFigure(StaticMapFigure(maps, labels, "Static input maps"),
                    "The models' static input maps f(u): the steady output of a static-map "
                    "model, the input nonlinearity of a Hammerstein model (both in output "
                    "units), the valves' open fraction of an input-affine NARX (0..1).");
    }

    // Residuals of the best model (the first of the ranking).
    const auto best = summary.models.begin();
    try {
      const Eigen::VectorXd e = data.y(out) - SimulateModel(*best, data, in);
      const int lag = std::min<int>(options.residual_max_lag, static_cast<int>(data.size()) - 2);
      const ResidualCorrelation rc =
          ComputeResidualCorrelation(e, data.u(in), lag, options.residual_confidence);
      doc.AddFigure(ResidualFigure(rc, "Residuals of " + best->method),
                    fmt::format("Residual analysis of the best-ranked model ({}): {:.0f} % of the "
                                "autocorrelation lags and {:.0f} % of the cross-correlation "
                                "lags lie outside the {:g} % band.",
                                best->method, 100.0 * rc.auto_outside, 100.0 * rc.cross_outside,
                                100.0 * rc.confidence));
    } catch (const InvalidArgument& e) {
      doc.AddParagraph(std::string("Residual analysis not available: ") + e.what());
    }
  }

  doc.AddHeading("Reproduce");
  if (options.commands.empty()) {
    doc.AddParagraph("No command lines were recorded for this report.");
  } else {
    doc.AddParagraph("The commands that reproduce this report:");
    doc.AddCommands(options.commands);
  }

  summary.html_path = (std::filesystem::path(dir) / "report.html").string();
  summary.models_path = (std::filesystem::path(dir) / "models.json").string();
  doc.Write(summary.html_path);
  nlohmann::json j;
  j["data"] = source;
  j["models"] = nlohmann::json::array();
  for (const auto& m : summary.models) j["models"].push_back(ToJson(m));
  j["failures"] = nlohmann::json::array();
  for (const auto& [m, e] : summary.failures)
    j["failures"].push_back({{"method", m}, {"error", e}});
  {
    std::ofstream f(summary.models_path);
    if (!f) throw DataError(summary.models_path + ": cannot open the file for writing");
    f << j.dump(2) << "\n";
  }
  summary.num_figures = doc.num_figures();
  summary.num_tables = doc.num_tables();
  if (summary.models.empty()) {
    summary.termination = Termination::kFailure;
    summary.message = "no method gave a model";
  } else if (!summary.failures.empty()) {
    summary.termination = Termination::kPartial;
    summary.message =
        fmt::format("{} of {} methods failed", summary.failures.size(), options.methods.size());
  } else {
    summary.termination = Termination::kSuccess;
    summary.message = "all methods gave a model";
  }
  return summary;
}

}  // namespace pneumid
