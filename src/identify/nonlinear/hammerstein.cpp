#include "pneumid/identify/nonlinear/hammerstein.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <ceres/ceres.h>
#include <fmt/format.h>
#include <Eigen/Dense>

#include "../ceres_logging.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/identify/nonlinear/static_map_fit.hpp"
#include "pneumid/identify/parametric/arx.hpp"
#include "pneumid/lti/response.hpp"

namespace pneumid {

namespace {

// The tent basis of the knots at x: f(x) = (1 - w) alpha_j + w alpha_{j+1},
// clamped to the end values beyond the knots.
struct Tent {
  int j = 0;
  double w = 0.0;
};

Tent TentAt(const std::vector<double>& c, double x) {
  const int m = static_cast<int>(c.size());
  if (!(x > c.front())) return {0, 0.0};
  if (x >= c.back()) return {m - 2, 1.0};
  const int j = static_cast<int>(std::upper_bound(c.begin(), c.end(), x) - c.begin()) - 1;
  return {j, (x - c[j]) / (c[j + 1] - c[j])};
}

inline double Value(double x) { return x; }
template <typename J>
double Value(const J& x) {
  return x.a;
}

// The parameter vector of the output-error problem: a (na), b_1..b_{nb-1}
// (b_nb = A(1) - their sum: unit static gain), then the m map values.
struct Layout {
  int na = 0, nb = 1, nk = 0, m = 2;
  int size() const { return na + nb - 1 + m; }
  int map_offset() const { return na + nb - 1; }
};

// x(t) = -sum a_i x(t-i) + sum_k b_k v(t-nk-k) with x and v in steady state
// x = v = v0 before the record (G(1) = 1 by the layout).
template <typename T>
void SimulateUnitGainFrom(const T* p, const Layout& l, const std::vector<T>& v, std::vector<T>* x,
                          const T& v0) {
  const T* a = p;
  T b_last = T(1.0);
  for (int i = 0; i < l.na; ++i) b_last += a[i];
  for (int k = 0; k + 1 < l.nb; ++k) b_last -= p[l.na + k];
  const auto b = [&](int k) { return k + 1 < l.nb ? p[l.na + k] : b_last; };
  const auto n = static_cast<long>(v.size());
  x->resize(v.size());
  for (long t = 0; t < n; ++t) {
    T s = T(0.0);
    for (int i = 1; i <= l.na; ++i) s -= a[i - 1] * (t - i >= 0 ? (*x)[t - i] : v0);
    for (int k = 0; k < l.nb; ++k) {
      const long tau = t - l.nk - k;
      s += b(k) * (tau >= 0 ? v[tau] : v0);
    }
    (*x)[t] = s;
  }
}

// As SimulateUnitGainFrom, at rest at `rest`, or at the first input v(0)
// when rest is not finite.
template <typename T>
void SimulateUnitGain(const T* p, const Layout& l, const std::vector<T>& v, std::vector<T>* x,
                      double rest = std::numeric_limits<double>::quiet_NaN()) {
  SimulateUnitGainFrom(p, l, v, x, std::isfinite(rest) ? T(rest) : v[0]);
}

// The input map through the tents of u: v(t) = (1 - w) alpha_j + w alpha_{j+1}.
template <typename T>
std::vector<T> MapThroughTents(const T* alpha, const std::vector<Tent>& tents) {
  std::vector<T> v(tents.size());
  for (std::size_t t = 0; t < tents.size(); ++t)
    v[t] = (1.0 - tents[t].w) * alpha[tents[t].j] + tents[t].w * alpha[tents[t].j + 1];
  return v;
}

// The output map with values beta on the knots at x, flat beyond them; inside
// it is linear in x on the segment (derivatives with respect to x as well).
template <typename T>
T OutputMap(const std::vector<double>& knots, const T* beta, const T& x) {
  const double xv = Value(x);
  if (xv <= knots.front()) return beta[0];
  if (xv >= knots.back()) return beta[knots.size() - 1];
  const Tent h = TentAt(knots, xv);
  const T w = (x - knots[h.j]) / (knots[h.j + 1] - knots[h.j]);
  return (1.0 - w) * beta[h.j] + w * beta[h.j + 1];
}

// The rest x of the linear part whose output-map value is the first measured
// output y0: the preimage under the piecewise-linear map (values beta on the
// knots) nearest to `near` (the rest at the first input), or the knot whose
// value is nearest y0 when y0 lies outside the map's values (as
// SimulateNonlinear starts a Wiener or Hammerstein-Wiener model on a
// record). StaticMap::NearestPreimageOrEnd for the parameters as Ceres
// varies them (T a Jet in the cost functors); the estimates themselves use
// NearestPreimageOrEnd. Before, y0 outside the values started the record at
// `near`: a linear plant at rest at zero whose record starts with u = 6.67
// and y = 0 (0.01 below the map's lowest value, by noise) was fitted 90 %
// (noise-free: 72 %) with a kinked map.
template <typename T>
T RestFromFirstOutput(const std::vector<double>& knots, const T* beta, double y0, const T& near) {
  T best = near;
  double distance = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j + 1 < knots.size(); ++j) {
    const double b0 = Value(beta[j]), b1 = Value(beta[j + 1]);
    if (!((b0 - y0) * (b1 - y0) <= 0.0) || b0 == b1) continue;
    const T x = knots[j] + (y0 - beta[j]) / (beta[j + 1] - beta[j]) * (knots[j + 1] - knots[j]);
    const double d = std::abs(Value(x) - Value(near));
    if (d < distance) {
      distance = d;
      best = x;
    }
  }
  if (std::isfinite(distance)) return best;
  std::size_t end = 0;  // y0 beyond the values: the knot of the nearest value
  for (std::size_t j = 1; j < knots.size(); ++j) {
    const double d = std::abs(Value(beta[j]) - y0), d_end = std::abs(Value(beta[end]) - y0);
    if (d < d_end ||
        (d == d_end && std::abs(knots[j] - Value(near)) < std::abs(knots[end] - Value(near))))
      end = j;
  }
  return T(knots[end]);
}

// Simulation errors y - yhat of the Hammerstein model, from the rest that
// gives the first measured output (x = v = y(0) before the record, as
// SimulateNonlinear starts a record): a record that starts at rest away from
// f(u(0)), such as a staircase switched on at t = 0 from standstill, then
// does not pull the first level's map value toward y(0).
// With `monotone` (sign +-1) the map parameters are alpha_1 and the square
// roots of the increments: alpha_j = alpha_{j-1} + monotone * q_j^2.
struct HammersteinError {
  Layout l;
  const Eigen::VectorXd* y;
  std::vector<Tent> tents;  // of u(t)
  double monotone = 0.0;
  double rest = std::numeric_limits<double>::quiet_NaN();
  template <typename T>
  bool operator()(T const* const* params, T* residuals) const {
    const T* p = params[0];
    std::vector<T> values(p + l.map_offset(), p + l.map_offset() + l.m);
    if (monotone != 0.0)
      for (int j = 1; j < l.m; ++j) values[j] = values[j - 1] + monotone * values[j] * values[j];
    std::vector<T> x;
    SimulateUnitGain(p, l, MapThroughTents(values.data(), tents), &x, rest);
    for (std::size_t t = 0; t < tents.size(); ++t)
      residuals[t] = (*y)[static_cast<Eigen::Index>(t)] - x[t];
    return true;
  }
};

// Simulation errors of the Wiener model, from the rest whose output-map value
// is the first measured output (RestFromFirstOutput).
struct WienerError {
  Layout l;
  const Eigen::VectorXd* y;
  const Eigen::VectorXd* u;
  std::vector<double> knots;
  template <typename T>
  bool operator()(T const* const* params, T* residuals) const {
    const T* p = params[0];
    std::vector<T> v(static_cast<std::size_t>(u->size())), x;
    for (std::size_t t = 0; t < v.size(); ++t) v[t] = T((*u)[static_cast<Eigen::Index>(t)]);
    SimulateUnitGainFrom(p, l, v, &x,
                         RestFromFirstOutput(knots, p + l.map_offset(), (*y)[0], v[0]));
    for (std::size_t t = 0; t < v.size(); ++t)
      residuals[t] =
          (*y)[static_cast<Eigen::Index>(t)] - OutputMap(knots, p + l.map_offset(), x[t]);
    return true;
  }
};

// Simulation errors of the Hammerstein-Wiener model, from the rest whose
// output-map value is the first measured output (RestFromFirstOutput). The map parameters are
// the inner values f(c_2), .., f(c_{m-1}) of the input map (its end values
// are fixed: f(c_1) = c_1, f(c_m) = c_m), then the m values of the output map
// on `out_knots`.
struct HwError {
  Layout l;  // l.m = (m - 2) + m map parameters
  const Eigen::VectorXd* y;
  std::vector<Tent> tents;  // of u(t) on the input knots
  std::vector<double> in_knots, out_knots;
  template <typename T>
  bool operator()(T const* const* params, T* residuals) const {
    const T* p = params[0];
    const std::size_t m = in_knots.size();
    std::vector<T> alpha(m);
    alpha.front() = T(in_knots.front());
    alpha.back() = T(in_knots.back());
    for (std::size_t j = 1; j + 1 < m; ++j) alpha[j] = p[l.map_offset() + j - 1];
    std::vector<T> x;
    const T* beta = p + l.map_offset() + (m - 2);
    const std::vector<T> v = MapThroughTents(alpha.data(), tents);
    SimulateUnitGainFrom(p, l, v, &x, RestFromFirstOutput(out_knots, beta, (*y)[0], v[0]));
    for (std::size_t t = 0; t < tents.size(); ++t)
      residuals[t] = (*y)[static_cast<Eigen::Index>(t)] - OutputMap(out_knots, beta, x[t]);
    return true;
  }
};

template <typename Functor>
double MeanSquare(const Functor& f, const Eigen::VectorXd& theta, Eigen::Index n) {
  Eigen::VectorXd r(n);
  const double* p = theta.data();
  f(&p, r.data());
  return r.squaredNorm() / static_cast<double>(n);
}

// Output-error refinement of theta with Levenberg-Marquardt.
template <typename Functor>
void RefineOutputError(std::unique_ptr<Functor> functor, Eigen::Index n, const BlockModelOptions& o,
                       Eigen::VectorXd* theta, EstimationSummary* s) {
  s->initial_loss = MeanSquare(*functor, *theta, n);
  s->loss = s->initial_loss;
  s->termination = Termination::kConvergence;
  if (!o.refine) {
    s->message = "initial estimate (no output-error refinement)";
    return;
  }
  auto* cost = new ceres::DynamicAutoDiffCostFunction<Functor, 4>(functor.release());
  cost->AddParameterBlock(static_cast<int>(theta->size()));
  cost->SetNumResiduals(static_cast<int>(n));
  ceres::Problem problem;
  problem.AddResidualBlock(cost, nullptr, theta->data());
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = o.max_iterations;
  so.function_tolerance = o.function_tolerance;
  so.gradient_tolerance = o.gradient_tolerance;
  so.parameter_tolerance = o.parameter_tolerance;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary cs;
  internal::SilenceCeresLogging();
  ceres::Solve(so, &problem, &cs);
  s->iterations = static_cast<int>(cs.iterations.size()) - 1;
  s->loss = 2.0 * cs.final_cost / static_cast<double>(n);
  s->termination = cs.termination_type == ceres::CONVERGENCE      ? Termination::kConvergence
                   : cs.termination_type == ceres::NO_CONVERGENCE ? Termination::kNoConvergence
                                                                  : Termination::kFailure;
  s->message = "output-error Levenberg-Marquardt (Ceres): " + cs.message;
  if (s->termination == Termination::kNoConvergence)
    s->warnings.push_back(fmt::format("not converged after {} iterations", o.max_iterations));
}

// `two_maps`: Hammerstein-Wiener, m - 2 free input-map values and m output-map values.
void CheckSignals(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double Ts,
                  const BlockModelOptions& o, const char* what, bool two_maps = false) {
  std::string why;
  PNEUMID_CHECK(o.IsValid(&why), "{}", why);
  PNEUMID_CHECK(u.size() == y.size(), "{}: the input has {} samples, the output {}", what, u.size(),
                y.size());
  PNEUMID_CHECK(Ts > 0.0 && std::isfinite(Ts), "sample time must be positive, got Ts = {}", Ts);
  PNEUMID_CHECK(u.allFinite() && y.allFinite(), "{}: the data hold non-finite values", what);
  const int m =
      o.knots.empty() ? (o.num_knots == 0 ? 2 : o.num_knots) : static_cast<int>(o.knots.size());
  const int np = o.na + o.nb - 1 + (two_maps ? 2 * m - 2 : m);
  PNEUMID_CHECK(u.size() >= 2 * np,
                "{}: {} samples are too few for {} parameters (na = {}, nb = {}, {} knots)", what,
                u.size(), np, o.na, o.nb, m);
  PNEUMID_CHECK(u.maxCoeff() > u.minCoeff(),
                "{}: the input never leaves one operating point (u = {:g} throughout); a static "
                "map needs inputs over a range",
                what, u[0]);
}

void CheckParameterCount(Eigen::Index n, const Layout& l, const char* what) {
  PNEUMID_CHECK(n >= 2 * l.size(),
                "{}: {} samples are too few for {} parameters (na = {}, nb = {}, {} knots); give "
                "fewer knots or more data",
                what, n, l.size(), l.na, l.nb, l.m);
}

// The knots: given, or placed by PlaceMapKnots(u, num_knots); knots whose tent
// holds no sample are dropped (their value would be undetermined). `name`
// names the signal in the warnings.
std::vector<double> Knots(const Eigen::VectorXd& u, const BlockModelOptions& o,
                          std::vector<std::string>* warnings, const char* name = "u") {
  std::vector<double> c = o.knots;
  if (c.empty()) c = PlaceMapKnots(u, o.num_knots);
  for (;;) {
    std::vector<double> support(c.size(), 0.0);
    for (Eigen::Index t = 0; t < u.size(); ++t) {
      const Tent h = TentAt(c, u[t]);
      support[h.j] += 1.0 - h.w;
      support[h.j + 1] += h.w;
    }
    std::size_t empty = c.size();
    for (std::size_t j = 0; j < c.size() && empty == c.size(); ++j)
      if (support[j] < 1e-9) empty = j;
    if (empty == c.size() || c.size() <= 2) break;
    warnings->push_back(
        fmt::format("knot {} = {:g} dropped: no sample within its neighbours", name, c[empty]));
    c.erase(c.begin() + static_cast<std::ptrdiff_t>(empty));
  }
  return c;
}

PolynomialModel LinearPart(const Eigen::VectorXd& theta, const Layout& l, double Ts) {
  PolynomialModel g;
  g.structure = "OE";
  g.Ts = Ts;
  g.a.resize(l.na + 1);
  g.a[0] = 1.0;
  double b_last = 1.0;
  for (int i = 0; i < l.na; ++i) {
    g.a[i + 1] = theta[i];
    b_last += theta[i];
  }
  Eigen::VectorXd b = Eigen::VectorXd::Zero(l.nk + l.nb);
  for (int k = 0; k + 1 < l.nb; ++k) {
    b[l.nk + k] = theta[l.na + k];
    b_last -= theta[l.na + k];
  }
  b[l.nk + l.nb - 1] = b_last;
  g.b = {b};
  g.nk = {l.nk};
  return g;
}

// The map through the knots with the n values of theta from `offset`.
StaticMap MapOf(const std::vector<double>& knots, const Eigen::VectorXd& theta,
                Eigen::Index offset) {
  const Eigen::VectorXd v = theta.segment(offset, static_cast<Eigen::Index>(knots.size()));
  return StaticMap(knots, std::vector<double>(v.data(), v.data() + v.size()),
                   StaticMapExtrapolation::kClamp);
}

// The output map f on the range [lo, hi] of x, the final linear part's
// output over the estimation data: end knots beyond it (placed over the
// starting model's x, which reached farther, or simply not reached) are
// moved to lo and hi with f's values there. f is unchanged on [lo, hi], and
// so is every simulated output on the estimation data; beyond, the map is
// held at its values at the range's ends instead of at end values that a few
// samples near the tent's far edge set (an end value 133 N for a map that
// starts at 0 N, say), which a later record reaching there would follow.
StaticMap TrimToRange(const StaticMap& f, const std::vector<double>& x) {
  const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
  if (lo == x.end() || !std::isfinite(*lo) || !std::isfinite(*hi)) return f;
  const double a = std::max(*lo, f.u_min()), b = std::min(*hi, f.u_max());
  if (!(a < b)) return f;
  std::vector<double> u = {a}, y = {f.Evaluate(a)};
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (f.u()[i] > a && f.u()[i] < b) {
      u.push_back(f.u()[i]);
      y.push_back(f.y()[i]);
    }
  }
  u.push_back(b);
  y.push_back(f.Evaluate(b));
  return StaticMap(std::move(u), std::move(y), f.extrapolation());
}

