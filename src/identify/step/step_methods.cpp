#include "pneumid/identify/step/step_methods.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/evaluation/model_evaluation.hpp"
#include "pneumid/identify/evaluation/model_uncertainty.hpp"
#include "pneumid/identify/step/areas.hpp"
#include "pneumid/identify/step/ptn.hpp"
#include "pneumid/identify/step/reaction_curve.hpp"
#include "pneumid/identify/step/sopdt.hpp"
#include "pneumid/identify/step/strejc.hpp"
#include "pneumid/identify/step/two_point.hpp"
#include "pneumid/lti/response.hpp"

namespace pneumid {
namespace {

IdentifiedModel FromFopdt(const std::string& method, const FopdtParams& p) {
  IdentifiedModel m;
  m.method = method;
  m.structure = "FOPDT";
  m.params = {{"K", p.K}, {"tau", p.tau}, {"theta", p.theta}};
  m.tf = p.ToTransferFunction();
  return m;
}

std::pair<double, Eigen::Index> InitialInput(const Eigen::VectorXd& u) {
  const double tol = 1e-12 * std::max(1.0, u.cwiseAbs().maxCoeff());
  Eigen::Index k = 0;
  while (k < u.size() && std::abs(u[k] - u[0]) <= tol) ++k;
  return {u[0], k};
}

}  // namespace

bool StepMethodOptions::IsValid(std::string* error) const {
  return step.IsValid(error) && tangent.IsValid(error) && fit.IsValid(error);
}

const std::vector<std::string>& StepMethodNames() {
  static const std::vector<std::string> names{
      "reaction-curve", "tangent", "smith",   "sundaresan", "broida",   "sopdt",   "ptn",
      "strejc",         "areas",   "fit-p1d", "fit-p2d",    "fit-p2du", "fit-p3d", "fit-p1di"};
  return names;
}

bool IsStepMethod(const std::string& name) {
  const auto& n = StepMethodNames();
  return std::find(n.begin(), n.end(), name) != n.end();
}

Eigen::VectorXd SimulateOnData(const TransferFunction& g, const Dataset& data, int input,
                               int output, double y0) {
  // The levels before the first input change as the operating point.
  IdentifiedModel m;
  m.tf = g;
  const Eigen::VectorXd y = data.y(output);
  const auto [u0, k0] = InitialInput(data.u(input));
  m.u0 = u0;
  m.y0 = std::isnan(y0) ? (k0 > 0 ? y.head(k0).mean() : y[0]) : y0;
  return SimulateModel(m, data, input);
}

namespace {

// The operating point of a step-response model: the input before its first
// change and the output's mean there (or the offset a process fit estimated).
void SetOperatingPoint(const Dataset& data, int input, int output, IdentifiedModel* m) {
  const Eigen::VectorXd u = data.u(input), y = data.y(output);
  const auto [u0, k0] = InitialInput(u);
  m->u0 = u0;
  m->y0 = m->params.FindScalar("y0").value_or(k0 > 0 ? y.head(k0).mean() : y[0]);
}

}  // namespace

IdentifiedModel IdentifyStepMethod(const std::string& method, const Dataset& data,
                                   const IdentifyRequest& request,
                                   const StepMethodOptions& options) {
  std::string why;
  PNEUMID_CHECK(request.IsValid(&why), "invalid identify request: {}", why);
  PNEUMID_CHECK(options.IsValid(&why), "invalid step-method options: {}", why);
  PNEUMID_CHECK(IsStepMethod(method), "unknown step-response method '{}' (valid: {})", method,
                fmt::join(StepMethodNames(), ", "));
  const int in = request.input, out = request.output;
  IdentifiedModel m;
  if (method.rfind("fit-", 0) == 0) {
    ProcessFitOptions fo = options.fit;
    fo.structure = ProcessStructureFromString(method.substr(4), nullptr);
    const ProcessFitResult r = FitProcessModel(data, in, out, fo);
    m.method = method;
    m.structure = ToString(r.structure) + (r.zero ? "Z" : "");
    std::vector<std::string> names;
    for (const auto& [name, value] : NamedParams(r.structure, r.zero, r.params)) {
      m.params[name] = value;
      names.push_back(name);
    }
    for (const auto& [name, value] : NamedParams(r.structure, r.zero, r.param_std)) {
      if (std::isfinite(value)) m.param_std[name] = value;
    }
    if (r.covariance.size() > 0 && r.covariance.allFinite()) {
      m.covariance = ParameterCovariance{r.covariance_names, r.covariance};
    } else {
      SetDiagonalCovariance(&m, names);
    }
    m.tf = r.tf;
    // Every fit says how it ended and where it started from (the brief
    // report: termination, iterations, cost, the initial guess's source).
    m.notes.push_back(r.summary.BriefReport());
    if (!r.summary.covariance_ok) {
      m.notes.push_back("parameter standard deviations unavailable (singular Jacobian)");
    }
    m.termination = r.summary.termination;
    SetOperatingPoint(data, in, out, &m);
    m.u0 = r.params.u0;  // the input rest the fit used (it may not be u(0))
    ScoreModel(data, in, out, &m);
    return m;
  }

  const StepAnalysis step = AnalyzeStep(data, in, out, options.step);
  if (method == "reaction-curve") {
    m = FromFopdt(method, ReactionCurve(step));
    m.params["t63"] = step.CrossingTime(1.0 - std::exp(-1.0));
  } else if (method == "tangent") {
    const TangentResult t = InflectionTangent(step, options.tangent);
    m = FromFopdt(method, TangentFopdt(step, t));
    m.params["L"] = t.L;
    m.params["T"] = t.T;
    m.params["t_inflection"] = t.inflection_time;
    if (t.L < 0.0) m.notes.push_back(fmt::format("tangent delay L = {:.4g} s < 0 set to 0", t.L));
  } else if (method == "smith" || method == "sundaresan" || method == "broida") {
    const TwoPointMethod tp = TwoPointMethodFromString(method);
    m = FromFopdt(method, TwoPoint(step, tp));
    const auto [p1, p2] = TwoPointLevels(tp);
    m.params["t1"] = step.CrossingTime(p1);
    m.params["t2"] = step.CrossingTime(p2);
  } else if (method == "sopdt") {
    const ThreePointSopdtResult r = ThreePointSopdt(step);
    m.method = method;
    m.structure = "SOPDT";
    m.params = {{"K", r.params.K},
                {"tau1", r.params.tau1},
                {"tau2", r.params.tau2},
                {"theta", r.params.theta},
                {"R", r.ratio}};
    m.tf = r.params.tau2 > 0.0
               ? TransferFunction::Sopdt(r.params.K, r.params.tau1, r.params.tau2, r.params.theta)
               : TransferFunction::Fopdt(r.params.K, r.params.tau1, r.params.theta);
    if (r.clamped) {
      m.notes.push_back(
          fmt::format("20/50/80 % time ratio {:.4g} outside [1.541, 1.949]: lag "
                      "ratio clamped",
                      r.ratio));
    }
  } else if (method == "ptn") {
    const TangentResult t = InflectionTangent(step, options.tangent);
    const double td = std::max(t.L, 0.0);
    const std::vector<double> a = PtnCoefficients(td, t.T, request.order);
    m.method = method;
    m.structure = fmt::format("PT{}", request.order);
    m.params = {{"K", step.gain}, {"td", td}, {"tTL", t.T}, {"n", request.order}, {"a", a}};
    m.tf = PtnModel(step.gain, td, t.T, request.order);
    if (!m.tf.IsStable()) {
      m.notes.push_back(fmt::format("the truncated series of order {} is unstable", request.order));
    }
  } else if (method == "strejc") {
    const TangentResult t = InflectionTangent(step, options.tangent);
    const StrejcResult s = Strejc(t, step.gain);
    m.method = method;
    m.structure = "Strejc";
    m.params = {{"K", s.K}, {"T", s.T}, {"n", s.n}, {"theta", s.Td}, {"Tu", std::max(t.L, 0.0)},
                {"Tn", t.T}};
    Eigen::VectorXd den(1), lag(2);
    den << 1.0;
    lag << s.T, 1.0;
    for (int i = 0; i < s.n; ++i) den = poly::Multiply(den, lag);
    Eigen::VectorXd num(1);
    num << s.K;
    m.tf = TransferFunction(num, den, 0.0, s.Td);
  } else if (method == "areas") {
    const AreaResult a = CharacteristicAreas(step);
    m = FromFopdt(method, a.fopdt);
    m.params["T_ar"] = a.T_ar;
    m.params["A0"] = a.A0;
    m.params["A1"] = a.A1;
    m.params["A2"] = a.A2;
    m.params["A3"] = a.A3;
  }
  SetOperatingPoint(data, in, out, &m);
  ScoreModel(data, in, out, &m);
  return m;
}

}  // namespace pneumid
