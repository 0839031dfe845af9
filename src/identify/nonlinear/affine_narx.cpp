#include "pneumid/identify/nonlinear/affine_narx.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/nonlinear/narx_simulation_fit.hpp"
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

// Checks the options and data; returns the output scale y_scale = max |y|.
double CheckedOutputScale(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double Ts,
                          const AffineNarxOptions& options) {
  std::string why;
  PNEUMID_CHECK(options.IsValid(&why), "affine NARX: {}", why);
  PNEUMID_CHECK(u.size() == y.size(), "affine NARX: the input has {} samples, the output {}",
                u.size(), y.size());
  PNEUMID_CHECK(Ts > 0.0 && std::isfinite(Ts), "sample time must be positive, got Ts = {}", Ts);
  PNEUMID_CHECK(u.allFinite() && y.allFinite(), "affine NARX: the data hold non-finite values");
  const double u_min = u.size() ? u.minCoeff() : 0.0, u_max = u.size() ? u.maxCoeff() : 0.0;
  PNEUMID_CHECK(u_max > u_min,
                "affine NARX: the input never leaves one operating point (u = {:g} throughout)",
                u_min);
  const double y_scale = y.cwiseAbs().maxCoeff();
  PNEUMID_CHECK(y_scale > 0.0, "affine NARX: the output is zero throughout");
  return y_scale;
}

// The one-step regression: rows t = max(1, nk) .. N-1 (y(t-1) and u(t-nk) exist).
struct AffineNarxRegression {
  Eigen::Index rows = 0;
  Eigen::MatrixXd z_powers;   // row r: z(t-1)^p, p = 0..d
  std::vector<Tent> tent;     // tent weights of u(t-nk) on the knots
  Eigen::VectorXd dz;         // target z(t) - z(t-1)
  std::vector<int> per_knot;  // rows whose input is nearest to each knot
};

// Regressors: powers of z(t-1), the tent weights of u(t-nk), the target
// z(t) - z(t-1).
AffineNarxRegression BuildRegression(const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                                     double y_scale, const std::vector<double>& knots, int d,
                                     int nk, Eigen::Index first_row, Eigen::Index rows) {
  AffineNarxRegression reg;
  reg.rows = rows;
  reg.z_powers.resize(rows, d + 1);
  reg.tent.resize(static_cast<std::size_t>(rows));
  reg.dz.resize(rows);
  reg.per_knot.assign(knots.size(), 0);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const Eigen::Index t = r + first_row;
    const double z = y[t - 1] / y_scale;
    double power = 1.0;
    for (int k = 0; k <= d; ++k, power *= z) reg.z_powers(r, k) = power;
    reg.dz[r] = (y[t] - y[t - 1]) / y_scale;
    const double u_lagged = u[t - nk];
    reg.tent[static_cast<std::size_t>(r)] = TentAt(knots, u_lagged);
    const Tent& tent = reg.tent[static_cast<std::size_t>(r)];
    ++reg.per_knot[static_cast<std::size_t>(tent.w < 0.5 ? tent.j : tent.j + 1)];
  }
  return reg;
}

// The mapped input f(u(t-nk)) of every row for knot values alpha.
Eigen::VectorXd MappedInput(const AffineNarxRegression& reg, const Eigen::VectorXd& alpha) {
  Eigen::VectorXd mapped(reg.rows);
  for (Eigen::Index r = 0; r < reg.rows; ++r) {
    const Tent& tent = reg.tent[static_cast<std::size_t>(r)];
    mapped[r] = (1.0 - tent.w) * alpha[tent.j] + tent.w * alpha[tent.j + 1];
  }
  return mapped;
}

// The regressors [z^p, v z^p] of a, b for the mapped input v.
Eigen::MatrixXd AbRegressors(const AffineNarxRegression& reg, const Eigen::VectorXd& mapped) {
  const Eigen::Index cols = 2 * reg.z_powers.cols();
  Eigen::MatrixXd regressors(reg.rows, cols);
  regressors << reg.z_powers, reg.z_powers.array().colwise() * mapped.array();
  return regressors;
}

// The knot values of f from the alternating least squares and how the iteration ended.
struct AlternationResult {
  Eigen::VectorXd alpha;  // f at the knots, 0 at the first knot and 1 at the last
  int iterations = 0;
  bool converged = false;
  double initial_loss = 0.0;  // sum of squared one-step errors with f linear
};