BlockModelResult Finish(const Eigen::VectorXd& theta, const Layout& l, double Ts, StaticMap map,
                        EstimationSummary s) {
  BlockModelResult r;
  r.linear = LinearPart(theta, l, Ts);
  r.linear.noise_variance = s.loss;
  r.map = std::move(map);
  s.num_parameters = l.size();
  if (!r.linear.ToTransferFunction().IsStable())
    s.warnings.push_back("the linear part is unstable");
  r.summary = std::move(s);
  return r;
}

// theta of the layout from a, B (nb coefficients, any static gain) and map
// values, scaled so that G(1) = 1.
Eigen::VectorXd Normalised(const Eigen::VectorXd& a, Eigen::VectorXd b, Eigen::VectorXd values,
                           const Layout& l, bool map_after, std::vector<std::string>* warnings) {
  const double A1 = 1.0 + a.sum(), B1 = b.sum();
  const double g = B1 / A1;
  if (std::isfinite(g) && std::abs(g) > 1e-12) {
    b /= g;
    // Hammerstein: f -> g f; Wiener: x -> x / g, f kept (its knots move) -
    // the Wiener start re-fits f on the scaled x instead.
    if (!map_after) values *= g;
  } else {
    warnings->push_back(
        fmt::format("the initial linear part has static gain {:.3g}: not normalised to 1", g));
  }
  Eigen::VectorXd theta(l.size());
  theta.head(l.na) = a;
  theta.segment(l.na, l.nb - 1) = b.head(l.nb - 1);
  theta.segment(l.map_offset(), l.m) = values;
  return theta;
}

