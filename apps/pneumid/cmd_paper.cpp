// pneumid paper [-o DIR] [--json]
//
// The paper's whole workflow on the built-in IPA simulator (report/paper.hpp):
// prints every number of the paper next to pneumid's value, and writes
// Figures 4-6 as PNG and SVG into DIR.
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/report/paper.hpp"

namespace {

struct PaperArgs {
  std::string out_dir = "paper-figures";
  bool json = false;
  bool no_figures = false;
  std::string ipa_config;
  unsigned long long seed = 1;
};

void Run(const PaperArgs& a) {
  using namespace pneumid;
  PaperOptions o;
  o.ipa_config = a.ipa_config;
  o.seed = a.seed;
  if (!a.json && cli::StderrIsTerminal()) std::cerr << "running the paper's workflow...\r";
  const PaperResult r = RunPaper(o);
  std::vector<std::string> files;
  if (!a.no_figures) files = WritePaperFigures(r, a.out_dir);
  if (a.json) {
    nlohmann::json j = r.ToJson();
    j["figures"] = files;
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "Emhemed, Mamat, Faudzi (2015), Jurnal Teknologi 77:20, reproduced on the IPA "
                 "simulator (Ts = 0.01 s)\n\n";
    std::cout << r.TableText() << "\n";
    for (const auto& p : r.problems) std::cout << "problem: " << p << "\n";
    for (const auto& f : files) std::cout << "wrote " << f << "\n";
    std::cout << r.BriefReport() << "\n";
  }
}

const pneumid::cli::Registrar reg(
    "paper",
    "Reproduce the paper end to end on the IPA simulator: table of every number and "
    "Figures 4-6",
    [](CLI::App& app) {
      auto a = std::make_shared<PaperArgs>();
      app.add_option("--output-dir,-o", a->out_dir,
                     "Directory for fig4/fig5/fig6 .png and .svg (created when missing)")
          ->capture_default_str();
      app.add_flag("--json", a->json,
                   "Print {\"rows\": [{\"quantity\", \"paper\", \"pneumid\", \"note\"}]}");
      app.add_flag("--no-figures", a->no_figures, "Do not write the figure files");
      app.add_option("--ipa-config", a->ipa_config,
                     "TOML file with IPA simulator parameters (default: built-in)")
          ->check(CLI::ExistingFile);
      app.add_option("--seed", a->seed, "Sensor-noise seed of the simulator")
          ->capture_default_str();
      app.callback([a]() { Run(*a); });
    });

}  // namespace
