#include "model_options.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <complex>
#include <vector>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/spec.hpp"
#include "pneumid/models/model_file.hpp"
#include "validators.hpp"

namespace pneumid::cli {

void AddModelOptions(CLI::App& app, ModelOptions& options, bool with_ts) {
  app.add_option("--model", options.model,
                 "Model spec: arx-paper, arx-paper-ct, fopdt-paper, fopdt:K=..,tau=..,theta=.., "
                 "sopdt:K=..,tau1=..,tau2=..,theta=.., tf:num=..,den=..[,Ts=..][,delay=..], or a "
                 "model JSON file [FILE.json#method]");
  app.add_option("--num", options.num,
                 "Numerator, comma-separated: descending powers of s, or ascending powers of "
                 "z^-1 with --Ts (write --num=-1,2 when it starts with a minus sign)");
  app.add_option("--den", options.den, "Denominator, same convention as --num");
  if (with_ts) {
    app.add_option("--Ts", options.Ts,
                   "Sample time in s of the model given by --num/--den (default 0: continuous)");
  }
  app.add_option("--delay", options.delay,
                 "Input delay in s (overrides the model's; a multiple of Ts if discrete)");
}

void AddTimeGridOptions(CLI::App& app, double& t_final, double& dt) {
  app.add_option("--t-final", t_final,
                 "Simulated horizon in s (default 0: about 7 slowest time constants)")
      ->capture_default_str()
      ->check(NonNegative());
  app.add_option("--dt", dt,
                 "Time step in s (default 0: Ts, or 1/200 of the slowest time constant)")
      ->capture_default_str()
      ->check(NonNegative());
}

std::vector<double> ParseCoefficientList(const std::string& option, const std::string& text) {
  return ParseNumberList(option, text);
}

TransferFunction ResolveModel(const ModelOptions& o) {
  const bool has_spec = !o.model.empty();
  const bool has_poly = !o.num.empty() || !o.den.empty();
  PNEUMID_CHECK(has_spec || has_poly, "give a model: --model SPEC, or --num and --den");
  PNEUMID_CHECK(!(has_spec && has_poly),
                "give either --model or --num/--den, not both (--model '{}')", o.model);
  PNEUMID_CHECK(std::isnan(o.delay) || (std::isfinite(o.delay) && o.delay >= 0.0),
                "--delay must be >= 0 s, got {}", o.delay);
  TransferFunction g;
  if (has_spec) {
    g = ParseModelSpec(o.model);
  } else {
    PNEUMID_CHECK(!o.num.empty(), "--num is missing (--den was given)");
    PNEUMID_CHECK(!o.den.empty(), "--den is missing (--num was given)");
    PNEUMID_CHECK(std::isfinite(o.Ts) && o.Ts >= 0.0,
                  "--Ts must be >= 0 s (0 = continuous), got {}", o.Ts);
    const std::vector<double> num = ParseCoefficientList("--num", o.num);
    const std::vector<double> den = ParseCoefficientList("--den", o.den);
    g = TransferFunction(Eigen::Map<const Eigen::VectorXd>(num.data(), num.size()),
                         Eigen::Map<const Eigen::VectorXd>(den.data(), den.size()), o.Ts, 0.0);
  }
  if (!std::isnan(o.delay)) g = g.WithDelay(o.delay);
  return g;
}

std::string ModelLabel(const ModelOptions& options, const TransferFunction& g) {
  if (!options.model.empty()) return options.model;
  return fmt::format("G({}) = {}", g.IsDiscrete() ? "z" : "s", g.Normalized().ToString(4));
}

std::string DescribeModel(const TransferFunction& g, const std::string& indent) {
  const Eigen::VectorXcd p = g.Poles();
  std::vector<std::complex<double>> poles(p.data(), p.data() + p.size());
  std::sort(poles.begin(), poles.end(), [](auto a, auto b) {
    return a.real() != b.real() ? a.real() > b.real() : a.imag() > b.imag();
  });
  std::vector<std::string> items;
  for (const auto& z : poles) {
    const double scale = std::max(1.0, std::abs(z));
    if (std::abs(z.imag()) <= 1e-12 * scale) {
      items.push_back(fmt::format("{:.6g}", z.real()));
    } else if (z.imag() > 0) {
      items.push_back(fmt::format("{:.6g} +/- {:.6g}j", z.real(), z.imag()));
    }
  }
  std::string out;
  out += fmt::format("{}G({}) = {}\n", indent, g.IsDiscrete() ? "z" : "s", g.ToString(7));
  out += fmt::format("{}poles: {}\n", indent,
                     items.empty() ? "none" : fmt::format("{}", fmt::join(items, ", ")));
  out += fmt::format("{}DC gain: {:.6g}\n", indent, g.DcGain());
  out += fmt::format("{}stable: {}\n", indent, g.IsStable() ? "yes" : "no");
  return out;
}

}  // namespace pneumid::cli