AlternationResult AlternateLeastSquares(const AffineNarxRegression& reg,
                                        const std::vector<double>& knots, int d,
                                        const AffineNarxOptions& options) {
  const auto num_knots = static_cast<Eigen::Index>(knots.size());
  AlternationResult out;
  // f starts linear in u over the knots: 0 at the first knot, 1 at the last.
  out.alpha.resize(num_knots);
  for (Eigen::Index j = 0; j < num_knots; ++j)
    out.alpha[j] = (knots[j] - knots[0]) / (knots[num_knots - 1] - knots[0]);
  const Eigen::MatrixXd& Z = reg.z_powers;
  const Eigen::VectorXd& dz = reg.dz;
  double loss = std::numeric_limits<double>::infinity();
  for (; out.iterations < options.max_iterations; ++out.iterations) {
    // 1. a, b for the current f.
    const Eigen::MatrixXd regressors = AbRegressors(reg, MappedInput(reg, out.alpha));
    const Eigen::VectorXd ab = regressors.colPivHouseholderQr().solve(dz);
    const double loss_ab = (dz - regressors * ab).squaredNorm();
    if (out.iterations == 0) out.initial_loss = loss_ab;
    // 2. f for the current a, b (minimum norm where knots have no data).
    const Eigen::VectorXd a_of_z = Z * ab.head(d + 1), b_of_z = Z * ab.tail(d + 1);
    Eigen::MatrixXd tent_regressors = Eigen::MatrixXd::Zero(reg.rows, num_knots);
    for (Eigen::Index r = 0; r < reg.rows; ++r) {
      const Tent& tent = reg.tent[static_cast<std::size_t>(r)];
      tent_regressors(r, tent.j) += (1.0 - tent.w) * b_of_z[r];
      tent_regressors(r, tent.j + 1) += tent.w * b_of_z[r];
    }
    const Eigen::VectorXd next =
        tent_regressors.completeOrthogonalDecomposition().solve(dz - a_of_z);
    const double loss_f = (dz - a_of_z - tent_regressors * next).squaredNorm();
    // Normalise f (its offset and scale trade with a and b, fitted next round).
    const double span = next[num_knots - 1] - next[0];
    const double scale = std::abs(span) > 1e-12 ? span : (next.array() - next[0]).abs().maxCoeff();
    if (!(scale > 0.0) || !next.allFinite()) break;  // b(z) = 0: f is not determined
    out.alpha = (next.array() - next[0]) / scale;
    const double previous = loss;
    loss = std::min(loss_ab, loss_f);
    if (std::isfinite(previous) && previous - loss <= options.tolerance * previous) {
      out.converged = true;
      ++out.iterations;
      break;
    }
  }
  return out;
}

// ERR of each column of `terms` in the order written: its orthogonal part's
// share of target'target.
std::vector<double> ErrorReductionRatios(const Eigen::MatrixXd& terms,
                                         const Eigen::VectorXd& target) {
  std::vector<double> err;
  const double target_energy = target.squaredNorm();
  Eigen::MatrixXd orthogonal = terms;
  for (Eigen::Index c = 0; c < orthogonal.cols(); ++c) {
    for (Eigen::Index p = 0; p < c; ++p) {
      const double qq = orthogonal.col(p).squaredNorm();
      if (qq > 0.0)
        orthogonal.col(c) -= (orthogonal.col(p).dot(orthogonal.col(c)) / qq) * orthogonal.col(p);
    }
    const double ww = orthogonal.col(c).squaredNorm();
    err.push_back(ww > 1e-20 * terms.col(c).squaredNorm() && target_energy > 0.0
                      ? std::pow(orthogonal.col(c).dot(target), 2) / (ww * target_energy)
                      : 0.0);
  }
  return err;
}

// The NARX part in the mapped input v: terms z^p (index 0 = y(t-1)) and
// v z^p (index 1 = v(t-nk)), in that order; the z(t-1) coefficient carries
// the 1 of z(t) = z(t-1) + ...
NarxModel AffineNarxModel(const AffineNarxRegression& reg, const Eigen::VectorXd& mapped,
                          const Eigen::VectorXd& ab, int d, int nk, double Ts, double y_scale) {
  NarxModel narx;
  narx.ny = 1;
  narx.nu = 1;
  narx.nk = nk;
  narx.degree = d + 1;
  narx.Ts = Ts;
  narx.u_offset = 0.0;
  narx.u_scale = 1.0;
  narx.y_scale = y_scale;
  const Eigen::MatrixXd& Z = reg.z_powers;
  Eigen::MatrixXd terms(reg.rows, 2 * (d + 1));
  for (int k = 0; k <= d; ++k) {
    narx.terms.push_back(NarxTerm(static_cast<std::size_t>(k), 0));
    narx.theta.push_back(ab[k] + (k == 1 ? 1.0 : 0.0));
    terms.col(k) = Z.col(k);
  }
  for (int k = 0; k <= d; ++k) {
    NarxTerm term(static_cast<std::size_t>(k), 0);
    term.push_back(1);
    narx.terms.push_back(term);
    narx.theta.push_back(ab[d + 1 + k]);
    terms.col(d + 1 + k) = Z.col(k).cwiseProduct(mapped);
  }
  narx.err = ErrorReductionRatios(terms, (reg.dz + Z.col(1)).eval());
  return narx;
}

