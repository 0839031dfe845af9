#include "pneumid/identify/narx.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "pneumid/common/check.hpp"
#include "pneumid/common/strings.hpp"
#include "pneumid/identify/fit_metrics.hpp"

namespace pneumid {

namespace {

// Value of regressor r at time t from the output history `y` and input `u`.
inline double Regressor(const NarxModel& m, int r, Eigen::Index t, const Eigen::VectorXd& y,
                        const Eigen::VectorXd& u) {
  return r < m.ny ? y[t - 1 - r] / m.y_scale : (u[t - m.nk - (r - m.ny)] - m.u_offset) / m.u_scale;
}

inline double TermValue(const NarxModel& m, const NarxTerm& term, Eigen::Index t,
                        const Eigen::VectorXd& y, const Eigen::VectorXd& u) {
  double v = 1.0;
  for (int r : term) v *= Regressor(m, r, t, y, u);
  return v;
}

void AddCandidates(int n, int degree, int first, NarxTerm* prefix, std::vector<NarxTerm>* out) {
  if (static_cast<int>(prefix->size()) == degree) return;
  for (int r = first; r < n; ++r) {
    prefix->push_back(r);
    out->push_back(*prefix);
    AddCandidates(n, degree, r, prefix, out);
    prefix->pop_back();
  }
}

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
    for (std::size_t i = 0; i < terms.size(); ++i)
      v += theta[i] * TermValue(*this, terms[i], t, y, u);
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
    for (std::size_t i = 0; i < terms.size(); ++i)
      v += theta[i] * TermValue(*this, terms[i], t, s, u);
    s[t] = y_scale * v;
  }
  return s;
}

nlohmann::json ToJson(const NarxModel& m) {
  std::vector<std::string> names;
  for (const NarxTerm& t : m.terms) names.push_back(m.TermName(t));
  return {{"ny", m.ny},           {"nu", m.nu},          {"nk", m.nk},
          {"degree", m.degree},   {"Ts", m.Ts},          {"terms", names},
          {"theta", m.theta},     {"err", m.err},        {"u_offset", m.u_offset},
          {"u_scale", m.u_scale}, {"y_scale", m.y_scale}};
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
  return m;
}