// Least-squares values of a piecewise-linear map on the knots through (x, y).
Eigen::VectorXd FitMapValues(const std::vector<double>& knots, const Eigen::VectorXd& x,
                             const Eigen::VectorXd& y) {
  const auto m = static_cast<Eigen::Index>(knots.size());
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(x.size(), m);
  for (Eigen::Index t = 0; t < x.size(); ++t) {
    const Tent h = TentAt(knots, x[t]);
    H(t, h.j) += 1.0 - h.w;
    H(t, h.j + 1) += h.w;
  }
  return H.completeOrthogonalDecomposition().solve(y);
}

}  // namespace

bool BlockModelOptions::IsValid(std::string* error) const {
  auto fail = [error](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (na < 0 || nb < 1 || nk < 0)
    return fail(fmt::format(
        "BlockModelOptions: orders must be na >= 0, nb >= 1, nk >= 0, got na = {}, nb = {}, "
        "nk = {}",
        na, nb, nk));
  if (knots.empty() && num_knots != 0 && num_knots < 2)
    return fail(fmt::format("BlockModelOptions::num_knots must be 0 (automatic) or >= 2, got {}",
                            num_knots));
  if (!knots.empty()) {
    if (knots.size() < 2)
      return fail(
          fmt::format("BlockModelOptions::knots needs at least 2 knots, got {}", knots.size()));
    for (std::size_t i = 0; i < knots.size(); ++i) {
      if (!std::isfinite(knots[i]) || (i > 0 && knots[i] <= knots[i - 1]))
        return fail(fmt::format(
            "BlockModelOptions::knots must be finite and strictly increasing, got knot {} = {} "
            "after {}",
            i, knots[i], i > 0 ? knots[i - 1] : knots[i]));
    }
  }
  if (max_iterations < 1)
    return fail(
        fmt::format("BlockModelOptions::max_iterations must be >= 1, got {}", max_iterations));
  if (!(function_tolerance > 0.0 && gradient_tolerance > 0.0 && parameter_tolerance > 0.0))
    return fail("BlockModelOptions: the tolerances must be positive");
  return true;
}

BlockModelResult EstimateHammerstein(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double Ts,
                                     const BlockModelOptions& o) {
  CheckSignals(u, y, Ts, o, "Hammerstein");
  EstimationSummary s;
  const std::vector<double> knots = Knots(u, o, &s.warnings);
  const Layout l{o.na, o.nb, o.nk, static_cast<int>(knots.size())};
  CheckParameterCount(u.size(), l, "Hammerstein");
  std::vector<Tent> tents(static_cast<std::size_t>(u.size()));
  for (Eigen::Index t = 0; t < u.size(); ++t)
    tents[static_cast<std::size_t>(t)] = TentAt(knots, u[t]);

  // 1. Bai's over-parameterised least squares.
  const int n0 = std::max(l.na, l.nk + l.nb - 1);
  const Eigen::Index rows = u.size() - n0;
  const int mm = l.m - 1;  // basis functions 2..m
  Eigen::MatrixXd phi = Eigen::MatrixXd::Zero(rows, l.na + 1 + l.nb * mm);
  Eigen::VectorXd target = y.tail(rows);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const Eigen::Index t = r + n0;
    for (int i = 1; i <= l.na; ++i) phi(r, i - 1) = -y[t - i];
    phi(r, l.na) = 1.0;
    for (int k = 0; k < l.nb; ++k) {
      const Tent& h = tents[static_cast<std::size_t>(t - l.nk - k)];
      const int col = l.na + 1 + k * mm;
      if (h.j >= 1) phi(r, col + h.j - 1) += 1.0 - h.w;
      phi(r, col + h.j) += h.w;  // basis j + 1 >= 2 always
    }
  }
  const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(phi);
  if (cod.rank() < phi.cols())
    s.warnings.push_back(
        fmt::format("the over-parameterised regressors have rank {} of {}: minimum-norm start",
                    cod.rank(), phi.cols()));
  const Eigen::VectorXd sol = cod.solve(target);
  Eigen::MatrixXd Theta(l.nb, mm);
  for (int k = 0; k < l.nb; ++k) Theta.row(k) = sol.segment(l.na + 1 + k * mm, mm).transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Theta, Eigen::ComputeThinU | Eigen::ComputeThinV);
  Eigen::VectorXd b = svd.singularValues()[0] * svd.matrixU().col(0);
  const Eigen::VectorXd d = svd.matrixV().col(0);
  const double B1 = b.sum();
  Eigen::VectorXd alpha(l.m);
  alpha[0] = std::abs(B1) > 1e-12 ? sol[l.na] / B1 : 0.0;
  alpha.tail(mm) = (alpha[0] + d.array()).matrix();
  Eigen::VectorXd theta = Normalised(sol.head(l.na), b, alpha, l, /*map_after=*/false, &s.warnings);

  // Monotone map: the start made monotone (PAVA) in the direction of its
  // trend, then parameterised by squared increments (kept off 0, where their
  // derivative would vanish).
  double monotone = 0.0;
  if (o.monotone_map) {
    Eigen::Ref<Eigen::VectorXd> a = theta.segment(l.map_offset(), l.m);
    monotone = a[l.m - 1] >= a[0] ? 1.0 : -1.0;
    const std::vector<double> pooled =
        PoolAdjacentViolators(std::vector<double>(a.data(), a.data() + l.m),
                              std::vector<double>(l.m, 1.0), monotone > 0.0);
    const double floor =
        1e-3 * std::sqrt(std::max(std::abs(pooled.back() - pooled.front()), 1e-12));
    for (int j = l.m - 1; j >= 1; --j)
      a[j] = std::max(std::sqrt(std::abs(pooled[j] - pooled[j - 1])), floor);
    a[0] = pooled[0];
  }

  // 2. Output-error refinement.
  RefineOutputError(
      std::make_unique<HammersteinError>(HammersteinError{l, &y, std::move(tents), monotone, y[0]}),
      u.size(), o, &theta, &s);
  if (monotone != 0.0) {
    Eigen::Ref<Eigen::VectorXd> a = theta.segment(l.map_offset(), l.m);
    for (int j = 1; j < l.m; ++j) a[j] = a[j - 1] + monotone * a[j] * a[j];
  }
  s.num_rows = u.size();
  return Finish(theta, l, Ts, MapOf(knots, theta, l.map_offset()), std::move(s));
}

