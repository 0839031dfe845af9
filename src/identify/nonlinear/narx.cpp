#include "pneumid/identify/nonlinear/narx.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/nonlinear/narx_simulation_fit.hpp"

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

// Summary, theta and fits of the chosen terms: columns S (normalised) of the
// rows t = n0 .. N-1, theta by least squares, then refined by the simulation
// error when the focus is kSimulation.
void FinishNarx(const Eigen::MatrixXd& S, const Eigen::VectorXd& target, const Eigen::VectorXd& u,
                const Eigen::VectorXd& y, const NarxOptions& o, const std::string& frols,
                NarxResult* result) {
  NarxModel& m = result->model;
  const Eigen::Index rows = S.rows();
  const Eigen::VectorXd theta = S.colPivHouseholderQr().solve(target);
  m.theta.assign(theta.data(), theta.data() + theta.size());
  EstimationSummary& s = result->summary;
  s.termination = Termination::kConvergence;
  s.num_rows = rows;
  s.num_parameters = static_cast<int>(S.cols());
  s.loss = m.y_scale * m.y_scale * (target - S * theta).squaredNorm() / static_cast<double>(rows);
  s.message = frols;
  if (o.focus == NarxFocus::kSimulation && !m.terms.empty()) {
    NarxSimulationFitOptions so;
    so.max_iterations = o.max_iterations;
    const NarxSimulationFitResult r = FitNarxSimulation(&m, u, y, so);
    s.termination = r.summary.termination;
    s.iterations = r.summary.iterations;
    s.initial_loss = r.summary.initial_loss;
    s.loss = r.summary.loss;
    s.message += fmt::format(
        "; focus simulation: {} ({} iterations, mean squared simulation error {:.4g}, from {:.4g} "
        "of the least-squares start)",
        r.summary.message, r.summary.iterations, r.summary.loss, r.summary.initial_loss);
    s.warnings.insert(s.warnings.end(), r.summary.warnings.begin(), r.summary.warnings.end());
  }
  const Eigen::VectorXd th =
      Eigen::Map<const Eigen::VectorXd>(m.theta.data(), static_cast<Eigen::Index>(m.theta.size()));
  result->one_step_fit_percent = NrmseFit(target, (S * th).eval());
  result->simulation_fit_percent = NarxSimulationFit(m, u, y, rows, &s.warnings);
}

}  // namespace

const char* ToString(NarxFocus focus) {
  return focus == NarxFocus::kSimulation ? "simulation" : "prediction";
}

