// pneumid identify DATA --method M1,M2,...|all [--order N] [--json] [--plot FILE.png] [-o FILE]
//
// Identifies models of a plant from measured data with the step-response
// methods (reaction curve, tangent, two-point, SOPDT, PTn, Strejc, areas,
// process-model fits) and the parametric ones (ARX, ARMAX, OE, BJ, IV4,
// N4SID, CRA, SPA), and lists them best fit first.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <type_traits>
#include <variant>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "data_options.hpp"
#include "output_options.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/identify/identify.hpp"
#include "pneumid/report/plot.hpp"

namespace pneumid::cli {
namespace {

struct IdentifyArgs {
  DataOptions data;
  std::string methods = "reaction-curve";
  IdentifyRequest request;
  std::string loss = "none";
  bool json = false;
  std::string plot;
  std::string output;
};

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

void Progress(std::size_t i, std::size_t n, const std::string& method) {
  if (!StderrIsTerminal() || n < 2) return;
  const int width = 30;
  const int filled = static_cast<int>(width * i / n);
  std::cerr << fmt::format("\ridentify [{}{}] {}/{} {:<16}", std::string(filled, '#'),
                           std::string(width - filled, '.'), i, n, method)
            << std::flush;
  if (i == n) std::cerr << "\r" << std::string(width + 40, ' ') << "\r" << std::flush;
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
    const double y0 = m.params.FindScalar("y0").value_or(std::numeric_limits<double>::quiet_NaN());
    try {
      const Eigen::VectorXd yhat =
          SimulateOnData(m.discrete ? *m.discrete : m.tf, data, request.input, request.output, y0);
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

void Run(const IdentifyArgs& args) {
  std::string why;
  PNEUMID_CHECK(args.request.IsValid(&why), "{}", why);
  const std::vector<std::string> methods = ParseMethodList(args.methods);
  const bool all_requested = args.methods.find("all") != std::string::npos;
  const Dataset data = LoadFromOptions(args.data);
  IdentifyOptions options;
  options.step.fit.loss = RobustLossFromString(args.loss);

  std::vector<IdentifiedModel> models;
  for (std::size_t i = 0; i < methods.size(); ++i) {
    Progress(i, methods.size(), methods[i]);
    const std::string& m = methods[i];
    try {
      models.push_back(Identify(m, data, args.request, options));
    } catch (const std::exception& e) {
      // With "all", a method that does not suit the data is skipped with a
      // warning; a method asked for by name fails the command.
      if (!all_requested) {
        throw DataError(fmt::format("{}: {}", m, e.what()));
      }
      std::cerr << fmt::format("pneumid identify: warning: {} skipped: {}\n", m, e.what());
    }
  }
  Progress(methods.size(), methods.size(), "");
  if (models.empty()) throw DataError("no method produced a model for these data");
  std::stable_sort(models.begin(), models.end(),
                   [](const auto& a, const auto& b) { return a.fit_percent > b.fit_percent; });

  nlohmann::json j;
  j["models"] = nlohmann::json::array();
  for (const IdentifiedModel& m : models) j["models"].push_back(ToJson(m));
  if (!args.output.empty()) WriteJsonFile(j, args.output);
  if (!args.plot.empty()) WritePlot(args.plot, data, args.request, models);

  if (args.json && !args.output.empty()) {
    // The models are in the file: a short summary here, not the same JSON twice.
    nlohmann::ordered_json brief;
    brief["output"] = args.output;
    brief["models"] = nlohmann::json::array();
    for (const IdentifiedModel& m : models)
      brief["models"].push_back(
          {{"method", m.method}, {"structure", m.structure}, {"fit_percent", m.fit_percent}});
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
  std::cout << fmt::format("{:<16} {:<10} {:>9} {:>11}  {}\n", "method", "structure", "fit %",
                           "IAE", "parameters");
  for (const IdentifiedModel& m : models) {
    std::cout << fmt::format("{:<16} {:<10} {:>9.2f} {:>11.4g}  {}\n", m.method, m.structure,
                             m.fit_percent, m.iae, FormatParams(m.params));
    for (const std::string& note : m.notes) std::cout << fmt::format("{:<16} note: {}\n", "", note);
  }
  if (!args.plot.empty()) std::cout << "plot written to " << args.plot << "\n";
  if (!args.output.empty()) std::cout << "models written to " << args.output << "\n";
}

static Registrar reg(
    "identify", "Identify models (step-response, process-model fits, ARX/ARMAX/OE/BJ, ...)",
    [](CLI::App& app) {
      auto args = std::make_shared<IdentifyArgs>();
      AddDataOptions(app, args->data);
      app.add_option("-m,--method,--methods", args->methods,
                     "Comma-separated methods, or all: reaction-curve, tangent, smith, "
                     "sundaresan, broida, sopdt, ptn, strejc, areas, fit-p1d, fit-p2d, fit-p2du, "
                     "fit-p3d, fit-p1di, arx, armax, oe, bj, iv4, n4sid, cra, spa")
          ->capture_default_str();
      app.add_option("--order", args->request.order, "PTn order n (ptn)")
          ->capture_default_str()
          ->check(CLI::Range(1, 20));
      app.add_option("--na", args->request.na, "A order (arx, armax, iv4; n4sid state order)")
          ->capture_default_str();
      app.add_option("--nb", args->request.nb, "B order")->capture_default_str();
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
          ->check([](const std::string& s) {
            try {
              SubspaceWeightingFromString(s);
              return std::string();
            } catch (const InvalidArgument& e) {
              return std::string(e.what());
            }
          });
      app.add_option("--loss", args->loss, "Loss of the fit-* methods: none, huber, cauchy")
          ->capture_default_str();
      app.add_flag("--json", args->json,
                   "Print {\"models\": [...]} as JSON, best first (with -o: the file name and "
                   "each model's method, structure and fit_percent)");
      AddPlotOption(app, args->plot,
                    "the data and the responses of the (up to 8) best models with a positive fit");
      app.add_option("-o,--output", args->output,
                     "Write the models as JSON ({\"models\": [...]}) to this file");
      app.callback([args] { Run(*args); });
    });

}  // namespace
}  // namespace pneumid::cli