namespace {

// One Wiener fit (EstimateWiener) from the linear part `arx`: that ARX scaled
// to unit gain, x simulated from rest at u(0); the knots of f over the range
// of x (where the output map is evaluated), f fitted on x; then the joint
// output-error refinement. `s` receives the summary, the result's loss the
// mean squared simulation error it ended with.
BlockModelResult WienerFrom(const ArxResult& arx, const Eigen::VectorXd& u,
                            const Eigen::VectorXd& y, double Ts, const BlockModelOptions& o) {
  EstimationSummary s;
  const Eigen::VectorXd a = arx.model.a.tail(o.na);
  const Eigen::VectorXd b = arx.model.b[0].segment(o.nk, o.nb);
  const Layout l0{o.na, o.nb, o.nk, 0};
  Eigen::VectorXd theta = Normalised(a, b, Eigen::VectorXd(), l0, true, &s.warnings);
  const std::vector<double> v(u.data(), u.data() + u.size());
  std::vector<double> x;
  SimulateUnitGain(theta.data(), l0, v, &x);
  const Eigen::VectorXd xv = Eigen::Map<const Eigen::VectorXd>(x.data(), u.size());
  const bool x_finite = xv.allFinite() && xv.maxCoeff() > xv.minCoeff();
  if (!x_finite)
    s.warnings.push_back(
        "the initial linear part gives no usable x (unstable or constant): output-map knots "
        "placed over the input range");
  // With G(1) = 1 the settled values of x are the input levels: the knots
  // where the input dwells (PlaceMapKnots of u), widened to the range of x
  // where its transients leave them; knots no sample of x reaches are dropped.
  BlockModelOptions ko = o;
  if (ko.knots.empty()) {
    ko.knots = PlaceMapKnots(u, o.num_knots);
    if (x_finite) {
      const double margin = 0.01 * (ko.knots.back() - ko.knots.front());
      if (xv.minCoeff() < ko.knots.front() - margin)
        ko.knots.insert(ko.knots.begin(), xv.minCoeff());
      if (xv.maxCoeff() > ko.knots.back() + margin) ko.knots.push_back(xv.maxCoeff());
    }
  }
  const std::vector<double> knots = Knots(x_finite ? xv : u, ko, &s.warnings, "x");
  const Layout l{o.na, o.nb, o.nk, static_cast<int>(knots.size())};
  CheckParameterCount(u.size(), l, "Wiener");
  theta.conservativeResize(l.size());
  theta.segment(l.map_offset(), l.m) =
      x_finite ? FitMapValues(knots, xv, y) : FitMapValues(knots, u, y);
  RefineOutputError(std::make_unique<WienerError>(WienerError{l, &y, &u, knots}), u.size(), o,
                    &theta, &s);
  s.num_rows = u.size();
  StaticMap f = MapOf(knots, theta, l.map_offset());
  if (o.knots.empty()) {  // placed here, not given
    std::vector<double> final_x;
    SimulateUnitGainFrom(theta.data(), l, v, &final_x, f.NearestPreimageOrEnd(y[0], v[0]));
    f = TrimToRange(f, final_x);
  }
  return Finish(theta, l, Ts, std::move(f), std::move(s));
}

}  // namespace