bool NarxOptions::IsValid(std::string* error) const {
  auto fail = [error](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (ny < 0 || nu < 1 || nk < 0)
    return fail(
        fmt::format("NarxOptions: lags must be ny >= 0, nu >= 1, nk >= 0, got ny = {}, "
                    "nu = {}, nk = {}",
                    ny, nu, nk));
  if (degree < 1 || degree > 3)
    return fail(fmt::format("NarxOptions::degree must be 1, 2 or 3, got {}", degree));
  if (!(err_tolerance > 0.0 && err_tolerance < 1.0))
    return fail(fmt::format("NarxOptions::err_tolerance must be in (0, 1), got {}", err_tolerance));
  if (max_terms < 1)
    return fail(fmt::format("NarxOptions::max_terms must be >= 1, got {}", max_terms));
  return true;
}

std::vector<NarxTerm> NarxCandidates(int ny, int nu, int degree) {
  std::vector<NarxTerm> out = {NarxTerm{}};
  std::vector<NarxTerm> all;
  NarxTerm prefix;
  AddCandidates(ny + nu, degree, 0, &prefix, &all);
  std::stable_sort(all.begin(), all.end(),
                   [](const NarxTerm& a, const NarxTerm& b) { return a.size() < b.size(); });
  out.insert(out.end(), all.begin(), all.end());
  return out;
}

NarxResult EstimateNarx(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double Ts,
                        const NarxOptions& o) {
  std::string why;
  PNEUMID_CHECK(o.IsValid(&why), "{}", why);
  PNEUMID_CHECK(u.size() == y.size(), "NARX: the input has {} samples, the output {}", u.size(),
                y.size());
  PNEUMID_CHECK(Ts > 0.0 && std::isfinite(Ts), "sample time must be positive, got Ts = {}", Ts);
  PNEUMID_CHECK(u.allFinite() && y.allFinite(), "NARX: the data hold non-finite values");
  NarxResult result;
  NarxModel& m = result.model;
  m.ny = o.ny;
  m.nu = o.nu;
  m.nk = o.nk;
  m.degree = o.degree;
  m.Ts = Ts;
  if (o.normalise) {
    const double lo = u.minCoeff(), hi = u.maxCoeff();
    PNEUMID_CHECK(hi > lo, "NARX: the input never leaves one operating point (u = {:g} throughout)",
                  lo);
    m.u_offset = 0.5 * (lo + hi);
    m.u_scale = 0.5 * (hi - lo);
    m.y_scale = y.cwiseAbs().maxCoeff();
    PNEUMID_CHECK(m.y_scale > 0.0, "NARX: the output is zero throughout");
  }
  const std::vector<NarxTerm> cand = NarxCandidates(o.ny, o.nu, o.degree);
  const Eigen::Index n0 = m.FirstSample();
  const Eigen::Index rows = std::max<Eigen::Index>(0, y.size() - n0);
  const auto M = static_cast<Eigen::Index>(cand.size());
  PNEUMID_CHECK(M <= rows,
                "NARX: {} candidate terms (ny = {}, nu = {}, degree = {}) exceed the {} "
                "regression rows of the {} samples; lower the lags or the degree, or give "
                "more data",
                M, o.ny, o.nu, o.degree, rows, y.size());
  Eigen::MatrixXd P(rows, M);
  for (Eigen::Index r = 0; r < rows; ++r)
    for (Eigen::Index c = 0; c < M; ++c) P(r, c) = TermValue(m, cand[c], r + n0, y, u);
  const Eigen::VectorXd target = y.tail(rows) / m.y_scale;
  const double yy = target.squaredNorm();
  PNEUMID_CHECK(yy > 0.0, "NARX: the output is zero throughout (y'y = 0)");

  // FROLS: W holds the candidates orthogonalised against the chosen terms.
  Eigen::MatrixXd W = P;
  const Eigen::VectorXd norms = P.colwise().norm();
  std::vector<bool> used(static_cast<std::size_t>(M), false);
  std::vector<Eigen::Index> chosen;
  double esr = 1.0;
  std::string stop;
  while (true) {
    Eigen::Index best = -1;
    double best_err = 0.0;
    for (Eigen::Index c = 0; c < M; ++c) {
      if (used[c]) continue;
      const double ww = W.col(c).squaredNorm();
      if (ww <= 1e-20 * norms[c] * norms[c] || ww == 0.0) continue;
      const double g = W.col(c).dot(target) / ww;
      const double err = g * g * ww / yy;
      if (err > best_err) {
        best_err = err;
        best = c;
      }
    }
    if (best < 0) {
      stop = "no independent candidate left";
      break;
    }
    used[best] = true;
    chosen.push_back(best);
    m.err.push_back(best_err);
    esr -= best_err;
    const Eigen::VectorXd q = W.col(best);
    const double qq = q.squaredNorm();
    for (Eigen::Index c = 0; c < M; ++c)
      if (!used[c]) W.col(c) -= (q.dot(W.col(c)) / qq) * q;
    if (esr < o.err_tolerance) {
      stop = fmt::format("1 - sum ERR = {:.3g} < {:g}", esr, o.err_tolerance);
      break;
    }
    if (static_cast<int>(chosen.size()) >= o.max_terms) {
      stop = fmt::format("max_terms = {} reached (1 - sum ERR = {:.3g})", o.max_terms, esr);
      break;
    }
  }
  Eigen::MatrixXd S(rows, static_cast<Eigen::Index>(chosen.size()));
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    S.col(static_cast<Eigen::Index>(i)) = P.col(chosen[i]);
    m.terms.push_back(cand[chosen[i]]);
  }
  const Eigen::VectorXd theta = S.colPivHouseholderQr().solve(target);
  m.theta.assign(theta.data(), theta.data() + theta.size());

  EstimationSummary& s = result.summary;
  s.termination = Termination::kConvergence;
  s.num_rows = rows;
  s.num_parameters = static_cast<int>(chosen.size());
  s.loss = m.y_scale * m.y_scale * (target - S * theta).squaredNorm() / static_cast<double>(rows);
  s.message = fmt::format("FROLS: {} of {} candidate terms, stopped: {}", chosen.size(), M, stop);
  result.one_step_fit_percent = NrmseFit(target, (S * theta).eval());
  result.simulation_fit_percent = NarxSimulationFit(m, u, y, rows, &s.warnings);
  return result;
}

double NarxSimulationFit(const NarxModel& m, const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                         Eigen::Index rows, std::vector<std::string>* warnings) {
  const Eigen::VectorXd sim = m.Simulate(u, y);
  if (!sim.allFinite()) {
    if (warnings) warnings->push_back("the free-run simulation diverges");
    return -std::numeric_limits<double>::infinity();
  }
  return NrmseFit(y.tail(rows).eval(), sim.tail(rows).eval());
}

}  // namespace pneumid
