#include "pneumid/identify/parametric/parametric_model.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <variant>

#include "../parametric_filter.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/identify/identified_model.hpp"

namespace pneumid {

namespace {

std::vector<double> ToStd(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

Eigen::VectorXd FromJsonArray(const nlohmann::json& j, const char* key) {
  PNEUMID_CHECK(j.is_array() && !j.empty(), "params.{} must be a non-empty array of numbers", key);
  Eigen::VectorXd v(j.size());
  for (std::size_t i = 0; i < j.size(); ++i) {
    PNEUMID_CHECK(j[i].is_number(), "params.{}[{}] is not a number", key, i);
    v[static_cast<Eigen::Index>(i)] = j[i].get<double>();
  }
  return v;
}

void CheckMonic(const Eigen::VectorXd& p, const char* name) {
  PNEUMID_CHECK(p.size() >= 1 && p[0] == 1.0, "polynomial {} must be monic (first coefficient 1)",
                name);
}

}  // namespace

int PolynomialModel::nb(int input) const {
  PNEUMID_CHECK(input >= 0 && input < num_inputs(), "input {} out of range [0, {})", input,
                num_inputs());
  return static_cast<int>(b[input].size()) - nk[input];
}

int PolynomialModel::nf(int input) const {
  PNEUMID_CHECK(input >= 0 && input < num_inputs(), "input {} out of range [0, {})", input,
                num_inputs());
  if (f.empty()) return 0;
  return static_cast<int>(f[input].size()) - 1;
}

std::vector<std::string> PolynomialModel::ParameterNames() const {
  std::vector<std::string> names;
  for (int i = 1; i <= na(); ++i) names.push_back(fmt::format("a{}", i));
  for (int in = 0; in < num_inputs(); ++in)
    for (int i = 1; i <= nb(in); ++i)
      names.push_back(num_inputs() == 1 ? fmt::format("b{}", i) : fmt::format("b{}_{}", in + 1, i));
  for (int i = 1; i <= nc(); ++i) names.push_back(fmt::format("c{}", i));
  for (int i = 1; i <= nd(); ++i) names.push_back(fmt::format("d{}", i));
  for (int in = 0; in < num_inputs(); ++in)
    for (int i = 1; i <= nf(in); ++i)
      names.push_back(num_inputs() == 1 ? fmt::format("f{}", i) : fmt::format("f{}_{}", in + 1, i));
  return names;
}

Eigen::VectorXd PolynomialModel::Parameters() const {
  std::vector<double> p;
  for (int i = 1; i <= na(); ++i) p.push_back(a[i]);
  for (int in = 0; in < num_inputs(); ++in)
    for (int i = 0; i < nb(in); ++i) p.push_back(b[in][nk[in] + i]);
  for (int i = 1; i <= nc(); ++i) p.push_back(c[i]);
  for (int i = 1; i <= nd(); ++i) p.push_back(d[i]);
  for (int in = 0; in < num_inputs(); ++in)
    for (int i = 1; i <= nf(in); ++i) p.push_back(f[in][i]);
  return Eigen::Map<Eigen::VectorXd>(p.data(), static_cast<Eigen::Index>(p.size()));
}

Eigen::VectorXd PolynomialModel::ParameterStd() const {
  if (covariance.size() == 0) return {};
  return covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
}

void PolynomialModel::Validate() const {
  PNEUMID_CHECK(Ts > 0.0, "sample time must be positive, got Ts = {}", Ts);
  PNEUMID_CHECK(!b.empty(), "a polynomial model needs at least one input (B polynomial)");
  PNEUMID_CHECK(nk.size() == b.size(), "one delay per input expected: {} B polynomials, {} delays",
                b.size(), nk.size());
  CheckMonic(a, "A");
  CheckMonic(c, "C");
  CheckMonic(d, "D");
  PNEUMID_CHECK(f.empty() || f.size() == b.size(),
                "one F polynomial per input expected: {} B polynomials, {} F", b.size(), f.size());
  for (const auto& fi : f) CheckMonic(fi, "F");
  for (std::size_t i = 0; i < b.size(); ++i) {
    PNEUMID_CHECK(nk[i] >= 0, "input delay must be >= 0, got nk = {}", nk[i]);
    PNEUMID_CHECK(b[i].size() >= nk[i], "B polynomial of input {} shorter than its delay nk = {}",
                  i, nk[i]);
    for (int k = 0; k < nk[i]; ++k)
      PNEUMID_CHECK(b[i][k] == 0.0, "B polynomial of input {} must start with nk = {} zeros", i,
                    nk[i]);
  }
}

TransferFunction PolynomialModel::ToTransferFunction(int input) const {
  PNEUMID_CHECK(input >= 0 && input < num_inputs(), "input {} out of range [0, {})", input,
                num_inputs());
  Eigen::VectorXd den = a;
  if (!f.empty()) den = internal::Convolve(a, f[input]);
  // Move leading delays out of the numerator while it is longer than the
  // denominator, so that the model stays proper in z without poles at 0.
  int shift = 0;
  const Eigen::Index len = b[input].size();
  while (len - shift > den.size() && shift < nk[input]) ++shift;
  Eigen::VectorXd num = b[input].segment(shift, len - shift);
  return TransferFunction::Discrete(ToStd(num), ToStd(den), Ts, shift);
}

nlohmann::json PolynomialModel::ParamsJson() const {
  nlohmann::json j;
  j["a"] = ToStd(a);
  if (num_inputs() == 1) {
    j["b"] = ToStd(b[0]);
    j["nk"] = nk[0];
  } else {
    nlohmann::json bs = nlohmann::json::array();
    for (const auto& bi : b) bs.push_back(ToStd(bi));
    j["b"] = bs;
    j["nk"] = nk;
  }
  if (nc() > 0) j["c"] = ToStd(c);
  if (nd() > 0) j["d"] = ToStd(d);
  if (!f.empty()) {
    if (num_inputs() == 1) {
      j["f"] = ToStd(f[0]);
    } else {
      nlohmann::json fs = nlohmann::json::array();
      for (const auto& fi : f) fs.push_back(ToStd(fi));
      j["f"] = fs;
    }
  }
  j["Ts"] = Ts;
  return j;
}

PolynomialModel PolynomialModel::FromParamsJson(const nlohmann::json& params,
                                                const std::string& structure) {
  PNEUMID_CHECK(params.is_object(), "params must be a JSON object");
  for (const char* key : {"b", "nk", "Ts"})
    PNEUMID_CHECK(params.contains(key), "params lacks the key '{}'", key);
  PolynomialModel m;
  m.structure = structure;
  PNEUMID_CHECK(params["Ts"].is_number(), "params.Ts is not a number");
  m.Ts = params["Ts"].get<double>();
  m.a = params.contains("a") ? FromJsonArray(params["a"], "a") : Eigen::VectorXd::Ones(1);
  if (params.contains("c")) m.c = FromJsonArray(params["c"], "c");
  if (params.contains("d")) m.d = FromJsonArray(params["d"], "d");
  const auto& jb = params["b"];
  PNEUMID_CHECK(jb.is_array() && !jb.empty(), "params.b must be a non-empty array");
  if (jb[0].is_array()) {
    for (const auto& bi : jb) m.b.push_back(FromJsonArray(bi, "b"));
    PNEUMID_CHECK(params["nk"].is_array() && params["nk"].size() == m.b.size(),
                  "params.nk must be an array with one delay per input ({})", m.b.size());
    for (const auto& k : params["nk"]) m.nk.push_back(k.get<int>());
    if (params.contains("f"))
      for (const auto& fi : params["f"]) m.f.push_back(FromJsonArray(fi, "f"));
  } else {
    m.b.push_back(FromJsonArray(jb, "b"));
    PNEUMID_CHECK(params["nk"].is_number_integer(), "params.nk must be an integer");
    m.nk.push_back(params["nk"].get<int>());
    if (params.contains("f")) m.f.push_back(FromJsonArray(params["f"], "f"));
  }
  m.Validate();
  return m;
}

namespace {

// A coefficient vector of `params`: reals, or integers written without a point.
Eigen::VectorXd CoefficientsParam(const ParamValue& value, const std::string& key) {
  if (const auto* reals = std::get_if<std::vector<double>>(&value)) {
    PNEUMID_CHECK(!reals->empty(), "params.{} must be a non-empty array", key);
    return Eigen::Map<const Eigen::VectorXd>(reals->data(), static_cast<Eigen::Index>(reals->size()));
  }
  if (const auto* ints = std::get_if<std::vector<int>>(&value)) {
    PNEUMID_CHECK(!ints->empty(), "params.{} must be a non-empty array", key);
    Eigen::VectorXd v(static_cast<Eigen::Index>(ints->size()));
    for (std::size_t i = 0; i < ints->size(); ++i) v(static_cast<Eigen::Index>(i)) = (*ints)[i];
    return v;
  }
  throw InvalidArgument(fmt::format("params.{} must be an array of numbers", key));
}

// One coefficient vector per input (rows of `params`).
std::vector<Eigen::VectorXd> CoefficientRowsParam(const ParamValue& value,
                                                  const std::string& key) {
  const auto* rows = std::get_if<std::vector<std::vector<double>>>(&value);
  PNEUMID_CHECK(rows != nullptr && !rows->empty(), "params.{} must be a non-empty array of arrays",
                key);
  std::vector<Eigen::VectorXd> out;
  for (const std::vector<double>& row : *rows) out.push_back(CoefficientsParam(row, key));
  return out;
}

}  // namespace

ModelParams ToModelParams(const PolynomialModel& model) {
  ModelParams p;
  p["a"] = ToStd(model.a);
  if (model.num_inputs() == 1) {
    p["b"] = ToStd(model.b[0]);
    p["nk"] = model.nk[0];
  } else {
    std::vector<std::vector<double>> rows;
    for (const auto& bi : model.b) rows.push_back(ToStd(bi));
    p["b"] = rows;
    p["nk"] = model.nk;
  }
  if (model.nc() > 0) p["c"] = ToStd(model.c);
  if (model.nd() > 0) p["d"] = ToStd(model.d);
  if (!model.f.empty()) {
    if (model.num_inputs() == 1) {
      p["f"] = ToStd(model.f[0]);
    } else {
      std::vector<std::vector<double>> rows;
      for (const auto& fi : model.f) rows.push_back(ToStd(fi));
      p["f"] = rows;
    }
  }
  p["Ts"] = model.Ts;
  return p;
}

PolynomialModel PolynomialModelFromParams(const ModelParams& params, const std::string& structure) {
  for (const char* key : {"b", "nk", "Ts"})
    PNEUMID_CHECK(params.contains(key), "params lacks the key '{}'", key);
  PolynomialModel m;
  m.structure = structure;
  const std::optional<double> Ts = params.FindScalar("Ts");
  PNEUMID_CHECK(Ts.has_value(), "params.Ts is not a number");
  m.Ts = *Ts;
  m.a = params.contains("a") ? CoefficientsParam(params.at("a"), "a") : Eigen::VectorXd::Ones(1);
  if (params.contains("c")) m.c = CoefficientsParam(params.at("c"), "c");
  if (params.contains("d")) m.d = CoefficientsParam(params.at("d"), "d");
  const ParamValue& b = params.at("b");
  if (std::holds_alternative<std::vector<std::vector<double>>>(b)) {
    m.b = CoefficientRowsParam(b, "b");
    const auto* nks = std::get_if<std::vector<int>>(&params.at("nk"));
    PNEUMID_CHECK(nks != nullptr && nks->size() == m.b.size(),
                  "params.nk must be an array with one delay per input ({})", m.b.size());
    m.nk = *nks;
    if (params.contains("f")) m.f = CoefficientRowsParam(params.at("f"), "f");
  } else {
    m.b.push_back(CoefficientsParam(b, "b"));
    const auto* nk = std::get_if<int>(&params.at("nk"));
    PNEUMID_CHECK(nk != nullptr, "params.nk must be an integer");
    m.nk.push_back(*nk);
    if (params.contains("f")) m.f.push_back(CoefficientsParam(params.at("f"), "f"));
  }
  m.Validate();
  return m;
}

namespace {

void CheckData(const PolynomialModel& model, const Eigen::MatrixXd& u, const Eigen::VectorXd* y) {
  PNEUMID_CHECK(u.cols() == model.num_inputs(),
                "the model has {} input(s) but the data has {} input column(s)", model.num_inputs(),
                u.cols());
  if (y != nullptr)
    PNEUMID_CHECK(y->size() == u.rows(), "output and input lengths differ: {} vs {}", y->size(),
                  u.rows());
}

// sum_i B_i / F_i u_i
Eigen::VectorXd FilteredInputs(const PolynomialModel& model, const Eigen::MatrixXd& u) {
  Eigen::VectorXd w = Eigen::VectorXd::Zero(u.rows());
  for (int i = 0; i < model.num_inputs(); ++i) {
    const Eigen::VectorXd one = Eigen::VectorXd::Ones(1);
    w += internal::Filter(model.b[i], model.f.empty() ? one : model.f[i], u.col(i));
  }
  return w;
}

}  // namespace

Eigen::VectorXd Simulate(const PolynomialModel& model, const Eigen::MatrixXd& u) {
  CheckData(model, u, nullptr);
  const Eigen::VectorXd one = Eigen::VectorXd::Ones(1);
  return internal::Filter(one, model.a, FilteredInputs(model, u));
}

Eigen::VectorXd PredictionErrors(const PolynomialModel& model, const Eigen::VectorXd& y,
                                 const Eigen::MatrixXd& u) {
  CheckData(model, u, &y);
  const Eigen::VectorXd one = Eigen::VectorXd::Ones(1);
  const Eigen::VectorXd v = internal::Filter(model.a, one, y) - FilteredInputs(model, u);
  return internal::Filter(model.d, model.c, v);
}

Eigen::VectorXd Predict(const PolynomialModel& model, const Eigen::VectorXd& y,
                        const Eigen::MatrixXd& u, int horizon) {
  CheckData(model, u, &y);
  if (horizon <= 0) return Simulate(model, u);
  const Eigen::VectorXd eps = PredictionErrors(model, y, u);
  // First `horizon` impulse-response coefficients of H = C / (A D).
  Eigen::VectorXd impulse = Eigen::VectorXd::Zero(horizon);
  impulse[0] = 1.0;
  const Eigen::VectorXd h =
      internal::Filter(model.c, internal::Convolve(model.a, model.d), impulse);
  Eigen::VectorXd yhat = y;
  for (Eigen::Index t = 0; t < y.size(); ++t) {
    double s = 0.0;
    const Eigen::Index kmax = std::min<Eigen::Index>(horizon - 1, t);
    for (Eigen::Index k = 0; k <= kmax; ++k) s += h[k] * eps[t - k];
    yhat[t] -= s;
  }
  return yhat;
}

}  // namespace pneumid

namespace pneumid {

std::string EstimationSummary::BriefReport() const {
  std::string s = fmt::format("{}: N = {}, {} parameters, loss {:.6g}", ToString(termination),
                              num_rows, num_parameters, loss);
  if (iterations > 0)
    s += fmt::format(", {} iterations (initial loss {:.6g})", iterations, initial_loss);
  if (condition_number > 0)
    s += fmt::format(", cond {:.3g} (scaled {:.3g})", condition_number, scaled_condition_number);
  if (!message.empty()) s += ": " + message;
  return s;
}

}  // namespace pneumid