NarxFocus NarxFocusFromString(const std::string& name) {
  if (name == "prediction") return NarxFocus::kPrediction;
  PNEUMID_CHECK(name == "simulation", "unknown NARX focus '{}' (valid: prediction, simulation)",
                name);
  return NarxFocus::kSimulation;
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
  if (max_iterations < 1)
    return fail(fmt::format("NarxOptions::max_iterations must be >= 1, got {}", max_iterations));
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
  // The free run's band (narx_model.hpp): the outputs estimated on, widened
  // as the simulation-focus fit's clip band.
  std::tie(m.y_min, m.y_max) = NarxDataBand(y, NarxSimulationFitOptions{}.band);
  const std::vector<NarxTerm> cand = NarxCandidates(o.ny, o.nu, o.degree);
  const Eigen::Index n0 = m.FirstSample();
  const Eigen::Index rows = std::max<Eigen::Index>(0, y.size() - n0);
  const auto M = static_cast<Eigen::Index>(cand.size());
  PNEUMID_CHECK(M <= rows,
                "NARX: {} candidate terms (ny = {}, nu = {}, degree = {}) exceed the {} "
                "regression rows of the {} samples; lower the lags or the degree, or give "
                "more data",
                M, o.ny, o.nu, o.degree, rows, y.size());
  // FROLS without modifying the candidates (one rows x M matrix W): with the
  // chosen terms orthonormalised to q_1..q_s, a candidate's part orthogonal
  // to them, w = p - sum_k (q_k'p) q_k, has
  //   w'w = p'p - sum_k (q_k'p)^2,   w't = p't - sum_k (q_k'p)(q_k't),
  // so each step needs one product q_s'p per candidate (a read-only pass over
  // W) to update ww and wt. The chosen term's q is orthogonalised explicitly
  // (twice, classical Gram-Schmidt with re-orthogonalisation) and a candidate
  // whose explicit remainder is below 1e-10 of its norm is dependent.
  // The regressors (normalised lagged outputs and inputs), then each
  // candidate as the product of its regressors' columns (as TermValue).
  const int nr = o.ny + o.nu;
  Eigen::MatrixXd R(rows, nr);
  for (int k = 0; k < nr; ++k)
    for (Eigen::Index r = 0; r < rows; ++r) R(r, k) = m.TermValue(NarxTerm(1, k), r + n0, y, u);
  Eigen::MatrixXd W(rows, M);
  for (Eigen::Index c = 0; c < M; ++c) {
    auto w = W.col(c);
    w.setOnes();
    for (int k : cand[static_cast<std::size_t>(c)]) w.array() *= R.col(k).array();
  }
  R.resize(0, 0);
  const Eigen::VectorXd target = y.tail(rows) / m.y_scale;
  const double yy = target.squaredNorm();
  PNEUMID_CHECK(yy > 0.0, "NARX: the output is zero throughout (y'y = 0)");
  Eigen::VectorXd norms2(M), ww(M), wt(M);
  for (Eigen::Index c = 0; c < M; ++c) {
    norms2[c] = ww[c] = W.col(c).squaredNorm();
    wt[c] = W.col(c).dot(target);
  }
  std::vector<bool> used(static_cast<std::size_t>(M), false);
  std::vector<Eigen::Index> chosen;
  std::vector<Eigen::VectorXd> basis;  // q_1..q_s, unit norm
  double esr = 1.0;
  std::string stop;
  const Eigen::Index work = rows * M;
  const unsigned threads =
      work < 4'000'000 ? 1u : std::max(1u, std::min(8u, std::thread::hardware_concurrency()));
  while (true) {
    Eigen::Index best = -1;
    double best_err = 0.0;
    for (Eigen::Index c = 0; c < M; ++c) {
      if (used[static_cast<std::size_t>(c)]) continue;
      if (!(ww[c] > 1e-10 * norms2[c])) continue;
      const double err = wt[c] * wt[c] / (ww[c] * yy);  // g^2 w'w / y'y, g = w't / w'w
      if (err > best_err) {
        best_err = err;
        best = c;
      }
    }
    if (best < 0) {
      stop = "no independent candidate left";
      break;
    }
    Eigen::VectorXd q = W.col(best);
    for (int pass = 0; pass < 2; ++pass)
      for (const Eigen::VectorXd& b : basis) q -= b.dot(q) * b;
    const double qq = q.squaredNorm();
    used[static_cast<std::size_t>(best)] = true;
    if (!(qq > 1e-10 * norms2[best])) continue;  // dependent after all: never chosen
    q /= std::sqrt(qq);
    const double err = std::pow(q.dot(target), 2) / yy;
    chosen.push_back(best);
    m.err.push_back(err);
    esr -= err;
    const double qt = q.dot(target);
    // Columns are independent: split them over the hardware threads (the
    // result does not depend on the split).
    auto downdate = [&](Eigen::Index from, Eigen::Index to) {
      for (Eigen::Index c = from; c < to; ++c) {
        if (used[static_cast<std::size_t>(c)]) continue;
        const double d = q.dot(W.col(c));
        ww[c] -= d * d;
        wt[c] -= d * qt;
      }
    };
    if (threads == 1) {
      downdate(0, M);
    } else {
      std::vector<std::thread> pool;
      const Eigen::Index chunk = (M + threads - 1) / threads;
      for (unsigned k = 0; k < threads; ++k)
        pool.emplace_back(downdate, std::min<Eigen::Index>(M, k * chunk),
                          std::min<Eigen::Index>(M, (k + 1) * chunk));
      for (std::thread& t : pool) t.join();
    }
    basis.push_back(std::move(q));
    if (esr < o.err_tolerance) {
      stop = fmt::format("1 - sum ERR = {:.3g} < {:g}", esr, o.err_tolerance);
      break;
    }
    if (static_cast<int>(chosen.size()) >= o.max_terms) {
      stop = fmt::format("max_terms = {} reached (1 - sum ERR = {:.3g})", o.max_terms, esr);
      break;
    }
  }
  basis.clear();
  Eigen::MatrixXd S(rows, static_cast<Eigen::Index>(chosen.size()));
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    S.col(static_cast<Eigen::Index>(i)) = W.col(chosen[i]);
    m.terms.push_back(cand[chosen[i]]);
  }
  W.resize(0, 0);
  FinishNarx(S, target, u, y, o,
             fmt::format("FROLS: {} of {} candidate terms, stopped: {}", chosen.size(), M, stop),
             &result);
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
