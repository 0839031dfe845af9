#include "pneumid/identify/nonlinear/affine_narx.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/nonlinear/static_map_fit.hpp"

namespace pneumid {

bool AffineNarxOptions::IsValid(std::string* error) const {
  auto fail = [error](std::string msg) {
    if (error) *error = std::move(msg);
    return false;
  };
  if (degree < 1 || degree > 3) return fail(fmt::format("degree must be in 1..3, got {}", degree));
  if (nk < 0) return fail(fmt::format("nk must be >= 0, got {}", nk));
  if (knots.empty() && num_knots != 0 && num_knots < 2)
    return fail(fmt::format("num_knots must be 0 (automatic) or >= 2, got {}", num_knots));
  if (!knots.empty()) {
    if (knots.size() < 2) return fail(fmt::format("need >= 2 knots, got {}", knots.size()));
    for (std::size_t i = 0; i < knots.size(); ++i) {
      if (!std::isfinite(knots[i])) return fail(fmt::format("knot {} is not finite", i));
      if (i > 0 && !(knots[i] > knots[i - 1]))
        return fail(fmt::format("knots must increase strictly: knot {} = {:g} after {:g}", i,
                                knots[i], knots[i - 1]));
    }
  }
  if (max_iterations < 1)
    return fail(fmt::format("max_iterations must be >= 1, got {}", max_iterations));
  if (!(tolerance > 0.0 && tolerance < 1.0))
    return fail(fmt::format("tolerance must be in (0, 1), got {}", tolerance));
  return true;
}

namespace {

// Tent basis of the knots at x: weight 1 - w on knot j, w on knot j + 1;
// beyond the knots all weight on the end knot (the map clamps).
struct Tent {
  Eigen::Index j = 0;
  double w = 0.0;
};

Tent TentAt(const std::vector<double>& c, double x) {
  const auto m = static_cast<Eigen::Index>(c.size());
  if (!(x > c.front())) return {0, 0.0};
  if (x >= c.back()) return {m - 2, 1.0};
  const auto j = static_cast<Eigen::Index>(std::upper_bound(c.begin(), c.end(), x) - c.begin()) - 1;
  return {j, (x - c[j]) / (c[j + 1] - c[j])};
}

}  // namespace

AffineNarxResult EstimateAffineNarx(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double Ts,
                                    const AffineNarxOptions& o) {
  std::string why;
  PNEUMID_CHECK(o.IsValid(&why), "affine NARX: {}", why);
  PNEUMID_CHECK(u.size() == y.size(), "affine NARX: the input has {} samples, the output {}",
                u.size(), y.size());
  PNEUMID_CHECK(Ts > 0.0 && std::isfinite(Ts), "sample time must be positive, got Ts = {}", Ts);
  PNEUMID_CHECK(u.allFinite() && y.allFinite(), "affine NARX: the data hold non-finite values");
  const double lo = u.size() ? u.minCoeff() : 0.0, hi = u.size() ? u.maxCoeff() : 0.0;
  PNEUMID_CHECK(
      hi > lo, "affine NARX: the input never leaves one operating point (u = {:g} throughout)", lo);
  const double y_scale = y.cwiseAbs().maxCoeff();
  PNEUMID_CHECK(y_scale > 0.0, "affine NARX: the output is zero throughout");

  std::vector<double> knots = o.knots;
  if (knots.empty()) knots = PlaceMapKnots(u, o.num_knots);
  const auto m = static_cast<Eigen::Index>(knots.size());
  const int d = o.degree;
  // rows t = max(1, nk) .. N-1 (y(t-1) and u(t-nk) exist)
  const Eigen::Index n0 = std::max(1, o.nk);
  const Eigen::Index rows = std::max<Eigen::Index>(0, y.size() - n0);
  const Eigen::Index num_params = 2 * (d + 1) + m;
  PNEUMID_CHECK(rows >= num_params,
                "affine NARX: {} parameters (degree {}, {} knots) exceed the {} regression rows "
                "of the {} samples; use fewer knots or give more data",
                num_params, d, m, rows, y.size());

  // Regressors: powers of z(t-1), the tent weights of u(t-nk), the target
  // z(t) - z(t-1).
  Eigen::MatrixXd Z(rows, d + 1);
  std::vector<Tent> tent(static_cast<std::size_t>(rows));
  Eigen::VectorXd dz(rows), ulag(rows);
  std::vector<int> per_knot(static_cast<std::size_t>(m), 0);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const Eigen::Index t = r + n0;
    const double z = y[t - 1] / y_scale;
    double p = 1.0;
    for (int k = 0; k <= d; ++k, p *= z) Z(r, k) = p;
    dz[r] = (y[t] - y[t - 1]) / y_scale;
    ulag[r] = u[t - o.nk];
    tent[static_cast<std::size_t>(r)] = TentAt(knots, ulag[r]);
    const Tent& h = tent[static_cast<std::size_t>(r)];
    ++per_knot[static_cast<std::size_t>(h.w < 0.5 ? h.j : h.j + 1)];
  }

  // f starts linear in u over the knots: 0 at the first knot, 1 at the last.
  Eigen::VectorXd alpha(m);
  for (Eigen::Index j = 0; j < m; ++j) alpha[j] = (knots[j] - knots[0]) / (knots[m - 1] - knots[0]);
  auto mapped = [&](const Eigen::VectorXd& a) {
    Eigen::VectorXd v(rows);
    for (Eigen::Index r = 0; r < rows; ++r) {
      const Tent& h = tent[static_cast<std::size_t>(r)];
      v[r] = (1.0 - h.w) * a[h.j] + h.w * a[h.j + 1];
    }
    return v;
  };

