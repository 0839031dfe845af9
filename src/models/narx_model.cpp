#include "pneumid/models/narx_model.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/strings.hpp"

namespace pneumid {

namespace {

// Parses "y(t-2)" -> regressor index.
int ParseFactor(const std::string& f, int ny, int nu, int nk, const std::string& term) {
  const bool is_y = f.rfind("y(t-", 0) == 0, is_u = f.rfind("u(t", 0) == 0;
  PNEUMID_CHECK((is_y || is_u) && f.back() == ')',
                "NARX term '{}': factor '{}' is not y(t-K) or u(t-K)", Excerpt(term), Excerpt(f));
  const std::string num = f.substr(3, f.size() - 4);  // "-2" or "" (u(t))
  int lag = 0;
  if (!num.empty()) {
    PNEUMID_CHECK(
        num[0] == '-' && num.size() > 1 &&
            std::all_of(num.begin() + 1, num.end(), [](char c) { return c >= '0' && c <= '9'; }),
        "NARX term '{}': factor '{}' is not y(t-K) or u(t-K)", Excerpt(term), Excerpt(f));
    lag = std::stoi(num.substr(1));
  }
  if (is_y) {
    PNEUMID_CHECK(lag >= 1 && lag <= ny, "NARX term '{}': y lag {} outside 1..ny = {}",
                  Excerpt(term), lag, ny);
    return lag - 1;
  }
  PNEUMID_CHECK(lag >= nk && lag <= nk + nu - 1, "NARX term '{}': u lag {} outside {}..{}",
                Excerpt(term), lag, nk, nk + nu - 1);
  return ny + lag - nk;
}

NarxTerm ParseTerm(const std::string& s, int ny, int nu, int nk) {
  NarxTerm term;
  if (s == "1") return term;
  for (const std::string& part : Split(s, '*')) {
    std::string f(Trim(part));
    int power = 1;
    if (const auto caret = f.find('^'); caret != std::string::npos) {
      const std::string p = f.substr(caret + 1);
      PNEUMID_CHECK(p.size() == 1 && p[0] >= '1' && p[0] <= '9', "NARX term '{}': bad power '{}'",
                    Excerpt(s), Excerpt(p));
      power = p[0] - '0';
      f = f.substr(0, caret);
    }
    const int r = ParseFactor(f, ny, nu, nk, s);
    for (int k = 0; k < power; ++k) term.push_back(r);
  }
  std::sort(term.begin(), term.end());
  return term;
}

}  // namespace

// Value of regressor r at time t from the output history `y` and input `u`.
double NarxModel::Regressor(int r, Eigen::Index t, const Eigen::VectorXd& y,
                            const Eigen::VectorXd& u) const {
  return r < ny ? y[t - 1 - r] / y_scale : (u[t - nk - (r - ny)] - u_offset) / u_scale;
}

double NarxModel::TermValue(const NarxTerm& term, Eigen::Index t, const Eigen::VectorXd& y,
                            const Eigen::VectorXd& u) const {
  double v = 1.0;
  for (int r : term) v *= Regressor(r, t, y, u);
  return v;
}

int NarxModel::FirstSample() const { return std::max(ny, nk + nu - 1); }

std::string NarxModel::TermName(const NarxTerm& term) const {
  if (term.empty()) return "1";
  std::string s;
  for (std::size_t i = 0; i < term.size();) {
    std::size_t j = i;
    while (j < term.size() && term[j] == term[i]) ++j;
    if (!s.empty()) s += '*';
    const int r = term[i];
    s += r < ny ? fmt::format("y(t-{})", r + 1)
                : (nk + r - ny == 0 ? std::string("u(t)") : fmt::format("u(t-{})", nk + r - ny));
    if (j - i > 1) s += fmt::format("^{}", j - i);
    i = j;
  }
  return s;
}

std::string NarxModel::Equation() const {
  std::string s = "y(t) =";
  const bool scaled = u_offset != 0.0 || u_scale != 1.0 || y_scale != 1.0;
  for (std::size_t i = 0; i < terms.size(); ++i) {
    const double c = theta[i];
    s += fmt::format(" {} {:.4g}", c < 0 ? '-' : (i == 0 ? ' ' : '+'), std::abs(c));
    if (!terms[i].empty()) s += " " + TermName(terms[i]);
  }
  if (scaled)
    s += fmt::format(" (normalised: y := y / {:.6g}, u := (u - {:.6g}) / {:.6g})", y_scale,
                     u_offset, u_scale);
  return s;
}

Eigen::VectorXd NarxModel::Predict(const Eigen::VectorXd& y, const Eigen::VectorXd& u) const {
  PNEUMID_CHECK(y.size() == u.size(), "NARX: the output has {} samples, the input {}", y.size(),
                u.size());
  Eigen::VectorXd p = y;
  for (Eigen::Index t = FirstSample(); t < y.size(); ++t) {
    double v = 0.0;
    for (std::size_t i = 0; i < terms.size(); ++i) v += theta[i] * TermValue(terms[i], t, y, u);
    p[t] = y_scale * v;
  }
  return p;
}

Eigen::VectorXd NarxModel::Simulate(const Eigen::VectorXd& u, const Eigen::VectorXd& y) const {
  PNEUMID_CHECK(y.size() == u.size(), "NARX: the output has {} samples, the input {}", y.size(),
                u.size());
  PNEUMID_CHECK(y.size() >= FirstSample(),
                "NARX: the simulation needs the first {} measured outputs, got {} samples",
                FirstSample(), y.size());
  Eigen::VectorXd s = y;
  for (Eigen::Index t = FirstSample(); t < y.size(); ++t) {
    double v = 0.0;
    for (std::size_t i = 0; i < terms.size(); ++i) v += theta[i] * TermValue(terms[i], t, s, u);
    s[t] = std::clamp(y_scale * v, y_min, y_max);  // NaN stays NaN
  }
  return s;
}

bool NarxModel::ForgetsItsStart(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double shift,
                                const Eigen::VectorXd* run) const {
  const Eigen::VectorXd nominal = run != nullptr ? *run : Simulate(u, y);
  PNEUMID_CHECK(nominal.size() == y.size(), "NARX: the run has {} samples, the output {}",
                nominal.size(), y.size());
  const Eigen::Index n0 = FirstSample(), half = (y.size() - n0) / 2;
  if (!(shift > 0.0) || half < 2) return true;
  for (const double sign : {-1.0, 1.0}) {
    Eigen::VectorXd shifted = y;
    shifted.head(n0).array() += sign * shift;
    const Eigen::VectorXd r = Simulate(u, shifted);
    if (!r.tail(half).allFinite() ||
        !((r.tail(half) - nominal.tail(half)).cwiseAbs().maxCoeff() <= 0.2 * shift))
      return false;
  }
  return true;
}

nlohmann::json ToJson(const NarxModel& m) {
  std::vector<std::string> names;
  for (const NarxTerm& t : m.terms) names.push_back(m.TermName(t));
  nlohmann::json j = {{"ny", m.ny},           {"nu", m.nu},          {"nk", m.nk},
                      {"degree", m.degree},   {"Ts", m.Ts},          {"terms", names},
                      {"theta", m.theta},     {"err", m.err},        {"u_offset", m.u_offset},
                      {"u_scale", m.u_scale}, {"y_scale", m.y_scale}};
  if (std::isfinite(m.y_min)) j["y_min"] = m.y_min;
  if (std::isfinite(m.y_max)) j["y_max"] = m.y_max;
  return j;
}

NarxModel NarxModelFromJson(const nlohmann::json& j) {
  PNEUMID_CHECK(j.is_object(), "a NARX model must be a JSON object, got a JSON {}", j.type_name());
  for (const char* key : {"ny", "nu", "nk", "Ts", "terms", "theta"})
    PNEUMID_CHECK(j.contains(key), "NARX model without the key '{}'", key);
  NarxModel m;
  for (auto [key, dst] : {std::pair{"ny", &m.ny}, {"nu", &m.nu}, {"nk", &m.nk}}) {
    PNEUMID_CHECK(j.at(key).is_number_integer() && j.at(key).get<int>() >= 0,
                  "NARX model: '{}' must be an integer >= 0, got {}", key,
                  Excerpt(j.at(key).dump()));
    *dst = j.at(key).get<int>();
  }
  m.degree = j.value("degree", 2);
  PNEUMID_CHECK(j.at("Ts").is_number() && j.at("Ts").get<double>() > 0,
                "NARX model: 'Ts' must be a positive number, got {}", Excerpt(j.at("Ts").dump()));
  m.Ts = j.at("Ts").get<double>();
  PNEUMID_CHECK(j.at("terms").is_array() && j.at("theta").is_array() &&
                    j.at("terms").size() == j.at("theta").size(),
                "NARX model: 'terms' and 'theta' must be arrays of equal length");
  for (const nlohmann::json& t : j.at("terms")) {
    PNEUMID_CHECK(t.is_string(), "NARX model: a term must be a string, got {}", Excerpt(t.dump()));
    m.terms.push_back(ParseTerm(t.get<std::string>(), m.ny, m.nu, m.nk));
  }
  for (const nlohmann::json& v : j.at("theta")) {
    PNEUMID_CHECK(v.is_number(), "NARX model: 'theta' must hold numbers, got {}",
                  Excerpt(v.dump()));
    m.theta.push_back(v.get<double>());
  }
  if (j.contains("err")) m.err = j.at("err").get<std::vector<double>>();
  for (auto [key, dst] :
       {std::pair{"u_offset", &m.u_offset}, {"u_scale", &m.u_scale}, {"y_scale", &m.y_scale}}) {
    if (!j.contains(key)) continue;
    PNEUMID_CHECK(j.at(key).is_number(), "NARX model: '{}' must be a number, got {}", key,
                  Excerpt(j.at(key).dump()));
    *dst = j.at(key).get<double>();
  }
  PNEUMID_CHECK(m.u_scale != 0.0 && m.y_scale != 0.0,
                "NARX model: u_scale and y_scale must not be 0, got {} and {}", m.u_scale,
                m.y_scale);
  for (auto [key, dst] : {std::pair{"y_min", &m.y_min}, {"y_max", &m.y_max}}) {
    if (!j.contains(key)) continue;
    PNEUMID_CHECK(j.at(key).is_number() && std::isfinite(j.at(key).get<double>()),
                  "NARX model: '{}' must be a finite number, got {}", key,
                  Excerpt(j.at(key).dump()));
    *dst = j.at(key).get<double>();
  }
  PNEUMID_CHECK(m.y_min < m.y_max, "NARX model: y_min must lie below y_max, got {} and {}", m.y_min,
                m.y_max);
  return m;
}

}  // namespace pneumid
