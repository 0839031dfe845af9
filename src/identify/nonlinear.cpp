#include "pneumid/identify/nonlinear.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/model_evaluation.hpp"
#include "pneumid/lti/conversion.hpp"

namespace pneumid {

namespace {

std::string Values(const std::vector<double>& v) {
  std::vector<std::string> s;
  for (double x : v) s.push_back(fmt::format("{:.4g}", x));
  return fmt::format("[{}]", fmt::join(s, " "));
}

// "input map: monotone increasing, ...; u = [...]; y = [...]".
std::string MapNote(const char* which, const StaticMap& f) {
  const auto [lo, hi] = std::minmax_element(f.y().begin(), f.y().end());
  // Flat within 0.5 % of the output range counts as dead zone / saturation.
  return fmt::format("{}: {}; u = {}; y = {}", which, f.Describe(0.005 * (*hi - *lo)),
                     Values(f.u()), Values(f.y()));
}

void SetLinearPart(const PolynomialModel& g, IdentifiedModel* m) {
  m->discrete = g.ToTransferFunction(0);
  try {
    m->tf = D2C(*m->discrete, DiscretizationMethod::kZoh);
  } catch (const InvalidArgument& e) {
    m->tf = *m->discrete;
    m->notes.push_back(std::string("no continuous (zoh d2c) form of the linear part: ") + e.what());
  }
  const auto a = g.a, b = g.b[0];
  m->params = {{"A", std::vector<double>(a.data(), a.data() + a.size())},
               {"B", std::vector<double>(b.data(), b.data() + b.size())},
               {"nk", g.nk[0]},
               {"Ts", g.Ts}};
}

BlockModelOptions BlockOptions(const IdentifyRequest& request, const NonlinearOptions& options) {
  BlockModelOptions o = options.block;
  o.na = request.na;
  o.nb = std::max(1, request.nb);
  o.nk = request.nk;
  return o;
}

void AddSummary(const EstimationSummary& s, IdentifiedModel* m) {
  m->termination = s.termination;
  m->notes.push_back(
      fmt::format("{} ({} iterations, mean squared simulation error {:.4g}, "
                  "from {:.4g})",
                  s.message, s.iterations, s.loss, s.initial_loss));
  for (const std::string& w : s.warnings) m->notes.push_back(w);
}

}  // namespace

bool NonlinearOptions::IsValid(std::string* error) const {
  BlockModelOptions b = block;
  b.na = 0;  // orders come from the request
  b.nb = 1;
  b.nk = 0;
  NarxOptions n = narx;
  n.ny = 0;
  n.nu = 1;
  n.nk = 0;
  return static_map.IsValid(error) && b.IsValid(error) && n.IsValid(error);
}

const std::vector<std::string>& NonlinearMethodNames() {
  static const std::vector<std::string> names = {"static-map", "hammerstein", "wiener",
                                                 "hw",         "narx",        "affine-narx"};
  return names;
}

bool IsNonlinearMethod(const std::string& name) {
  const auto& n = NonlinearMethodNames();
  return std::find(n.begin(), n.end(), name) != n.end();
}

bool IsNonlinearModel(const IdentifiedModel& model) {
  return model.input_map.has_value() || model.output_map.has_value() || model.narx.has_value();
}

IdentifiedModel IdentifyNonlinear(const std::string& method, const Dataset& data,
                                  const IdentifyRequest& request, const NonlinearOptions& options) {
  std::string why;
  PNEUMID_CHECK(IsNonlinearMethod(method), "unknown nonlinear method '{}' (valid: {})", method,
                fmt::join(NonlinearMethodNames(), ", "));
  PNEUMID_CHECK(request.IsValid(&why), "invalid identify request: {}", why);
  PNEUMID_CHECK(options.IsValid(&why), "{}", why);
  PNEUMID_CHECK(request.input >= 0 && request.input < data.num_inputs() && request.output >= 0 &&
                    request.output < data.num_outputs(),
                "input column {} / output column {} do not exist (the data have {} input(s) and "
                "{} output(s))",
                request.input, request.output, data.num_inputs(), data.num_outputs());
  data.RequireUniform();
  const Eigen::VectorXd u = data.u(request.input), y = data.y(request.output);
  const double Ts = data.SampleTime();
  IdentifiedModel m;
  m.method = method;
  if (method == "static-map") {
    const StaticMapFitResult r = FitStaticMap(u, y, Ts, options.static_map);
    m.structure = "static map";
    m.input_map = r.map;
    m.discrete = TransferFunction::Discrete({1.0}, {1.0}, Ts);
    m.tf = TransferFunction();
    m.params = {{"knots", static_cast<int>(r.map.size())},
                {"segments", r.summary.segments_used},
                {"Ts", Ts}};
    m.termination = r.summary.termination;
    m.notes.push_back(MapNote("map", r.map));
    m.notes.push_back(r.summary.BriefReport());
  } else if (method == "hammerstein" || method == "wiener") {
    const BlockModelOptions o = BlockOptions(request, options);
    const bool hammerstein = method == "hammerstein";
    const BlockModelResult r =
        hammerstein ? EstimateHammerstein(u, y, Ts, o) : EstimateWiener(u, y, Ts, o);
    m.structure = hammerstein ? "Hammerstein" : "Wiener";
    (hammerstein ? m.input_map : m.output_map) = r.map;
    SetLinearPart(r.linear, &m);
    m.notes.push_back(MapNote(hammerstein ? "input map f(u)" : "output map f(x)", r.map));
    AddSummary(r.summary, &m);
  } else if (method == "hw") {
    const BlockModelResult r = EstimateHammersteinWiener(u, y, Ts, BlockOptions(request, options));
    m.structure = "Hammerstein-Wiener";
    m.input_map = r.map;
    m.output_map = r.output_map;
    SetLinearPart(r.linear, &m);
    m.notes.push_back(MapNote("input map f(u)", r.map));
    m.notes.push_back(MapNote("output map g(x)", *r.output_map));
    AddSummary(r.summary, &m);
  } else if (method == "affine-narx") {
    AffineNarxOptions o;
    o.degree = options.narx.degree;
    o.nk = std::max(1, request.nk);
    o.knots = options.block.knots;
    o.num_knots = options.block.num_knots;
    const AffineNarxResult r = EstimateAffineNarx(u, y, Ts, o);
    m.structure = "input-affine NARX";
    m.narx = r.narx;
    m.input_map = r.map;
    m.discrete = TransferFunction::Discrete({1.0}, {1.0}, Ts);
    m.tf = TransferFunction();
    m.params = {
        {"degree", o.degree}, {"nk", o.nk}, {"knots", static_cast<int>(r.map.size())}, {"Ts", Ts}};
    m.notes.push_back(MapNote("input map f(u)", r.map));
    m.notes.push_back(r.narx.Equation() + " (u: the mapped input f(u))");
    m.notes.push_back(fmt::format("{}; one-step fit {:.2f} %, simulation fit {:.2f} %",
                                  r.summary.message, r.one_step_fit_percent,
                                  r.simulation_fit_percent));
    for (const std::string& w : r.summary.warnings) m.notes.push_back(w);
    m.termination = r.summary.termination;
  } else {  // narx
    NarxOptions o = options.narx;
    o.ny = request.na;
    o.nu = std::max(1, request.nb);
    o.nk = request.nk;
    const NarxResult r = EstimateNarx(u, y, Ts, o);
    m.structure = "NARX";
    m.narx = r.model;
    m.discrete = TransferFunction::Discrete({1.0}, {1.0}, Ts);
    m.tf = TransferFunction();
    m.params = {{"ny", o.ny},
                {"nu", o.nu},
                {"nk", o.nk},
                {"degree", o.degree},
                {"terms", static_cast<int>(r.model.terms.size())},
                {"Ts", Ts}};
    std::vector<std::string> terms;
    for (std::size_t i = 0; i < r.model.terms.size(); ++i)
      terms.push_back(
          fmt::format("{} (ERR {:.4g})", r.model.TermName(r.model.terms[i]), r.model.err[i]));
    m.notes.push_back(fmt::format("selected terms: {}", fmt::join(terms, ", ")));
    m.notes.push_back(r.model.Equation());
    m.notes.push_back(fmt::format("{}; one-step fit {:.2f} %, simulation fit {:.2f} %",
                                  r.summary.message, r.one_step_fit_percent,
                                  r.simulation_fit_percent));
    for (const std::string& w : r.summary.warnings) m.notes.push_back(w);
    m.termination = r.summary.termination;
  }
  ScoreModel(data, request.input, request.output, &m);
  return m;
}

Eigen::VectorXd SimulateNonlinear(const IdentifiedModel& model, const Dataset& data, int input,
                                  int output) {
  PNEUMID_CHECK(IsNonlinearModel(model), "the model{} has no nonlinear part",
                model.method.empty() ? "" : " '" + model.method + "'");
  PNEUMID_CHECK(input >= 0 && input < data.num_inputs(),
                "input column {} does not exist (the data have {} input(s))", input,
                data.num_inputs());
  const double Ts = data.SampleTime();
  const double model_Ts = model.narx ? model.narx->Ts : model.discrete ? model.discrete->Ts() : Ts;
  PNEUMID_CHECK(std::abs(model_Ts - Ts) <= 1e-6 * Ts,
                "the model{} has sample time {} s, the data{} {} s",
                model.method.empty() ? "" : " '" + model.method + "'", model_Ts,
                data.source().empty() ? "" : " of " + data.source(), Ts);
  const Eigen::VectorXd u = data.u(input);
  if (model.narx) {
    PNEUMID_CHECK(output >= 0 && output < data.num_outputs(),
                  "a NARX simulation starts from the measured output: output column {} does "
                  "not exist (the data have {} output(s))",
                  output, data.num_outputs());
    // affine-narx: the NARX runs on the mapped input f(u).
    if (model.input_map) return model.narx->Simulate(model.input_map->Evaluate(u), data.y(output));
    return model.narx->Simulate(u, data.y(output));
  }
  PNEUMID_CHECK(model.discrete.has_value(),
                "the block-oriented model{} has no discrete linear part",
                model.method.empty() ? "" : " '" + model.method + "'");
  const TransferFunction g(model.discrete->num(), model.discrete->den(), Ts,
                           model.discrete->delay());
  if (model.output_map) {
    Eigen::VectorXd v = u;
    if (model.input_map) v = model.input_map->Evaluate(u);
    return SimulateWiener(g, *model.output_map, v);
  }
  return SimulateHammerstein(*model.input_map, g, u);
}

}  // namespace pneumid