  Eigen::VectorXd ab(2 * (d + 1));
  double loss = std::numeric_limits<double>::infinity(), initial_loss = 0.0;
  int iterations = 0;
  bool converged = false;
  for (; iterations < o.max_iterations; ++iterations) {
    // 1. a, b for the current f.
    const Eigen::VectorXd v = mapped(alpha);
    Eigen::MatrixXd F(rows, 2 * (d + 1));
    F << Z, Z.array().colwise() * v.array();
    ab = F.colPivHouseholderQr().solve(dz);
    const double loss_ab = (dz - F * ab).squaredNorm();
    if (iterations == 0) initial_loss = loss_ab;
    // 2. f for the current a, b (minimum norm where knots have no data).
    const Eigen::VectorXd A = Z * ab.head(d + 1), B = Z * ab.tail(d + 1);
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(rows, m);
    for (Eigen::Index r = 0; r < rows; ++r) {
      const Tent& h = tent[static_cast<std::size_t>(r)];
      H(r, h.j) += (1.0 - h.w) * B[r];
      H(r, h.j + 1) += h.w * B[r];
    }
    const Eigen::VectorXd next = H.completeOrthogonalDecomposition().solve(dz - A);
    const double loss_f = (dz - A - H * next).squaredNorm();
    // Normalise f (its offset and scale trade with a and b, fitted next round).
    const double span = next[m - 1] - next[0];
    const double scale = std::abs(span) > 1e-12 ? span : (next.array() - next[0]).abs().maxCoeff();
    if (!(scale > 0.0) || !next.allFinite()) break;  // b(z) = 0: f is not determined
    alpha = (next.array() - next[0]) / scale;
    const double previous = loss;
    loss = std::min(loss_ab, loss_f);
    if (std::isfinite(previous) && previous - loss <= o.tolerance * previous) {
      converged = true;
      ++iterations;
      break;
    }
  }
  // Final a, b for the final f.
  const Eigen::VectorXd v = mapped(alpha);
  Eigen::MatrixXd F(rows, 2 * (d + 1));
  F << Z, Z.array().colwise() * v.array();
  ab = F.colPivHouseholderQr().solve(dz);
  const Eigen::VectorXd pred = F * ab;

  AffineNarxResult result;
  result.map = StaticMap(knots, std::vector<double>(alpha.data(), alpha.data() + m),
                         StaticMapExtrapolation::kClamp);
  NarxModel& n = result.narx;
  n.ny = 1;
  n.nu = 1;
  n.nk = o.nk;
  n.degree = d + 1;
  n.Ts = Ts;
  n.u_offset = 0.0;
  n.u_scale = 1.0;
  n.y_scale = y_scale;
  // Terms z^p (index 0 = y(t-1)) and v z^p (index 1 = v(t-nk)), in that order;
  // the z(t-1) coefficient carries the 1 of z(t) = z(t-1) + ...
  Eigen::MatrixXd S(rows, 2 * (d + 1));
  for (int k = 0; k <= d; ++k) {
    n.terms.push_back(NarxTerm(static_cast<std::size_t>(k), 0));
    n.theta.push_back(ab[k] + (k == 1 ? 1.0 : 0.0));
    S.col(k) = Z.col(k);
  }
  for (int k = 0; k <= d; ++k) {
    NarxTerm t(static_cast<std::size_t>(k), 0);
    t.push_back(1);
    n.terms.push_back(t);
    n.theta.push_back(ab[d + 1 + k]);
    S.col(d + 1 + k) = Z.col(k).cwiseProduct(v);
  }
  // ERR of each term in the order written: its orthogonal part's share of z'z.
  const Eigen::VectorXd target = (dz + Z.col(1)).eval();
  const double zz = target.squaredNorm();
  Eigen::MatrixXd W = S;
  for (Eigen::Index c = 0; c < W.cols(); ++c) {
    for (Eigen::Index p = 0; p < c; ++p) {
      const double qq = W.col(p).squaredNorm();
      if (qq > 0.0) W.col(c) -= (W.col(p).dot(W.col(c)) / qq) * W.col(p);
    }
    const double ww = W.col(c).squaredNorm();
    n.err.push_back(ww > 1e-20 * S.col(c).squaredNorm() && zz > 0.0
                        ? std::pow(W.col(c).dot(target), 2) / (ww * zz)
                        : 0.0);
  }

  EstimationSummary& s = result.summary;
  s.termination = converged ? Termination::kConvergence : Termination::kNoConvergence;
  s.num_rows = rows;
  s.num_parameters = static_cast<int>(num_params);
  s.iterations = iterations;
  s.loss = y_scale * y_scale * (dz - pred).squaredNorm() / static_cast<double>(rows);
  s.initial_loss = y_scale * y_scale * initial_loss / static_cast<double>(rows);
  s.message =
      converged ? fmt::format("alternating least squares converged after {} rounds", iterations)
                : fmt::format("alternating least squares stopped after {} rounds (max_iterations)",
                              iterations);
  for (Eigen::Index j = 0; j < m; ++j)
    if (per_knot[static_cast<std::size_t>(j)] == 0)
      s.warnings.push_back(
          fmt::format("no data near knot u = {:g}: its map value is the "
                      "minimum-norm choice",
                      knots[static_cast<std::size_t>(j)]));
  const Eigen::VectorXd zt = y.tail(rows) / y_scale;
  result.one_step_fit_percent = NrmseFit(zt, (pred + Z.col(1)).eval());
  result.simulation_fit_percent =
      NarxSimulationFit(n, result.map.Evaluate(u), y, rows, &s.warnings);
  return result;
}

}  // namespace pneumid
