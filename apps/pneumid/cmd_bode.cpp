// pneumid bode: frequency response and stability margins of a model.
//
//   pneumid bode --model fopdt-paper [--w-min 0.1 --w-max 1000 --points 50] [--json]
//                [--plot bode.svg] [--confidence 3]
#include <cmath>
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "model_options.hpp"
#include "identified_spec.hpp"
#include "output_options.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/identify/evaluation/model_uncertainty.hpp"
#include "pneumid/lti/frequency.hpp"
#include "pneumid/report/figures.hpp"
#include "validators.hpp"

namespace pneumid::cli {
namespace {

struct BodeArgs {
  ModelOptions model;
  double w_min = 0.0;
  double w_max = 0.0;
  int points = 0;  ///< 0: 50 over --w-min..--w-max, else the automatic grid
  double confidence = 0.0;  ///< band of +-K standard deviations; 0 = none
  bool json = false;
  std::string plot;
};

void Run(const BodeArgs& o) {
  const TransferFunction g = ResolveModel(o.model);
  Eigen::VectorXd omega;
  const bool has_range = o.w_min > 0.0 || o.w_max > 0.0;
  if (has_range) {
    // A bound not given comes from the automatic grid (the poles and zeros).
    const Eigen::VectorXd automatic = Bode(g).omega;
    const double lo = o.w_min > 0.0 ? o.w_min : std::min(automatic[0], 0.01 * o.w_max);
    double hi = o.w_max > 0.0 ? o.w_max
                              : std::max(automatic[automatic.size() - 1], 100.0 * o.w_min);
    if (o.w_max <= 0.0 && g.IsDiscrete()) hi = std::min(hi, M_PI / g.Ts());  // Nyquist
    PNEUMID_CHECK(hi > lo, "--w-min and --w-max must satisfy 0 < w-min < w-max (rad/s), got {} and {}",
                  lo, hi);
    omega = LogSpace(std::log10(lo), std::log10(hi), o.points > 0 ? o.points : 50);
  } else if (o.points > 0) {
    // --points alone: that many frequencies over the automatic range.
    const Eigen::VectorXd automatic = Bode(g).omega;
    omega =
        LogSpace(std::log10(automatic[0]), std::log10(automatic[automatic.size() - 1]), o.points);
  }
  const BodeData b = Bode(g, omega);
  const Margins m = ComputeMargins(g);
  const std::optional<IdentifiedModel> identified = ModelForConfidence(o.model.model, o.confidence);
  UncertaintyOptions uo;
  uo.discrete = g.IsDiscrete();  // the form drawn: "tf" of the file, discrete when it is
  const BodeStd sd = identified ? BodeResponseStd(*identified, b.omega, uo) : BodeStd{};
  if (!o.plot.empty()) {
    // The figure over the range of the table, on a grid of at least 400 frequencies.
    const Eigen::VectorXd w =
        LogSpace(std::log10(b.omega[0]), std::log10(b.omega[b.omega.size() - 1]),
                 std::max<int>(400, static_cast<int>(b.omega.size())));
    const std::string label = ModelLabel(o.model, g);
    NamedModel nm{label, g};
    if (identified) nm.identified = std::make_shared<const IdentifiedModel>(*identified);
    BodeFigure({nm}, w, "Bode diagram of " + label, o.confidence).Save(o.plot);
  }
  if (o.json) {
    nlohmann::ordered_json j;
    j["omega"] = std::vector<double>(b.omega.data(), b.omega.data() + b.omega.size());
    j["magnitude_db"] =
        std::vector<double>(b.magnitude_db.data(), b.magnitude_db.data() + b.magnitude_db.size());
    j["phase_deg"] =
        std::vector<double>(b.phase_deg.data(), b.phase_deg.data() + b.phase_deg.size());
    if (identified) {
      j["confidence"] = o.confidence;
      j["magnitude_db_std"] = JsonNumbers(sd.magnitude_db);
      j["phase_deg_std"] = JsonNumbers(sd.phase_deg);
    }
    nlohmann::ordered_json mj;
    mj["gain_margin"] = JsonNumber(m.gain_margin);
    mj["gain_margin_db"] = JsonNumber(m.gain_margin_db);
    mj["phase_crossover"] = JsonNumber(m.phase_crossover);
    mj["phase_margin"] = JsonNumber(m.phase_margin);
    mj["gain_crossover"] = JsonNumber(m.gain_crossover);
    j["margins"] = mj;
    if (!o.plot.empty()) j["plot"] = o.plot;
    std::cout << j.dump() << "\n";
    return;
  }
  std::cout << "model:\n" << DescribeModel(g.Normalized(), "  ");
  std::cout << fmt::format("  {:>14} {:>14} {:>14}", "omega [rad/s]", "|G| [dB]", "phase [deg]");
  const std::string band = fmt::format("+-{:g} sd", o.confidence);
  if (identified) std::cout << fmt::format(" {:>14} {:>14}", band + " [dB]", band + " [deg]");
  std::cout << "\n";
  for (Eigen::Index i = 0; i < b.omega.size(); ++i) {
    std::cout << fmt::format("  {:>14.6g} {:>14.6g} {:>14.6g}", b.omega[i], b.magnitude_db[i],
                             b.phase_deg[i]);
    if (identified)
      std::cout << fmt::format(" {:>14.6g} {:>14.6g}", o.confidence * sd.magnitude_db[i],
                               o.confidence * sd.phase_deg[i]);
    std::cout << "\n";
  }
  std::cout << fmt::format("gain margin:  {:.6g} ({:.4g} dB) at {:.6g} rad/s\n", m.gain_margin,
                           m.gain_margin_db, m.phase_crossover);
  std::cout << fmt::format("phase margin: {:.6g} deg at {:.6g} rad/s\n", m.phase_margin,
                           m.gain_crossover);
  if (!o.plot.empty()) std::cout << "plot written to " << o.plot << "\n";
}

const Registrar reg("bode",
                    "Frequency response (magnitude, unwrapped phase) and margins of a model",
                    [](CLI::App& app) {
                      auto o = std::make_shared<BodeArgs>();
                      AddModelOptions(app, o->model);
                      app.add_option("--w-min", o->w_min,
                                     "Lowest frequency in rad/s (default: from the poles/zeros, "
                                     "at most --w-max / 100)")
                          ->check(Positive());
                      app.add_option("--w-max", o->w_max,
                                     "Highest frequency in rad/s (discrete: at most pi/Ts; "
                                     "default: from the poles/zeros, at least --w-min x 100)")
                          ->check(Positive());
                      app.add_option("--points", o->points,
                                     "Number of log-spaced frequencies (default: 50 from --w-min "
                                     "to --w-max, else the automatic grid)")
                          ->check(AtLeast(2));
                      AddConfidenceOption(app, o->confidence, "magnitude and phase");
                      app.add_flag("--json", o->json,
                                   "Print {\"omega\", \"magnitude_db\", \"phase_deg\", "
                                   "\"margins\"} instead (with --confidence also "
                                   "\"confidence\", \"magnitude_db_std\", \"phase_deg_std\")");
                      AddPlotOption(app, o->plot, "magnitude and phase");
                      app.callback([o] { Run(*o); });
                    });

}  // namespace
}  // namespace pneumid::cli
