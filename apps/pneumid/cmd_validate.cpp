// pneumid validate MODEL.json DATA: simulation / k-step prediction fit and the
// residual tests of MATLAB compare and resid, with an optional plot.
#include <fstream>
#include <iostream>
#include <memory>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "data_options.hpp"
#include "identified_spec.hpp"
#include "output_options.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/data/preprocess.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/evaluation/model_evaluation.hpp"
#include "pneumid/identify/evaluation/residual_analysis.hpp"
#include "pneumid/identify/evaluation/validation.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/identify/nonlinear/nonlinear.hpp"
#include "pneumid/identify/parametric/parametric_model.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/report/plot.hpp"
#include "validators.hpp"

namespace pneumid::cli {
namespace {

struct ValidateArgs {
  std::string model;
  DataOptions data;
  PreprocessArgs preprocess;
  int horizon = 0;
  int max_lag = 25;
  int skip = 0;
  std::string initial_state = "zero";
  std::string plot;
  std::string output;  // trace CSV: t, u, y, y_model
  bool json = false;
};

// The trace of the validation: t, u, y, y_model (and y_pred with --horizon).
void WriteTrace(const std::string& path, const Dataset& data, const CompareResult& sim,
                const CompareResult* pred, int horizon) {
  std::ofstream f(path);
  PNEUMID_CHECK(f.good(), "cannot write the trace file {}", path);
  f << "t,u,y,y_model" << (pred ? fmt::format(",y_pred{}", horizon) : "") << "\n";
  const Eigen::VectorXd u = data.u(0);
  for (Eigen::Index i = 0; i < sim.t.size(); ++i) {
    f << fmt::format("{},{},{},{}", sim.t[i], u[i], sim.y[i], sim.yhat[i]);
    if (pred) f << fmt::format(",{}", i < pred->yhat.size() ? pred->yhat[i] : 0.0);
    f << "\n";
  }
  PNEUMID_CHECK(f.good(), "writing the trace file {} failed", path);
}

// The polynomial form of an identified ARX/ARMAX/OE/BJ model (k-step prediction
// and prediction-error residuals need its noise model).
std::optional<PolynomialModel> PolynomialOf(const IdentifiedModel& m) {
  if (!m.params.contains("a") || !m.params.contains("b") || !m.params.contains("Ts"))
    return std::nullopt;
  return PolynomialModelFromParams(m.params, m.structure);
}

// Runs a residual analysis; returns why it is undefined (a constant input or
// residual has no correlation) instead of failing the command, "" on success.
template <typename Analyze>
std::string TryResiduals(ResidualAnalysis* out, Analyze&& analyze) {
  try {
    *out = analyze();
    return "";
  } catch (const InvalidArgument& e) {
    return e.what();
  }
}

// Simulation fit of an identified model (its operating point applied).
CompareResult SimulateIdentified(const IdentifiedModel& m, const Dataset& data, int skip,
                                 InitialCondition initial) {
  PNEUMID_CHECK(skip + 2 <= data.size(), "--skip {} leaves fewer than 2 of the {} samples", skip,
                data.size());
  CompareResult r;
  r.t = data.time();
  r.y = data.y(0);
  r.yhat = SimulateModel(m, data, 0, 0, initial);
  const FitMetrics f = ScoreSimulation(data, 0, r.yhat, skip);
  r.fit_percent = f.fit_percent;
  r.rmse = f.rmse;
  return r;
}

/// The data to validate on: the command's preprocessing, then the model's own
/// (recorded when it was identified, with its offsets): together they would
/// remove offsets twice, so only a window may be added to a model's preprocessing.
Dataset LoadValidationData(const ValidateArgs& args,
                           const std::optional<IdentifiedModel>& identified) {
  const PreprocessOptions prep = ToPreprocessOptions(args.preprocess);
  Dataset loaded = LoadFromOptions(args.data);
  RequireSingleInputOutput(loaded, args.data, "validate");
  Dataset data = Preprocess(std::move(loaded), prep);
  if (identified && identified->preprocessing) {
    PreprocessOptions rest = prep;
    rest.window = {};
    PNEUMID_CHECK(rest.IsIdentity(),
                  "{} carries the preprocessing it was identified with ({}); it is applied to "
                  "the data, so give no other preprocessing flag than --window",
                  args.model, fmt::join(identified->preprocessing->steps, "; "));
    data = ApplyRecorded(data, *identified->preprocessing);
  }
  return data;
}

/// The fits and residual tests of a model on the data.
struct ValidationResult {
  CompareResult sim;   ///< simulation
  CompareResult pred;  ///< k-step prediction, when have_pred
  bool have_pred = false;
  std::vector<std::string> warnings;  ///< the data leave the model's identification range
  ResidualAnalysis residuals;
  std::string residuals_unavailable;  ///< why the residual tests are undefined (constant input)
};

/// Validates an identified model: simulation, k-step prediction (polynomial
/// models with --horizon) and residual tests.
ValidationResult ValidateIdentified(const ValidateArgs& args, const IdentifiedModel& identified,
                                    const std::optional<PolynomialModel>& poly, const Dataset& data,
                                    InitialCondition initial) {
  CompareOptions compare;
  compare.skip = args.skip;
  ResidualAnalysisOptions residual_options;
  residual_options.max_lag = args.max_lag;
  ValidationResult result;
  result.sim = SimulateIdentified(identified, data, args.skip, initial);
  result.warnings = ExtrapolationWarnings(identified, data, 0, &result.sim.yhat);
  for (const std::string& w : result.warnings) {
    std::cerr << "pneumid validate: warning: " << w << "\n";
  }
  PNEUMID_CHECK(args.horizon == 0 || poly,
                "--horizon needs a polynomial model with a noise model; '{}' is a {} model "
                "(simulation only)",
                args.model, identified.structure);
  // The polynomial form acts on the deviations from the model's operating point.
  OperatingPoint op{Eigen::VectorXd::Zero(data.num_inputs()),
                    Eigen::VectorXd::Zero(data.num_outputs())};
  op.u0[compare.input] = identified.u0;
  op.y0[compare.output] = identified.y0;
  const Dataset deviations = SubtractOperatingPoint(data, op);
  if (args.horizon > 0) {
    compare.horizon = args.horizon;
    result.pred = Compare(*poly, deviations, compare);
    result.pred.y.array() += identified.y0;
    result.pred.yhat.array() += identified.y0;
    result.have_pred = true;
  }
  const CompareResult& sim = result.sim;
  result.residuals_unavailable = TryResiduals(&result.residuals, [&] {
    return poly ? AnalyzeResiduals(*poly, deviations, residual_options)
                : AnalyzeResiduals(sim.y - sim.yhat, data.u(0), residual_options);
  });
  return result;
}

/// Validates a model spec (a transfer function): simulation and residual tests.
ValidationResult ValidateModelSpec(const ValidateArgs& args, const Dataset& data,
                                   InitialCondition initial) {
  PNEUMID_CHECK(args.horizon == 0,
                "--horizon needs a polynomial model with a noise model; '{}' is a transfer "
                "function (simulation only)",
                args.model);
  CompareOptions compare;
  compare.skip = args.skip;
  ResidualAnalysisOptions residual_options;
  residual_options.max_lag = args.max_lag;
  ValidationResult result;
  const TransferFunction g = ParseModelSpec(args.model);
  if (initial == InitialCondition::kZero) {
    result.sim = Compare(g, data, compare);
  } else {
    IdentifiedModel m;  // a model spec acts on the signals as they are (u0 = y0 = 0)
    m.method = args.model;
    m.tf = g;
    result.sim = SimulateIdentified(m, data, args.skip, initial);
  }
  const CompareResult& sim = result.sim;
  result.residuals_unavailable = TryResiduals(&result.residuals, [&] {
    return AnalyzeResiduals(sim.y - sim.yhat, data.u(0), residual_options);
  });
  return result;
}

/// Plots data, simulation (and prediction) and, when defined, the residual correlations.
void PlotValidation(const ValidateArgs& args, const std::string& label,
                    const ValidationResult& result) {
  const CompareResult& sim = result.sim;
  const ResidualAnalysis& res = result.residuals;
  const bool show_residuals = result.residuals_unavailable.empty();
  Figure fig(show_residuals ? 3 : 1);
  fig.title = fmt::format("Validation of {}", label);
  auto& ax = fig.axes(0);
  ax.title = fmt::format("simulation fit {:.2f} %", sim.fit_percent);
  ax.xlabel = "time [s]";
  ax.ylabel = "output";
  ax.AddLine(sim.t, sim.y, "data");
  ax.AddLine(sim.t, sim.yhat, "simulated");
  if (result.have_pred)
    ax.AddLine(result.pred.t, result.pred.yhat, fmt::format("{}-step prediction", args.horizon),
               LineStyle::kDashed);
  if (show_residuals) {
    auto& ac = fig.axes(1);
    ac.title = fmt::format("residual autocorrelation: {}", res.whiteness_passed ? "pass" : "fail");
    ac.xlabel = "lag [samples]";
    ac.AddLine(res.lags_auto, res.autocorr, "r_e");
    ac.AddHorizontalLine(res.bound, "99 % bound");
    ac.AddHorizontalLine(-res.bound);
    auto& xc = fig.axes(2);
    xc.title = fmt::format("residual-input cross-correlation: {}",
                           res.independence_passed ? "pass" : "fail");
    xc.xlabel = "lag [samples]";
    xc.AddLine(res.lags_cross, res.crosscorr, "r_eu");
    xc.AddHorizontalLine(res.bound, "99 % bound");
    xc.AddHorizontalLine(-res.bound);
  }
  fig.Save(args.plot);
}

void PrintJson(const ValidateArgs& args, const std::string& label, const Dataset& data,
               InitialCondition initial, const ValidationResult& result) {
  nlohmann::json j;
  j["model"] = label;
  j["samples"] = data.size();
  j["fit_percent"] = result.sim.fit_percent;
  j["warnings"] = result.warnings;
  j["initial_state"] = ToString(initial);
  j["rmse"] = result.sim.rmse;
  if (result.have_pred) {
    j["prediction"] = {{"horizon", args.horizon},
                       {"fit_percent", result.pred.fit_percent},
                       {"rmse", result.pred.rmse}};
  }
  if (result.residuals_unavailable.empty()) {
    j["residuals"] = result.residuals.ToJson();
  } else {
    j["residuals"] = nullptr;
    j["residuals_unavailable"] = result.residuals_unavailable;
  }
  if (!args.plot.empty()) j["plot"] = args.plot;
  std::cout << j.dump(2) << "\n";
}

void PrintText(const ValidateArgs& args, const std::string& label, const Dataset& data,
               const ValidationResult& result) {
  const CompareResult& sim = result.sim;
  const ResidualAnalysis& res = result.residuals;
  std::cout << fmt::format("model: {}\ndata: {} samples, Ts = {:g} s\n", label, data.size(),
                           data.SampleTime());
  std::cout << fmt::format("simulation fit: {:.2f} % (NRMSE), RMSE {:.6g}\n", sim.fit_percent,
                           sim.rmse);
  if (result.have_pred)
    std::cout << fmt::format("{}-step prediction fit: {:.2f} %, RMSE {:.6g}\n", args.horizon,
                             result.pred.fit_percent, result.pred.rmse);
  if (!result.residuals_unavailable.empty()) {
    std::cout << "residual analysis: not available: " << result.residuals_unavailable << "\n";
    if (!args.plot.empty()) std::cout << "plot written to " << args.plot << "\n";
    return;
  }
  std::cout << fmt::format("residual analysis (max lag {}, 99 % bound +-{:.4g}):\n", args.max_lag,
                           res.bound);
  std::cout << fmt::format(
      "  whiteness:    {} (Q = {:.4g}, chi2 limit {:.4g}; {} of {} lags outside)\n",
      res.whiteness_passed ? "pass" : "FAIL", res.whiteness_statistic, res.whiteness_threshold,
      res.auto_outside, res.autocorr.size() - 1);
  std::cout << fmt::format(
      "  independence: {} (Q = {:.4g}, chi2 limit {:.4g}; {} of {} lags outside)\n",
      res.independence_passed ? "pass" : "FAIL", res.independence_statistic,
      res.independence_threshold, res.cross_outside, res.crosscorr.size());
  std::cout << fmt::format("verdict: {}\n", res.passed() ? "pass" : "FAIL");
  if (!args.plot.empty()) std::cout << "plot written to " << args.plot << "\n";
}

void Run(const ValidateArgs& args) {
  PNEUMID_CHECK(args.horizon >= 0, "--horizon must be >= 0 (0 = simulation), got {}", args.horizon);
  std::string label = args.model;
  const std::optional<IdentifiedModel> identified = ReadIdentified(args.model);
  const Dataset data = LoadValidationData(args, identified);
  std::optional<PolynomialModel> poly;
  if (identified) {
    label = fmt::format("{} {}", identified->method, identified->structure);
    poly = PolynomialOf(*identified);
  }
  const InitialCondition initial = InitialConditionFromString(args.initial_state);
  const ValidationResult result = identified
                                      ? ValidateIdentified(args, *identified, poly, data, initial)
                                      : ValidateModelSpec(args, data, initial);
  if (!args.output.empty()) {
    WriteTrace(args.output, data, result.sim, result.have_pred ? &result.pred : nullptr,
               args.horizon);
  }
  if (!args.plot.empty()) PlotValidation(args, label, result);
  if (args.json) {
    PrintJson(args, label, data, initial, result);
  } else {
    PrintText(args, label, data, result);
  }
}

static Registrar reg(
    "validate", "Fit (simulation, k-step prediction) and residual tests of a model on data",
    [](CLI::App& app) {
      auto args = std::make_shared<ValidateArgs>();
      app.add_option("MODEL", args->model,
                     "Model: JSON written by `pneumid identify --json` (FILE.json[#method]) or "
                     "any model spec (arx-paper, tf:..., fopdt:...)")
          ->required();
      AddDataOptions(app, args->data);
      AddPreprocessOptions(app, args->preprocess);
      app.add_option("--horizon", args->horizon,
                     "Also report the k-step-ahead prediction fit (polynomial models)")
          ->check(AtLeast(1));
      app.add_option("--max-lag", args->max_lag, "Largest correlation lag of the residual tests")
          ->capture_default_str()
          ->check(AtLeast(1));
      app.add_option("--initial-state", args->initial_state,
                     "Start of the simulation: zero (at rest at the model's operating point) or "
                     "estimate (the state that best explains the data, as MATLAB compare's 'e')")
          ->capture_default_str()
          ->check(CLI::IsMember({"zero", "estimate"}));
      app.add_option("--skip", args->skip, "Initial samples left out of the fit")
          ->capture_default_str()
          ->check(AtLeast(0));
      AddPlotOption(app, args->plot, "data/model and residual correlations");
      app.add_option("-o,--output", args->output,
                     "Write the trace as CSV: t, u, y, y_model (and y_predK with --horizon K)");
      app.add_flag("--json", args->json, "Print the results as JSON");
      app.callback([args] { Run(*args); });
    });

}  // namespace
}  // namespace pneumid::cli
