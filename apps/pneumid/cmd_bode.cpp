// pneumid bode: frequency response and stability margins of a model.
//
//   pneumid bode --model fopdt-paper [--w-min 0.1 --w-max 1000 --points 50] [--json]
#include <cmath>
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "model_options.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/lti/frequency.hpp"

namespace pneumid::cli {
namespace {

struct BodeOptions {
  ModelOptions model;
  double w_min = 0.0;
  double w_max = 0.0;
  int points = 50;
  bool json = false;
};

nlohmann::json Number(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

void Run(const BodeOptions& o) {
  const TransferFunction g = ResolveModel(o.model);
  Eigen::VectorXd omega;
  const bool has_range = o.w_min > 0.0 || o.w_max > 0.0;
  if (has_range) {
    PNEUMID_CHECK(o.w_min > 0.0 && o.w_max > o.w_min,
                  "--w-min and --w-max must satisfy 0 < w-min < w-max (rad/s), got {} and {}",
                  o.w_min, o.w_max);
    PNEUMID_CHECK(o.points >= 2, "--points must be >= 2, got {}", o.points);
    omega = LogSpace(std::log10(o.w_min), std::log10(o.w_max), o.points);
  }
  const BodeData b = Bode(g, omega);
  const Margins m = ComputeMargins(g);
  if (o.json) {
    nlohmann::ordered_json j;
    j["omega"] = std::vector<double>(b.omega.data(), b.omega.data() + b.omega.size());
    j["magnitude_db"] =
        std::vector<double>(b.magnitude_db.data(), b.magnitude_db.data() + b.magnitude_db.size());
    j["phase_deg"] =
        std::vector<double>(b.phase_deg.data(), b.phase_deg.data() + b.phase_deg.size());
    nlohmann::ordered_json mj;
    mj["gain_margin"] = Number(m.gain_margin);
    mj["gain_margin_db"] = Number(m.gain_margin_db);
    mj["phase_crossover"] = Number(m.phase_crossover);
    mj["phase_margin"] = Number(m.phase_margin);
    mj["gain_crossover"] = Number(m.gain_crossover);
    j["margins"] = mj;
    std::cout << j.dump() << "\n";
    return;
  }
  std::cout << "model:\n" << DescribeModel(g.Normalized(), "  ");
  std::cout << fmt::format("  {:>14} {:>14} {:>14}\n", "omega [rad/s]", "|G| [dB]", "phase [deg]");
  for (Eigen::Index i = 0; i < b.omega.size(); ++i) {
    std::cout << fmt::format("  {:>14.6g} {:>14.6g} {:>14.6g}\n", b.omega[i], b.magnitude_db[i],
                             b.phase_deg[i]);
  }
  std::cout << fmt::format("gain margin:  {:.6g} ({:.4g} dB) at {:.6g} rad/s\n", m.gain_margin,
                           m.gain_margin_db, m.phase_crossover);
  std::cout << fmt::format("phase margin: {:.6g} deg at {:.6g} rad/s\n", m.phase_margin,
                           m.gain_crossover);
}

const Registrar reg("bode",
                    "Frequency response (magnitude, unwrapped phase) and margins of a model",
                    [](CLI::App& app) {
                      auto o = std::make_shared<BodeOptions>();
                      AddModelOptions(app, o->model);
                      app.add_option("--w-min", o->w_min,
                                     "Lowest frequency in rad/s (default: from the poles/zeros)");
                      app.add_option("--w-max", o->w_max,
                                     "Highest frequency in rad/s (discrete: at most pi/Ts)");
                      app.add_option("--points", o->points, "Number of log-spaced frequencies")
                          ->capture_default_str();
                      app.add_flag("--json", o->json,
                                   "Print {\"omega\", \"magnitude_db\", \"phase_deg\", "
                                   "\"margins\"} instead");
                      app.callback([o] { Run(*o); });
                    });

}  // namespace
}  // namespace pneumid::cli
