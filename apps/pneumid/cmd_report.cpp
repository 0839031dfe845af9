// pneumid report DATA [--methods M,...] -o DIR [--json]
//
// Identifies models of DATA by several methods and writes DIR/report.html (a
// self-contained page with inline SVG plots, parameter and metric tables and
// the commands that reproduce it) and DIR/models.json.
#include <iostream>
#include <sstream>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "data_options.hpp"
#include "identified_spec.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/strings.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/identify/identify.hpp"
#include "pneumid/report/identification_report.hpp"
#include "progress.hpp"
#include "validators.hpp"

namespace {

std::vector<std::string> SplitComma(const std::string& s) {
  std::vector<std::string> out = pneumid::Split(s, ',');
  std::erase(out, std::string());
  return out;
}

struct ReportArgs {
  pneumid::cli::DataOptions data;
  pneumid::cli::PreprocessArgs preprocess;
  std::string methods = "auto";
  std::string out_dir;
  std::string title;
  int order = 2, na = 3, nb = 3, nk = 1;
  int max_lag = 25;
  double confidence = 0.0;  ///< bands of +-K standard deviations; 0 = none
  bool json = false;
  bool progress = false;
  bool orders_given = false;  ///< --na, --nb or --nk on the command line
};

void Run(const ReportArgs& a) {
  using namespace pneumid;
  ReportOptions o;
  // "auto": the paper's three on a step test, else the methods for general
  // inputs (AutoMethods, once the data are read).
  const std::vector<std::string> for_a_step = {"reaction-curve", "ptn", "arx"};
  const bool automatic = a.methods == "auto";
  o.methods = automatic ? for_a_step : SplitComma(a.methods);
  o.request.order = a.order;
  o.request.na = a.na;
  o.request.nb = a.nb;
  o.request.nk = a.nk;
  // As `identify`: without --na, --nb, --nk the nonlinear structures are chosen.
  o.choose_structure = !a.orders_given;
  o.residual_max_lag = a.max_lag;
  o.confidence = a.confidence;
  o.title = a.title;
  std::string error;
  PNEUMID_CHECK(o.IsValid(&error), "{}", error);

  std::string cmd = "pneumid report " + ShellQuote(a.data.path);
  const cli::DataOptions defaults;
  if (a.data.time_col != defaults.time_col) cmd += " --time-col " + ShellQuote(a.data.time_col);
  if (a.data.input_col != defaults.input_col) cmd += " --input-col " + ShellQuote(a.data.input_col);
  if (a.data.output_col != defaults.output_col)
    cmd += " --output-col " + ShellQuote(a.data.output_col);
  if (a.data.sample_time > 0) cmd += fmt::format(" --Ts {}", a.data.sample_time);
  if (!a.data.delimiter.empty()) cmd += " --delimiter " + ShellQuote(a.data.delimiter);
  if (a.data.format != defaults.format) cmd += " --format " + a.data.format;
  const cli::PreprocessArgs& p = a.preprocess;
  if (!p.window.empty()) cmd += " --window " + ShellQuote(p.window);
  if (p.resample > 0) cmd += fmt::format(" --resample {}", p.resample);
  if (p.remove_initial) cmd += " --remove-initial";
  if (p.detrend != "none") cmd += " --detrend " + p.detrend;
  if (!p.filter.empty()) cmd += " --filter " + ShellQuote(p.filter);
  if (p.decimate != 1) cmd += fmt::format(" --decimate {}", p.decimate);
  cmd += " --method " + ShellQuote(a.methods);
  if (a.order != 2) cmd += fmt::format(" --order {}", a.order);
  if (a.na != 3 || a.nb != 3 || a.nk != 1)
    cmd += fmt::format(" --na {} --nb {} --nk {}", a.na, a.nb, a.nk);
  if (a.max_lag != 25) cmd += fmt::format(" --max-lag {}", a.max_lag);
  if (a.confidence > 0.0) cmd += fmt::format(" --confidence {:g}", a.confidence);
  if (!a.title.empty()) cmd += " --title " + ShellQuote(a.title);
  cmd += " --output-dir " + ShellQuote(a.out_dir);
  o.commands = {cmd};

  PreprocessRecord record;
  Dataset loaded = cli::LoadFromOptions(a.data);
  cli::RequireSingleInputOutput(loaded, a.data, "report");
  const Dataset data =
      Preprocess(std::move(loaded), cli::ToPreprocessOptions(a.preprocess), &record);
  if (!record.IsIdentity()) o.preprocessing = record;
  if (automatic) {
    std::string auto_warning;
    o.methods = AutoMethods(data, o.request, for_a_step, &auto_warning);
    if (!auto_warning.empty()) std::cerr << "pneumid report: warning: " << auto_warning << "\n";
  }
  ReportSummary s;
  {
    cli::ProgressBar bar("report", a.progress || cli::StderrIsTerminal());
    o.progress = [&bar](std::size_t done, std::size_t total, const std::string& method) {
      bar(static_cast<double>(done) / static_cast<double>(total), method);
    };
    s = WriteIdentificationReport(data, o, a.out_dir);
  }

  if (a.json) {
    nlohmann::json j;
    j["termination"] = ToString(s.termination);
    j["message"] = s.message;
    j["html"] = s.html_path;
    j["models_json"] = s.models_path;
    j["figures"] = s.num_figures;
    j["tables"] = s.num_tables;
    j["models"] = nlohmann::json::array();
    for (const auto& m : s.models) j["models"].push_back(ToJson(m));
    j["failures"] = nlohmann::json::array();
    for (const auto& [m, e] : s.failures) j["failures"].push_back({{"method", m}, {"error", e}});
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << fmt::format("{:<16} {:<10} {:>10}  {}\n", "method", "structure", "fit [%]",
                             "model");
    for (const auto& m : s.models)
      std::cout << fmt::format("{:<16} {:<10} {:>10.2f}  {}\n", m.method, m.structure,
                               m.fit_percent, m.tf.ToString(5));
    for (const auto& [m, e] : s.failures) std::cout << fmt::format("{:<16} failed: {}\n", m, e);
    std::cout << s.BriefReport() << "\n";
  }
  if (s.termination == Termination::kFailure) {
    std::cerr << "pneumid report: error: " << s.message << " (see " << s.html_path << ")\n";
    throw cli::ExitCode{1};
  }
}

const pneumid::cli::Registrar reg(
    "report", "Identify models of a data file and write a self-contained HTML report",
    [](CLI::App& app) {
      auto a = std::make_shared<ReportArgs>();
      pneumid::cli::AddDataOptions(app, a->data);
      pneumid::cli::AddPreprocessOptions(app, a->preprocess);
      app.add_option("-m,--method,--methods", a->methods,
                     "Comma-separated identification methods (names of `pneumid identify "
                     "--method`), or auto: reaction-curve, ptn and arx for a step test, else "
                     "fit-p1d, arx, oe, bj, iv4")
          ->capture_default_str();
      app.add_option("--output-dir,-o", a->out_dir,
                     "Directory for report.html and models.json (created when missing)")
          ->required();
      app.add_option("--order", a->order, "PTn order")->capture_default_str();
      CLI::Option* na = app.add_option("--na", a->na, "ARX order of A (and of the nonlinear "
                                       "models' linear part; without --na, --nb, --nk their "
                                       "structure is chosen on held-out data)")
                            ->capture_default_str();
      CLI::Option* nb = app.add_option("--nb", a->nb, "ARX order of B")->capture_default_str();
      CLI::Option* nk =
          app.add_option("--nk", a->nk, "ARX input delay in samples")->capture_default_str();
      app.add_option("--max-lag", a->max_lag, "Largest lag of the residual correlations")
          ->capture_default_str()
          ->check(pneumid::cli::AtLeast(1));
      app.add_option("--title", a->title, "Report title (default: from the data file)");
      pneumid::cli::AddConfidenceOption(app, a->confidence,
                                        "the step and Bode responses of the models");
      app.add_flag("--json", a->json, "Print the summary as JSON");
      app.add_flag("--progress", a->progress,
                   "Draw the progress bar even when stderr is not a terminal");
      app.callback([a, na, nb, nk]() {
        a->orders_given = na->count() + nb->count() + nk->count() > 0;
        Run(*a);
      });
    });

}  // namespace
