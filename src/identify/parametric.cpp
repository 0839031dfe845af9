#include "pneumid/identify/parametric.hpp"

#include <algorithm>
#include <cmath>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/arx.hpp"
#include "pneumid/identify/fit_metrics.hpp"
#include "pneumid/identify/iv.hpp"
#include "pneumid/identify/pem.hpp"
#include "pneumid/lti/conversion.hpp"

namespace pneumid {

const std::vector<std::string>& ParametricMethodNames() {
  static const std::vector<std::string> names = {"arx", "iv4",   "armax", "oe",
                                                 "bj",  "n4sid", "cra",   "spa"};
  return names;
}

bool IsParametricMethod(const std::string& name) {
  const auto& n = ParametricMethodNames();
  return std::find(n.begin(), n.end(), name) != n.end();
}

IdentifiedModel ToIdentifiedModel(const std::string& method, const PolynomialModel& model,
                                  const EstimationSummary& summary, const Dataset& data, int input,
                                  int output) {
  IdentifiedModel r;
  r.method = method;
  r.structure = model.structure;
  r.params = model.ParamsJson();
  const Eigen::VectorXd sd = model.ParameterStd();
  if (sd.size() > 0) {
    const auto names = model.ParameterNames();
    for (std::size_t i = 0; i < names.size(); ++i)
      r.param_std[names[i]] = sd[static_cast<Eigen::Index>(i)];
  }
  r.discrete = model.ToTransferFunction(0);
  try {
    r.tf = D2C(*r.discrete, DiscretizationMethod::kZoh);
  } catch (const InvalidArgument& e) {
    r.tf = *r.discrete;
    r.notes.push_back(std::string("no continuous (zoh d2c) equivalent: ") + e.what());
  }
  Eigen::MatrixXd u(data.size(), model.num_inputs());
  if (model.num_inputs() == 1) {
    u.col(0) = data.u(input);
  } else {
    u = data.inputs();
  }
  const Eigen::VectorXd y = data.y(output);
  const Eigen::VectorXd yhat = Simulate(model, u);
  if (yhat.allFinite()) {
    r.fit_percent = NrmseFit(y, yhat);
    r.iae = Iae(data.time(), y, yhat);
  } else {
    r.fit_percent = -std::numeric_limits<double>::infinity();
    r.iae = std::numeric_limits<double>::infinity();
    r.notes.push_back("the simulated model output diverges (unstable model)");
  }
  r.notes.push_back(summary.BriefReport());
  for (const auto& w : summary.warnings) r.notes.push_back(w);
  return r;
}

namespace {

Dataset SisoData(const Dataset& data, const IdentifyRequest& request) {
  std::string error;
  PNEUMID_CHECK(request.IsValid(&error), "invalid identification request: {}", error);
  PNEUMID_CHECK(request.input >= 0 && request.input < data.num_inputs(),
                "input column {} out of range [0, {})", request.input, data.num_inputs());
  PNEUMID_CHECK(request.output >= 0 && request.output < data.num_outputs(),
                "output column {} out of range [0, {})", request.output, data.num_outputs());
  data.RequireUniform();
  Eigen::MatrixXd u = data.u(request.input);
  Eigen::MatrixXd y = data.y(request.output);
  std::vector<Channel> ic, oc;
  if (static_cast<int>(data.input_channels().size()) > request.input)
    ic.push_back(data.input_channels()[request.input]);
  if (static_cast<int>(data.output_channels().size()) > request.output)
    oc.push_back(data.output_channels()[request.output]);
  Dataset d(data.time(), u, y, ic, oc);
  d.set_source(data.source());
  return d;
}

}  // namespace

IdentifiedModel IdentifyParametric(const std::string& method, const Dataset& data,
                                   const IdentifyRequest& request) {
  PNEUMID_CHECK(IsParametricMethod(method), "unknown parametric method '{}'; valid: {}", method,
                fmt::format("{}", fmt::join(ParametricMethodNames(), ", ")));
  const Dataset d = SisoData(data, request);
  if (method == "arx") {
    ArxOptions o;
    o.na = request.na;
    o.nb = {request.nb};
    o.nk = {request.nk};
    const ArxResult r = EstimateArx(d, o);
    PNEUMID_CHECK(r.summary.IsSolutionUsable(), "ARX estimation failed: {}", r.summary.message);
    return ToIdentifiedModel(method, r.model, r.summary, d);
  }
  if (method == "iv4") {
    IvOptions o;
    o.na = request.na;
    o.nb = request.nb;
    o.nk = request.nk;
    const IvResult r = EstimateIv4(d, o);
    PNEUMID_CHECK(r.summary.IsSolutionUsable(), "IV4 estimation failed: {}", r.summary.message);
    return ToIdentifiedModel(method, r.model, r.summary, d);
  }
  if (method == "armax" || method == "oe" || method == "bj") {
    PemOrders o;
    o.na = request.na;
    o.nb = request.nb;
    o.nc = request.nc;
    o.nd = request.nd;
    o.nf = request.nf;
    o.nk = request.nk;
    const PemResult r = EstimatePolynomial(PolynomialStructureFromString(method), o, d);
    PNEUMID_CHECK(r.summary.IsSolutionUsable(), "{} estimation failed: {}", method,
                  r.summary.message);
    return ToIdentifiedModel(method, r.model, r.summary, d);
  }
  PNEUMID_CHECK(false, "method '{}' is not available yet", method);
  return {};
}

}  // namespace pneumid