BlockModelResult EstimateWiener(const Eigen::VectorXd& u, const Eigen::VectorXd& y, double Ts,
                                const BlockModelOptions& o) {
  CheckSignals(u, y, Ts, o, "Wiener");
  // Two starts, the lower simulation error kept: the ARX of the raw record,
  // and the ARX about the means. Without an intercept an output level (y =
  // 10 + 2 x) goes into a pole and a zero at z = 1, x loses the input's
  // levels, and the raw start validated at 87 % (offset 10) or -91 % (offset
  // 100) where the same record without the offset gave 97 %; on the IPA
  // twin's staircases the raw start ends lower.
  ArxOptions ao;
  ao.na = o.na;
  ao.nb = {o.nb};
  ao.nk = {o.nk};
  BlockModelResult best = WienerFrom(EstimateArx(y, u, Ts, ao), u, y, Ts, o);
  BlockModelResult centred = WienerFrom(
      EstimateArx((y.array() - y.mean()).matrix(), (u.array() - u.mean()).matrix(), Ts, ao), u, y,
      Ts, o);
  const auto loss = [](const BlockModelResult& r) {
    return std::isfinite(r.summary.loss) ? r.summary.loss : std::numeric_limits<double>::infinity();
  };
  if (loss(centred) < loss(best)) best = std::move(centred);
  return best;
}

