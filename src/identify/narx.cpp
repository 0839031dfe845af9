#include "pneumid/identify/narx.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/fit_metrics.hpp"

namespace pneumid {

namespace {

void AddCandidates(int n, int degree, int first, NarxTerm* prefix, std::vector<NarxTerm>* out) {
  if (static_cast<int>(prefix->size()) == degree) return;
  for (int r = first; r < n; ++r) {
    prefix->push_back(r);
    out->push_back(*prefix);
    AddCandidates(n, degree, r, prefix, out);
    prefix->pop_back();
  }
}

}  // namespace

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
    for (Eigen::Index c = 0; c < M; ++c) P(r, c) = m.TermValue(cand[c], r + n0, y, u);
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
