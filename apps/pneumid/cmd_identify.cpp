// pneumid identify DATA --method M1,M2,...|all [--order N] [--json] [--plot FILE.png] [-o FILE]
//
// Identifies models of a plant from measured data with the step-response
// methods (reaction curve, tangent, two-point, SOPDT, PTn, Strejc, areas,
// process-model fits), the parametric ones (ARX, ARMAX, OE, BJ, IV4,
// N4SID, CRA, SPA) and the nonlinear ones (static map, Hammerstein, Wiener,
// Hammerstein-Wiener, NARX), and lists them best fit first.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <optional>
#include <type_traits>
#include <variant>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "command_json.hpp"
#include "data_options.hpp"
#include "output_options.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/identify/identify.hpp"
#include "pneumid/report/plot.hpp"
#include "pneumid/workflow/identify_workflow.hpp"
#include "progress.hpp"
#include "validators.hpp"

namespace pneumid::cli {
namespace {

// "K=1.6 a=[1 -0.6 0.2] A=[[0.9] [0.1]] t=[200 values]": numbers with 4
// significant digits, arrays of more than 8 values by their size.
std::string FormatParams(const ModelParams& params) {
  auto array = [](const auto& xs, auto&& item) {
    if (xs.size() > 8) return fmt::format("[{} values]", xs.size());
    std::vector<std::string> items;
    for (const auto& x : xs) items.push_back(item(x));
    return fmt::format("[{}]", fmt::join(items, " "));
  };
  auto number = [](double x) { return fmt::format("{:.4g}", x); };
  std::vector<std::string> parts;
  for (const auto& [key, value] : params) {
    const std::string text = std::visit(
        [&](const auto& v) -> std::string {
          using T = std::decay_t<decltype(v)>;
          if constexpr (std::is_same_v<T, std::vector<std::vector<double>>>) {
            return array(v, [&](const std::vector<double>& row) { return array(row, number); });
          } else if constexpr (std::is_arithmetic_v<T>) {
            return number(v);
          } else {
            return array(v, number);
          }
        },
        value);
    parts.push_back(key + "=" + text);
  }
  return fmt::format("{}", fmt::join(parts, " "));
}

void WritePlot(const std::string& path, const Dataset& data, const IdentifyRequest& request,
               const std::vector<IdentifiedModel>& models) {
  Figure fig(2);
  fig.title = "Identified models" + (data.source().empty() ? "" : ": " + data.source());
  const Channel yc = request.output < static_cast<int>(data.output_channels().size())
                         ? data.output_channels()[request.output]
                         : Channel{"y", ""};
  const Channel uc = request.input < static_cast<int>(data.input_channels().size())
                         ? data.input_channels()[request.input]
                         : Channel{"u", ""};
  auto label = [](const Channel& c) {
    return c.unit.empty() ? c.name : fmt::format("{} [{}]", c.name, c.unit);
  };
  Axes& top = fig.axes(0);
  top.ylabel = label(yc);
  const Eigen::VectorXd y = data.y(request.output);
  top.AddLine(data.time(), y, "data");
  // The axis follows the data; at most the 8 best models with a positive fit are drawn.
  const double span = std::max(y.maxCoeff() - y.minCoeff(), 1e-12);
  top.ymin = y.minCoeff() - 0.15 * span;
  top.ymax = y.maxCoeff() + 0.15 * span;
  top.legend = LegendPosition::kBottomRight;
  int drawn = 0;
  for (const IdentifiedModel& m : models) {
    if (drawn >= 8 || !(m.fit_percent > 0.0)) break;
    ++drawn;
    try {
      const Eigen::VectorXd yhat = SimulateModel(m, data, request.input);
      if (yhat.allFinite()) {
        top.AddLine(data.time(), yhat, fmt::format("{} ({:.1f} %)", m.method, m.fit_percent));
      }
    } catch (const std::exception&) {
      // a model that cannot be simulated on these data is left out of the plot
    }
  }
  Axes& bottom = fig.axes(1);
  bottom.xlabel = "Time t [s]";
  bottom.ylabel = label(uc);
  bottom.legend = LegendPosition::kNone;
  bottom.AddStairs(data.time(), data.u(request.input), label(uc));
  fig.Save(path);
}

std::string FlagNames(const IdentifiedModel& m) {
  std::vector<std::string> names;
  for (const ModelFlagNote& f : m.flags) names.push_back(ToString(f.flag));
  return names.empty() ? "-" : fmt::format("{}", fmt::join(names, ","));
}

}  // namespace

IdentifyWorkflowOptions ToWorkflowOptions(const IdentifyArgs& args) {
  IdentifyWorkflowOptions o;
  o.methods = args.methods;
  o.preprocess.window = args.preprocess.window;
  o.preprocess.resample = args.preprocess.resample;
  o.preprocess.remove_initial = args.preprocess.remove_initial;
  o.preprocess.detrend = args.preprocess.detrend;
  o.preprocess.filter = args.preprocess.filter;
  o.preprocess.decimate = args.preprocess.decimate;
  o.request = args.request;
  o.loss = args.loss;
  o.nonlinear = args.nonlinear;
  o.split = args.split;
  return o;
}

namespace {

void Run(const IdentifyArgs& args) {
  std::optional<Dataset> validation_raw;
  if (!args.validation.empty()) {
    DataOptions v = args.data;
    v.path = args.validation;
    validation_raw.emplace(LoadFromOptions(v));
    RequireSingleInputOutput(*validation_raw, v, "identify");
  }
  const Dataset raw = LoadFromOptions(args.data);
  RequireSingleInputOutput(raw, args.data, "identify");
  IdentifyWorkflowResult outcome;
  {
    ProgressBar bar("identify", args.progress || StderrIsTerminal());
    outcome =
        RunIdentifyWorkflow(ToWorkflowOptions(args), raw,
                            validation_raw ? &*validation_raw : nullptr,
                            [&bar](std::size_t done, std::size_t total, const std::string& method) {
                              bar(static_cast<double>(done) / static_cast<double>(total), method);
                            });
  }
  for (const auto& [method, reason] : outcome.summary.failures)
    std::cerr << fmt::format("pneumid identify: {} failed: {}\n", method, reason);
  for (const std::string& w : outcome.summary.warnings)
    std::cerr << fmt::format("pneumid identify: warning: {}\n", w);
  if (outcome.summary.models.empty()) {
    // --json still prints what was tried, so that a script sees every
    // method's reason (the exit status is non-zero all the same).
    if (args.json) {
      nlohmann::json j = {{"models", nlohmann::json::array()},
                          {"best", nullptr},
                          {"failures", nlohmann::json::array()},
                          {"termination", ToString(outcome.summary.termination)},
                          {"message", outcome.summary.message},
                          {"warnings", outcome.summary.warnings}};
      for (const auto& [method, reason] : outcome.summary.failures)
        j["failures"].push_back({{"method", method}, {"reason", reason}});
      std::cout << j.dump(2) << "\n";
    }
    throw DataError(outcome.summary.message);
  }
  const Dataset& data = outcome.data;
  const PreprocessRecord& record = outcome.record;
  const IdentificationSummary& summary = outcome.summary;
  const std::vector<IdentifiedModel>& models = summary.models;
  const bool held_out = summary.validation_samples > 0;
  const std::optional<Dataset>& validation = validation_raw;
  const nlohmann::json j = outcome.ToJson();
  if (!args.output.empty()) SaveModelFile(args.output, j);
  if (!args.plot.empty()) WritePlot(args.plot, data, args.request, models);

  if (args.json && !args.output.empty()) {
    // The models are in the file: a short summary here, not the same JSON twice.
    nlohmann::ordered_json brief;
    brief["output"] = args.output;
    brief["models"] = nlohmann::json::array();
    for (const IdentifiedModel& m : models) {
      nlohmann::ordered_json b = {
          {"method", m.method}, {"structure", m.structure}, {"fit_percent", m.fit_percent}};
      if (held_out) b["validation_fit_percent"] = JsonNumber(m.validation_fit_percent);
      b["flags"] = nlohmann::json::array();
      for (const ModelFlagNote& f : m.flags) b["flags"].push_back(ToString(f.flag));
      b["rank_reason"] = RankReason(m);
      brief["models"].push_back(b);
    }
    brief["best"] = models.front().method;
    brief["failures"] = j["failures"];
    brief["termination"] = j["termination"];
    brief["warnings"] = j["warnings"];
    if (!args.plot.empty()) brief["plot"] = args.plot;
    std::cout << brief.dump(2) << "\n";
    return;
  }
  if (args.json) {
    std::cout << j.dump(2) << "\n";
    return;
  }
  std::cout << fmt::format("{} samples, Ts = {:g} s{}\n", data.size(), data.SampleTime(),
                           data.source().empty() ? "" : ", from " + data.source());
  for (const std::string& step : record.steps) std::cout << "preprocessing: " << step << "\n";
  if (held_out)
    std::cout << fmt::format("estimated on {} samples, validated on {} held-out samples{}\n",
                             summary.estimation_samples, summary.validation_samples,
                             validation ? " of " + validation->source() : "");
  std::cout << fmt::format("{:<16} {:<10} {:>9}{} {:>11}  {:<20} {}\n", "method", "structure",
                           "fit %", held_out ? fmt::format(" {:>9}", "val fit %") : "", "IAE",
                           "flags", "parameters");
  for (const IdentifiedModel& m : models) {
    std::cout << fmt::format("{:<16} {:<10} {:>9.2f}{} {:>11.4g}  {:<20} {}\n", m.method,
                             m.structure, m.fit_percent,
                             held_out ? fmt::format(" {:>9.2f}", m.validation_fit_percent) : "",
                             m.iae, FlagNames(m), FormatParams(m.params));
    for (const ModelFlagNote& f : m.flags)
      std::cout << fmt::format("{:<16} flag {}: {}\n", "", ToString(f.flag), f.reason);
    for (const std::string& note : m.notes) std::cout << fmt::format("{:<16} note: {}\n", "", note);
  }
  const IdentifiedModel& best = models.front();
  std::cout << fmt::format("best: {} ({:.2f} % {}fit): {}\n", best.method, RankScore(best),
                           held_out ? "validation " : "", RankReason(best));
  if (!summary.failures.empty())
    std::cout << fmt::format("failed: {}\n", [&] {
      std::vector<std::string> f;
      for (const auto& [method, reason] : summary.failures) f.push_back(method);
      return fmt::format("{}", fmt::join(f, ", "));
    }());
  if (!args.plot.empty()) std::cout << "plot written to " << args.plot << "\n";
  if (!args.output.empty()) std::cout << "models written to " << args.output << "\n";
}

static Registrar reg(
    "identify", "Identify models (step-response, process-model fits, ARX/ARMAX/OE/BJ, ...)",
    [](CLI::App& app) {
      auto args = std::make_shared<IdentifyArgs>();
      AddDataOptions(app, args->data);
      AddPreprocessOptions(app, args->preprocess);
      app.add_option("-m,--method,--methods", args->methods,
                     "Comma-separated methods, all, or auto (the reaction curve for a step "
                     "test, else fit-p1d, arx, oe, bj, iv4): reaction-curve, tangent, smith, "
                     "sundaresan, broida, sopdt, ptn, strejc, areas, fit-p1d, fit-p2d, fit-p2du, "
                     "fit-p3d, fit-p1di, arx, armax, oe, bj, iv4, n4sid, cra, spa; nonlinear "
                     "(not in all): static-map, hammerstein, wiener, hw, narx, affine-narx")
          ->capture_default_str();
      app.add_option("--order", args->request.order, "PTn order n (ptn)")
          ->capture_default_str()
          ->check(CLI::Range(1, 20));
      CLI::Option* na =
          app.add_option("--na", args->request.na,
                         "A order (arx, armax, iv4; n4sid state order); hammerstein, wiener, hw, "
                         "narx: when none of --na --nb --nk is given, they (narx: lags, delay and "
                         "terms) are chosen on held-out data (--validation, else the last 30 % of "
                         "DATA) and the choice is noted")
              ->capture_default_str();
      CLI::Option* nb = app.add_option("--nb", args->request.nb, "B order")->capture_default_str();
      CLI::Option* nk =
          app.add_option("--nk", args->request.nk, "input delay in samples")->capture_default_str();
      app.add_option("--nc", args->request.nc, "C order (armax, bj)")->capture_default_str();
      app.add_option("--nd", args->request.nd, "D order (bj)")->capture_default_str();
      app.add_option("--nf", args->request.nf, "F order (oe, bj)")->capture_default_str();
      app.add_flag("--feedthrough", args->request.feedthrough,
                   "n4sid: estimate the direct term D (default D = 0)");
      app.add_option_function<std::string>(
             "--n4sid-weight",
             [args](const std::string& s) {
               args->request.n4sid_weight = SubspaceWeightingFromString(s);
             },
             "n4sid weighting (MATLAB N4Weight): moesp (default), n4sid, cva")
          ->check(NameOf([](const std::string& s) { SubspaceWeightingFromString(s); }));
      app.add_option_function<std::string>(
             "--operating-point",
             [args](const std::string& s) {
               args->request.operating_point = OperatingPointKindFromString(s);
             },
             "arx, iv4, armax, oe, bj, n4sid: the levels (u0, y0) the model is identified "
             "around: auto (default: zero for a record that starts at rest at zero, else the "
             "raw signals or the means, whichever simulates the data better), zero (the raw "
             "signals), mean, initial (the first samples' level)")
          ->check(NameOf([](const std::string& s) { OperatingPointKindFromString(s); }));
      app.add_option(
             "--knots", args->nonlinear.block.num_knots,
             "hammerstein, wiener, hw, affine-narx: knots of the static map, spread evenly over "
             "the input range (hw: as many for the output map, over the range of G f(u)); "
             "default: where the data are (the levels of a staircase or multi-level input, "
             "else 11 quantiles; wiener: of G u)")
          ->check(CLI::Range(2, 1000));
      app.add_flag("--monotone-map", args->nonlinear.block.monotone_map,
                   "hammerstein: keep the input map monotone (invertible)");
      app.add_option("--settle", args->nonlinear.static_map.settle_fraction,
                     "static-map: fraction of each constant-input segment averaged (its end)")
          ->capture_default_str()
          ->check(InRange(0.01, 1.0));
      app.add_option("--min-segment", args->nonlinear.static_map.min_segment_duration,
                     "static-map: shortest constant-input segment used, s")
          ->capture_default_str()
          ->check(CLI::NonNegativeNumber);
      app.add_option("--degree", args->nonlinear.narx.degree,
                     "narx: polynomial degree (lags: ny = --na, nu = --nb, delay --nk); "
                     "affine-narx: degree "
                     "of its a(y) and b(y)")
          ->capture_default_str()
          ->check(CLI::Range(1, 3));
      CLI::Option* max_terms =
          app.add_option("--max-terms", args->nonlinear.narx.max_terms,
                         "narx: most terms selected (without --na --nb --nk: the largest number "
                         "the structure search tries, default 60)")
              ->capture_default_str()
              ->check(CLI::Range(1, 1000));
      app.add_option_function<std::string>(
             "--focus",
             [args](const std::string& name) {
               args->nonlinear.narx.focus = NarxFocusFromString(name);
             },
             "narx: criterion of the coefficients of the selected terms: prediction (one-step "
             "least squares) or simulation (refined by the free-run simulation error; the "
             "structure search then scores refined candidates)")
          ->check(CLI::IsMember({"prediction", "simulation"}))
          ->default_str("prediction");
      app.add_option("--err-tolerance", args->nonlinear.narx.err_tolerance,
                     "narx: stop when 1 - sum ERR falls below this")
          ->capture_default_str()
          ->check(InRange(1e-15, 0.999999));
      app.add_option("--loss", args->loss, "Loss of the fit-* methods: none, huber, cauchy")
          ->capture_default_str();
      app.add_flag("--json", args->json,
                   "Print {\"models\": [...]} as JSON, best first (with -o: the file name and "
                   "each model's method, structure and fit_percent)");
      AddPlotOption(app, args->plot,
                    "the data and the responses of the (up to 8) best models with a positive fit");
      app.add_option("-o,--output", args->output,
                     "Write the models as JSON ({\"models\": [...]}) to this file");
      app.add_option("--validation", args->validation,
                     "Held-out data file (same columns as DATA): models are ranked by their "
                     "simulation fit on it")
          ->check(CLI::ExistingFile);
      app.add_option("--split", args->split,
                     "Estimate on the first fraction of DATA (0 < F < 1, e.g. 0.7) and rank by "
                     "the fit on the rest (0, the default: the structure is chosen on the last "
                     "30 % and the models estimated on the whole record)")
          ->check(InRange(0.0, 1.0));
      app.add_flag("--progress", args->progress,
                   "Draw the progress bar even when stderr is not a terminal");
      app.callback([args, na, nb, nk, max_terms] {
        args->nonlinear.choose_structure = na->count() == 0 && nb->count() == 0 && nk->count() == 0;
        const std::vector<std::string> methods =
            args->methods == "auto" ? std::vector<std::string>{} : ParseMethodList(args->methods);
        if ((na->count() > 0 || nb->count() > 0) &&
            std::find(methods.begin(), methods.end(), "affine-narx") != methods.end())
          std::cerr << "pneumid identify: warning: affine-narx is first order (y(t-1) and "
                       "f(u(t-nk))): --na and --nb do not change it; --nk, --degree and --knots "
                       "do\n";
        if (max_terms->count() > 0) args->nonlinear.max_narx_terms = args->nonlinear.narx.max_terms;
        Run(*args);
      });
    });

}  // namespace
}  // namespace pneumid::cli
