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

namespace {

void CheckReportInputs(const Dataset& data, const ReportOptions& options) {
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
}

void CreateReportDirectory(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw DataError(dir + ": cannot create the directory: " + ec.message());
}

// Runs the methods; the models carry the report's preprocessing record.
void IdentifyReportModels(const Dataset& data, const ReportOptions& options,
                          ReportSummary& summary) {
  IdentifyOptions identify;
  identify.nonlinear.choose_structure = options.choose_structure;
  const IdentificationSummary identified =
      IdentifyModels(options.methods, data, options.request, identify, nullptr, options.progress);
  summary.models = identified.models;
  summary.failures = identified.failures;
  if (options.preprocessing)
    for (IdentifiedModel& model : summary.models) model.preprocessing = options.preprocessing;
}

// The channels the report is about and the axis labels of its figures.
struct ReportSignals {
  int input = 0;           ///< input channel index
  int output = 0;          ///< output channel index
  Channel output_channel;  ///< name and unit of the output
  SignalLabels labels;     ///< time, input and output axis labels
};

ReportSignals DescribeSignals(const Dataset& data, const IdentifyRequest& request) {
  ReportSignals signals;
  signals.input = request.input;
  signals.output = request.output;
  const int in = signals.input, out = signals.output;
  const Channel input_channel = in < static_cast<int>(data.input_channels().size())
                                    ? data.input_channels()[in]
                                    : Channel{"u", ""};
  signals.output_channel = out < static_cast<int>(data.output_channels().size())
                               ? data.output_channels()[out]
                               : Channel{"y", ""};
  signals.labels.time = ChannelLabel(data.time_channel(), "t");
  if (data.time_channel().unit.empty()) signals.labels.time = "Time t [s]";
  signals.labels.input = ChannelLabel(input_channel, "u");
  signals.labels.output = ChannelLabel(signals.output_channel, "y");
  return signals;
}

// Data section: the dataset's properties, its preprocessing and its step.
void AddDataSection(HtmlDocument& doc, const Dataset& data, const ReportOptions& options,
                    const std::string& source, const ReportSignals& signals) {
  doc.AddHeading("Data");
  Table table;
  table.caption = "Dataset";
  table.header = {"property", "value"};
  table.rows = {{"source", source},
                {"samples", std::to_string(data.size())},
                {"sample time [s]", Num(data.SampleTime())},
                {"duration [s]", Num(data.time()[data.size() - 1] - data.time()[0])},
                {"input", signals.labels.input},
                {"output", signals.labels.output}};
  if (options.preprocessing)
    for (const std::string& step : options.preprocessing->steps)
      table.rows.push_back({"preprocessing", step});
  try {
    const StepAnalysis step = AnalyzeStep(data, signals.input, signals.output);
    table.rows.push_back({"step", step.BriefReport()});
  } catch (const DataError& e) {
    table.rows.push_back({"step", std::string("no single step: ") + e.what()});
  }
  doc.AddTable(table);
}

Table ParameterTable(const std::vector<IdentifiedModel>& models) {
  Table table;
  table.caption = "Identified parameters";
  table.header = {"method", "structure", "parameters", "transfer function"};
  for (const auto& model : models) {
    std::string params;
    for (const auto& [name, value] : model.params) {
      if (!params.empty()) params += ", ";
      params += name + " = " + ParamText(value);
      if (model.param_std.contains(name)) params += " ± " + ParamText(model.param_std.at(name));
    }
    table.rows.push_back({model.method, model.structure, params, model.tf.ToString(5)});
  }
  return table;
}

// Each model simulated on the measured input, with its flags and notes.
Table FitTable(const std::vector<IdentifiedModel>& models, const Dataset& data,
               const ReportSignals& signals) {
  const std::string& output_unit = signals.output_channel.unit;
  Table table;
  table.caption = "Fit to the data (model simulated on the measured input)";
  table.header = {
      "method", "NRMSE fit [%]", "IAE [" + (output_unit.empty() ? "" : output_unit + " ") + "s]",
      "RMSE",   "max |error|",   "flags",
      "notes"};
  for (const auto& model : models) {
    FitMetrics fit;
    fit.fit_percent = model.fit_percent;
    fit.iae = model.iae;
    fit.rmse = fit.max_abs_error = std::numeric_limits<double>::quiet_NaN();
    try {
      fit = EvaluateModel(model, data, signals.input, signals.output);
    } catch (const InvalidArgument&) {
    }
    std::string flags, notes;
    for (const auto& flagged : model.flags)
      flags += (flags.empty() ? "" : "; ") + ToString(flagged.flag) + ": " + flagged.reason;
    for (const auto& note : model.notes) notes += (notes.empty() ? "" : "; ") + note;
    table.rows.push_back({model.method, Num(fit.fit_percent), Num(fit.iae), Num(fit.rmse),
                          Num(fit.max_abs_error), flags.empty() ? "-" : flags, notes});
  }
  return table;
}

// Models section: parameter and fit tables, and the methods that failed.
void AddModelsSection(HtmlDocument& doc, const ReportSummary& summary, const Dataset& data,
                      const ReportSignals& signals) {
  doc.AddHeading("Models");
  if (!summary.models.empty()) {
    doc.AddTable(ParameterTable(summary.models));
    doc.AddTable(FitTable(summary.models, data, signals));
  }
  if (!summary.failures.empty()) {
    doc.AddHeading("Methods that gave no model", 3);
    std::vector<std::string> items;
    for (const auto& [method, failure] : summary.failures) items.push_back(method + ": " + failure);
    doc.AddList(items);
  }
}

// The models sorted for the figures. Every model is compared with the data;
// the step and frequency responses leave out models flagged unstable, not
// finite or with a Nyquist pole, whose responses are not the plant's (and
// would set the axes).
struct FigureModels {
  std::vector<NamedModel> all;         ///< every model, for the comparison with the data
  std::vector<NamedModel> trusted;     ///< drawn in the step and frequency responses
  std::vector<std::string> left_out;   ///< methods of the flagged models
  std::vector<std::string> nonlinear;  ///< methods of the nonlinear models
  std::vector<NamedStaticMap> maps;    ///< the models' static input maps
};

FigureModels SortModelsForFigures(const std::vector<IdentifiedModel>& models, double confidence) {
  FigureModels sorted;
  for (const auto& model : models) {
    NamedModel named{model.method + " (" + model.structure + ")",
                     model.discrete ? *model.discrete : model.tf, model.u0, model.y0};
    // The comparison simulates nonlinear models as they are; the bands need it too.
    if (confidence > 0.0 || IsNonlinearModel(model))
      named.identified = std::make_shared<const IdentifiedModel>(model);
    sorted.all.push_back(named);
    if (model.input_map)
      sorted.maps.push_back({model.method, *model.input_map, model.narx.has_value()});
    if (IsNonlinearModel(model)) {
      sorted.nonlinear.push_back(model.method);  // no single step or frequency response
    } else if (RankGroup(model) == 0) {
      sorted.trusted.push_back(named);
    } else {
      sorted.left_out.push_back(model.method);
    }
  }
  return sorted;
}

// Caption sentences naming the models the response figures leave out.
std::string LeftOutText(const FigureModels& sorted) {
  std::string text = sorted.left_out.empty()
                         ? ""
                         : fmt::format(" Left out (flagged, see the fit table): {}.",
                                       fmt::join(sorted.left_out, ", "));
  if (!sorted.nonlinear.empty())
    text += fmt::format(
        " Not drawn: the nonlinear models ({}), whose responses depend on the operating "
        "point (their static maps are drawn below).",
        fmt::join(sorted.nonlinear, ", "));
  return text;
}

// Step responses (to the data's input step, else 1) and Bode diagram of the
// trusted models, with confidence bands when asked for.
void AddResponseFigures(HtmlDocument& doc, const Dataset& data, const ReportOptions& options,
                        const ReportSignals& signals, const FigureModels& sorted) {
  StepFigureOptions step_options;
  step_options.labels = signals.labels;
  step_options.title = "Step responses of the models";
  double du = 1.0;
  try {
    du = AnalyzeStep(data, signals.input, signals.output).du;
  } catch (const DataError&) {
  }
  step_options.amplitude = du;
  step_options.t_final = data.time()[data.size() - 1] - data.time()[0];
  step_options.confidence = options.confidence;
  const std::string band_text =
      options.confidence > 0.0
          ? fmt::format(
                " Shaded: \u00b1{:g} standard deviations of the models with a parameter "
                "covariance (first-order propagation).",
                options.confidence)
          : "";
  const std::string left_out_text = LeftOutText(sorted);
  if (!sorted.trusted.empty()) {
    doc.AddFigure(StepResponseFigure(sorted.trusted, step_options),
                  fmt::format("Responses of the models to an input step of {} (input units).{}{}",
                              Num(du), band_text, left_out_text));
    doc.AddFigure(BodeFigure(sorted.trusted, Eigen::VectorXd(), "Bode diagram", options.confidence),
                  "Frequency responses of the models." + band_text + left_out_text);
  }
}

// Residuals of the best model (the first of the ranking).
void AddResidualFigure(HtmlDocument& doc, const Dataset& data, const ReportOptions& options,
                       const ReportSignals& signals, const IdentifiedModel& best) {
  try {
    const Eigen::VectorXd residuals =
        data.y(signals.output) - SimulateModel(best, data, signals.input);
    const int lag = std::min<int>(options.residual_max_lag, static_cast<int>(data.size()) - 2);
    const ResidualCorrelation correlation = ComputeResidualCorrelation(
        residuals, data.u(signals.input), lag, options.residual_confidence);
    doc.AddFigure(ResidualFigure(correlation, "Residuals of " + best.method),
                  fmt::format("Residual analysis of the best-ranked model ({}): {:.0f} % of the "
                              "autocorrelation lags and {:.0f} % of the cross-correlation "
                              "lags lie outside the {:g} % band.",
                              best.method, 100.0 * correlation.auto_outside,
                              100.0 * correlation.cross_outside, 100.0 * correlation.confidence));
  } catch (const InvalidArgument& e) {
    doc.AddParagraph(std::string("Residual analysis not available: ") + e.what());
  }
}

// Figures section (when there are models): data and models, responses,
// static maps, residuals.
void AddFiguresSection(HtmlDocument& doc, const std::vector<IdentifiedModel>& models,
                       const Dataset& data, const ReportOptions& options,
                       const ReportSignals& signals) {
  if (models.empty()) return;
  const FigureModels sorted = SortModelsForFigures(models, options.confidence);
  doc.AddHeading("Figures");
  ComparisonFigureOptions comparison_options;
  comparison_options.labels = signals.labels;
  comparison_options.input = signals.input;
  comparison_options.output = signals.output;
  comparison_options.title = "Measured data and simulated models";
  doc.AddFigure(ModelComparisonFigure(data, sorted.all, comparison_options),
                "Measured output and each model driven by the measured input (deviation "
                "from the initial operating point), with the input below.");
  AddResponseFigures(doc, data, options, signals, sorted);
  if (!sorted.maps.empty()) {
    doc.AddFigure(StaticMapFigure(sorted.maps, signals.labels, "Static input maps"),
                  "The models' static input maps f(u): the steady output of a static-map "
                  "model, the input nonlinearity of a Hammerstein model (both in output "
                  "units), the valves' open fraction of an input-affine NARX (0..1).");
  }
  AddResidualFigure(doc, data, options, signals, models.front());
}

void AddReproduceSection(HtmlDocument& doc, const std::vector<std::string>& commands) {
  doc.AddHeading("Reproduce");
  if (commands.empty()) {
    doc.AddParagraph("No command lines were recorded for this report.");
  } else {
    doc.AddParagraph("The commands that reproduce this report:");
    doc.AddCommands(commands);
  }
}

// models.json: the data's source, every model and the methods that failed.
void WriteModelsJson(const ReportSummary& summary, const std::string& source) {
  nlohmann::json j = ModelFileDocument(summary.models);
  j["data"] = source;
  j["failures"] = nlohmann::json::array();
  for (const auto& [method, failure] : summary.failures)
    j["failures"].push_back({{"method", method}, {"error", failure}});
  SaveModelFile(summary.models_path, j);
}

void SetTermination(ReportSummary& summary, std::size_t num_methods) {
  if (summary.models.empty()) {
    summary.termination = Termination::kFailure;
    summary.message = "no method gave a model";
  } else if (!summary.failures.empty()) {
    summary.termination = Termination::kPartial;
    summary.message = fmt::format("{} of {} methods failed", summary.failures.size(), num_methods);
  } else {
    summary.termination = Termination::kSuccess;
    summary.message = "all methods gave a model";
  }
}

}  // namespace

ReportSummary WriteIdentificationReport(const Dataset& data, const ReportOptions& options,
                                        const std::string& dir) {
  CheckReportInputs(data, options);
  CreateReportDirectory(dir);

  ReportSummary summary;
  IdentifyReportModels(data, options, summary);

  const std::string source = data.source().empty() ? "(in-memory data)" : data.source();
  HtmlDocument doc(options.title.empty() ? "Identification report: " +
                                               std::filesystem::path(source).filename().string()
                                         : options.title);
  const ReportSignals signals = DescribeSignals(data, options.request);
  AddDataSection(doc, data, options, source, signals);
  AddModelsSection(doc, summary, data, signals);
  AddFiguresSection(doc, summary.models, data, options, signals);
  AddReproduceSection(doc, options.commands);

  summary.html_path = (std::filesystem::path(dir) / "report.html").string();
  summary.models_path = (std::filesystem::path(dir) / "models.json").string();
  doc.Write(summary.html_path);
  WriteModelsJson(summary, source);
  summary.num_figures = doc.num_figures();
  summary.num_tables = doc.num_tables();
  SetTermination(summary, options.methods.size());
  return summary;
}

}  // namespace pneumid