// Termination, losses (output units^2 per row), message and the knots without data.
void FillSummary(const AffineNarxRegression& reg, const AlternationResult& alternation,
                 const std::vector<double>& knots, const Eigen::VectorXd& prediction,
                 double y_scale, Eigen::Index num_params, EstimationSummary* summary) {
  const int iterations = alternation.iterations;
  summary->termination =
      alternation.converged ? Termination::kConvergence : Termination::kNoConvergence;
  summary->num_rows = reg.rows;
  summary->num_parameters = static_cast<int>(num_params);
  summary->iterations = iterations;
  summary->loss =
      y_scale * y_scale * (reg.dz - prediction).squaredNorm() / static_cast<double>(reg.rows);
  summary->initial_loss =
      y_scale * y_scale * alternation.initial_loss / static_cast<double>(reg.rows);
  summary->message =
      alternation.converged
          ? fmt::format("alternating least squares converged after {} rounds", iterations)
          : fmt::format("alternating least squares stopped after {} rounds (max_iterations)",
                        iterations);
  for (std::size_t j = 0; j < knots.size(); ++j)
    if (reg.per_knot[j] == 0)
      summary->warnings.push_back(
          fmt::format("no data near knot u = {:g}: its map value is the "
                      "minimum-norm choice",
                      knots[j]));
}

}  // namespace

AffineNarxResult EstimateAffineNarx(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double Ts,
                                    const AffineNarxOptions& options) {
  const double y_scale = CheckedOutputScale(u, y, Ts, options);
  std::vector<double> knots = options.knots;
  if (knots.empty()) knots = PlaceMapKnots(u, options.num_knots);
  const auto num_knots = static_cast<Eigen::Index>(knots.size());
  const int d = options.degree;
  // rows t = max(1, nk) .. N-1 (y(t-1) and u(t-nk) exist)
  const Eigen::Index first_row = std::max(1, options.nk);
  const Eigen::Index rows = std::max<Eigen::Index>(0, y.size() - first_row);
  const Eigen::Index num_params = 2 * (d + 1) + num_knots;
  PNEUMID_CHECK(rows >= num_params,
                "affine NARX: {} parameters (degree {}, {} knots) exceed the {} regression rows "
                "of the {} samples; use fewer knots or give more data",
                num_params, d, num_knots, rows, y.size());

  const AffineNarxRegression reg =
      BuildRegression(u, y, y_scale, knots, d, options.nk, first_row, rows);
  const AlternationResult alternation = AlternateLeastSquares(reg, knots, d, options);
  const Eigen::VectorXd& alpha = alternation.alpha;
  // Final a, b for the final f.
  const Eigen::VectorXd mapped = MappedInput(reg, alpha);
  const Eigen::MatrixXd regressors = AbRegressors(reg, mapped);
  const Eigen::VectorXd ab = regressors.colPivHouseholderQr().solve(reg.dz);
  const Eigen::VectorXd prediction = regressors * ab;

  AffineNarxResult result;
  result.map = StaticMap(knots, std::vector<double>(alpha.data(), alpha.data() + num_knots),
                         StaticMapExtrapolation::kClamp);
  result.narx = AffineNarxModel(reg, mapped, ab, d, options.nk, Ts, y_scale);
  // The free run's band, as a polynomial NARX's (narx_model.hpp): a run that
  // leaves the region estimated on is held at its edge, not carried to
  // infinity, and ExtrapolationWarnings says so.
  std::tie(result.narx.y_min, result.narx.y_max) = NarxDataBand(y, NarxSimulationFitOptions{}.band);
  FillSummary(reg, alternation, knots, prediction, y_scale, num_params, &result.summary);
  const Eigen::VectorXd zt = y.tail(rows) / y_scale;
  result.one_step_fit_percent = NrmseFit(zt, (prediction + reg.z_powers.col(1)).eval());
  result.simulation_fit_percent =
      NarxSimulationFit(result.narx, result.map.Evaluate(u), y, rows, &result.summary.warnings);
  return result;
}

}  // namespace pneumid