BlockModelResult EstimateHammersteinWiener(const Eigen::VectorXd& u, const Eigen::VectorXd& y,
                                           double Ts, const BlockModelOptions& o) {
  CheckSignals(u, y, Ts, o, "Hammerstein-Wiener", /*two_maps=*/true);
  // Start: the Hammerstein model (f_H, G), its map moved to the input units.
  BlockModelOptions ho = o;
  ho.monotone_map = false;
  const BlockModelResult h = EstimateHammerstein(u, y, Ts, ho);
  EstimationSummary s;
  s.warnings = h.summary.warnings;
  const std::vector<double>& in_knots = h.map.u();
  const auto m = static_cast<int>(in_knots.size());
  const double f1 = h.map.y().front(), fm = h.map.y().back();
  const double c1 = in_knots.front(), cm = in_knots.back();
  PNEUMID_CHECK(std::abs(fm - f1) > 1e-12 * std::max(std::abs(f1), std::abs(fm)),
                "Hammerstein-Wiener: the initial input map has the same value {:g} at both end "
                "knots u = {:g} and u = {:g}; the normalisation f(c_1) = c_1, f(c_m) = c_m needs "
                "an input map that changes over the input range",
                f1, c1, cm);
  const double scale = (cm - c1) / (fm - f1);
  std::vector<double> f(m);
  for (int j = 0; j < m; ++j) f[j] = c1 + scale * (h.map.y()[j] - f1);
  f.front() = c1;
  f.back() = cm;

  // x = G f(u); the output map's knots over its range, values fitted on (x, y).
  const Layout l{o.na, o.nb, o.nk, 2 * m - 2};
  Eigen::VectorXd theta(l.size());
  theta.head(l.na) = h.linear.a.tail(l.na);
  theta.segment(l.na, l.nb - 1) = h.linear.b[0].segment(l.nk, l.nb - 1);
  for (int j = 1; j + 1 < m; ++j) theta[l.map_offset() + j - 1] = f[j];
  std::vector<Tent> tents(static_cast<std::size_t>(u.size()));
  for (Eigen::Index t = 0; t < u.size(); ++t)
    tents[static_cast<std::size_t>(t)] = TentAt(in_knots, u[t]);
  std::vector<double> x;
  SimulateUnitGain(theta.data(), l, MapThroughTents(f.data(), tents), &x);
  const Eigen::VectorXd xv = Eigen::Map<const Eigen::VectorXd>(x.data(), u.size());
  BlockModelOptions go = o;
  go.knots.clear();
  go.num_knots = m;
  const std::vector<double> out_knots = Knots(xv, go, &s.warnings, "x");
  theta.conservativeResize(l.na + l.nb - 1 + (m - 2) + static_cast<Eigen::Index>(out_knots.size()));
  theta.tail(static_cast<Eigen::Index>(out_knots.size())) = FitMapValues(out_knots, xv, y);
  const Layout lj{o.na, o.nb, o.nk, m - 2 + static_cast<int>(out_knots.size())};

  // Joint output-error refinement of G and both maps.
  RefineOutputError(std::make_unique<HwError>(HwError{lj, &y, tents, in_knots, out_knots}),
                    u.size(), o, &theta, &s);
  s.num_rows = u.size();
  Eigen::VectorXd fv(m);
  fv << c1, theta.segment(lj.map_offset(), m - 2), cm;
  BlockModelResult r = Finish(theta, lj, Ts, MapOf(in_knots, fv, 0), std::move(s));
  std::vector<double> final_x;
  const std::vector<double> final_v = MapThroughTents(fv.data(), tents);
  const StaticMap output_map = MapOf(out_knots, theta, lj.map_offset() + m - 2);
  SimulateUnitGainFrom(theta.data(), lj, final_v, &final_x,
                       output_map.NearestPreimageOrEnd(y[0], final_v[0]));
  r.output_map = TrimToRange(output_map, final_x);
  return r;
}

namespace {

TransferFunction CheckDiscrete(const TransferFunction& g) {
  PNEUMID_CHECK(g.IsDiscrete(), "the linear part of a block-oriented model must be discrete");
  return g;
}

}  // namespace

Eigen::VectorXd SimulateHammerstein(const StaticMap& f, const TransferFunction& g,
                                    const Eigen::VectorXd& u) {
  CheckDiscrete(g);
  if (u.size() == 0) return {};
  const Eigen::VectorXd v = f.Evaluate(u);
  const double v0 = v[0];
  return (Lsim(g, (v.array() - v0).matrix(), g.Ts()).array() + g.DcGain() * v0).matrix();
}

Eigen::VectorXd SimulateWiener(const TransferFunction& g, const StaticMap& f,
                               const Eigen::VectorXd& u) {
  CheckDiscrete(g);
  if (u.size() == 0) return {};
  const double u0 = u[0];
  const Eigen::VectorXd x =
      (Lsim(g, (u.array() - u0).matrix(), g.Ts()).array() + g.DcGain() * u0).matrix();
  return f.Evaluate(x);
}

}  // namespace pneumid
