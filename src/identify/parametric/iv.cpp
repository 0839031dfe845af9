#include "pneumid/identify/parametric/iv.hpp"

#include <cmath>

#include <Eigen/Dense>

#include "../parametric_filter.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/identify/parametric/arx.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

bool IvOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (na < 0) return fail(fmt::format("na must be >= 0, got {}", na));
  if (nb < 1) return fail(fmt::format("nb must be >= 1, got {}", nb));
  if (nk < 0) return fail(fmt::format("nk must be >= 0, got {}", nk));
  return true;
}

Eigen::VectorXd ReflectUnstableRoots(const Eigen::VectorXd& monic) {
  PNEUMID_CHECK(monic.size() >= 1 && monic[0] == 1.0, "polynomial must be monic");
  if (monic.size() == 1) return monic;
  Eigen::VectorXcd r = poly::Roots(monic);
  bool changed = false;
  for (Eigen::Index i = 0; i < r.size(); ++i) {
    if (std::abs(r[i]) > 1.0) {
      r[i] = 1.0 / std::conj(r[i]);
      changed = true;
    }
  }
  if (!changed) return monic;
  Eigen::VectorXd p = poly::FromRoots(r);
  p /= p[0];
  return p;
}

namespace {

// Rows of the ARX-structure regressor from output-like signal x and input u.
Eigen::MatrixXd Regressors(const Eigen::VectorXd& x, const Eigen::VectorXd& u, const IvOptions& o,
                           Eigen::Index n0) {
  const Eigen::Index rows = x.size() - n0;
  Eigen::MatrixXd phi(rows, o.na + o.nb);
  for (int l = 1; l <= o.na; ++l) phi.col(l - 1) = -x.segment(n0 - l, rows);
  for (int j = 0; j < o.nb; ++j) phi.col(o.na + j) = u.segment(n0 - o.nk - j, rows);
  return phi;
}

PolynomialModel ToModel(const Eigen::VectorXd& theta, const IvOptions& o, double Ts) {
  PolynomialModel m;
  m.Ts = Ts;
  m.structure = "ARX";
  m.a = Eigen::VectorXd::Ones(o.na + 1);
  m.a.tail(o.na) = theta.head(o.na);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(o.nk + o.nb);
  b.tail(o.nb) = theta.tail(o.nb);
  m.b = {b};
  m.nk = {o.nk};
  return m;
}

struct IvSolution {
  Eigen::VectorXd theta;
  Eigen::MatrixXd cov;
  double loss = 0.0;
  double cond = 0.0;
  int dropped = 0;  ///< directions left out by the truncated SVD (0: full rank)
  bool ok = false;
};

// Smallest singular value, relative to the largest, of the column-scaled
// instrument matrix that SolveIv uses (about sqrt of double precision: a
// direction weaker than this is lost to rounding in the products zeta' phi).
constexpr double kIvRankTolerance = 1e-7;

// Solves the IV equations (zeta' phi) theta = zeta' y. Columns of zeta and phi
// are scaled to unit norm first so that the rank decision does not depend on
// the signals' units. When the scaled matrix has singular values below
// kIvRankTolerance times the largest (the instruments are nearly collinear:
// the model that generated them has a near-common factor of A and B, i.e. the
// orders exceed what the data determine), the equations are solved in the
// subspace they determine (truncated SVD: the minimum-norm solution in the
// scaled parameters, Söderström & Stoica 1983, Sec. 8.2) instead of through
// the near-null direction, whose amplification gives unstable models.
IvSolution SolveIv(const Eigen::MatrixXd& zeta, const Eigen::MatrixXd& phi,
                   const Eigen::VectorXd& y) {
  IvSolution s;
  const Eigen::VectorXd dz = zeta.colwise().norm().cwiseMax(1e-300).cwiseInverse();
  const Eigen::VectorXd dp = phi.colwise().norm().cwiseMax(1e-300).cwiseInverse();
  const Eigen::MatrixXd M = zeta.transpose() * phi;
  const Eigen::MatrixXd Ms = dz.asDiagonal() * M * dp.asDiagonal();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Ms, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd& sv = svd.singularValues();
  if (!(sv.size() > 0 && sv[0] > 0.0 && sv.allFinite())) return s;
  {
    Eigen::JacobiSVD<Eigen::MatrixXd> raw(M);
    const auto& r = raw.singularValues();
    s.cond = r[r.size() - 1] > 0 ? r[0] / r[r.size() - 1] : INFINITY;
  }
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(sv.size());
  for (Eigen::Index i = 0; i < sv.size(); ++i) {
    if (sv[i] > kIvRankTolerance * sv[0]) {
      inv[i] = 1.0 / sv[i];
    } else {
      ++s.dropped;
    }
  }
  // M^+ = Dp V S^+ U' Dz: the (truncated) inverse of M in the scaled coordinates.
  const Eigen::MatrixXd Mpinv = dp.asDiagonal() * svd.matrixV() * inv.asDiagonal() *
                                svd.matrixU().transpose() * dz.asDiagonal();
  s.theta = Mpinv * (zeta.transpose() * y);
  const Eigen::VectorXd e = y - phi * s.theta;
  s.loss = e.squaredNorm() / static_cast<double>(y.size());
  const double lambda = e.squaredNorm() / static_cast<double>(y.size() - phi.cols());
  s.cov = lambda * Mpinv * (zeta.transpose() * zeta) * Mpinv.transpose();
  s.ok = s.theta.allFinite() && s.dropped < sv.size();
  return s;
}

Eigen::VectorXd SimulateStable(const PolynomialModel& m, const Eigen::VectorXd& u) {
  PolynomialModel s = m;
  s.a = ReflectUnstableRoots(m.a);
  Eigen::MatrixXd um = u;
  return Simulate(s, um);
}

}  // namespace

IvResult EstimateIv4(const Eigen::VectorXd& y, const Eigen::VectorXd& u, double Ts,
                     const IvOptions& o) {
  std::string error;
  PNEUMID_CHECK(o.IsValid(&error), "invalid IV options: {}", error);
  PNEUMID_CHECK(Ts > 0.0, "sample time must be positive, got Ts = {}", Ts);
  PNEUMID_CHECK(y.size() == u.size(), "output and input lengths differ: {} vs {}", y.size(),
                u.size());
  PNEUMID_CHECK(y.allFinite() && u.allFinite(), "the data contain a non-finite value");
  IvResult result;
  EstimationSummary& sum = result.summary;
  const int d = o.na + o.nb;
  const Eigen::Index n0 = std::max(o.na, o.nk + o.nb - 1);
  const Eigen::Index nl = o.na + o.nb;  // order of the prefilter L
  sum.num_parameters = d;
  if (y.size() - n0 - nl <= 2 * d) {
    sum.termination = Termination::kFailure;
    sum.message = fmt::format("{} samples are too few for IV4 with {} parameters", y.size(), d);
    return result;
  }
  // Stage 1: least squares.
  ArxOptions ao;
  ao.na = o.na;
  ao.nb = {o.nb};
  ao.nk = {o.nk};
  Eigen::MatrixXd um = u;
  const ArxResult ls = EstimateArx(y, um, Ts, ao);
  if (!ls.summary.IsSolutionUsable()) {
    sum.termination = Termination::kFailure;
    sum.message = "initial least-squares estimate failed: " + ls.summary.message;
    return result;
  }
  const Eigen::VectorXd target = y.tail(y.size() - n0);
  const Eigen::MatrixXd phi = Regressors(y, u, o, n0);
  // Stage 2: IV with instruments from the LS model.
  Eigen::VectorXd x = SimulateStable(ls.model, u);
  IvSolution s2 = SolveIv(Regressors(x, u, o, n0), phi, target);
  if (!s2.ok) {
    sum.termination = Termination::kFailure;
    sum.message = "instrument matrix is singular (input not persistently exciting)";
    return result;
  }
  const PolynomialModel m2 = ToModel(s2.theta, o, Ts);
  // Stage 3: AR model of the equation error w = A2 y - B2 u.
  const Eigen::VectorXd one = Eigen::VectorXd::Ones(1);
  const Eigen::VectorXd w = internal::Filter(m2.a, one, y) - internal::Filter(m2.b[0], one, u);
  Eigen::VectorXd L = Eigen::VectorXd::Ones(nl + 1);
  if (nl > 0) {
    Eigen::MatrixXd wr(w.size() - nl, nl);
    for (Eigen::Index l = 1; l <= nl; ++l) wr.col(l - 1) = -w.segment(nl - l, w.size() - nl);
    L.tail(nl) = wr.colPivHouseholderQr().solve(w.tail(w.size() - nl));
    L = ReflectUnstableRoots(L);
  }
  // Stage 4: prefiltered IV with instruments from the stage-2 model.
  x = SimulateStable(m2, u);
  const Eigen::VectorXd yf = internal::Filter(L, one, y);
  const Eigen::VectorXd uf = internal::Filter(L, one, u);
  const Eigen::VectorXd xf = internal::Filter(L, one, x);
  const Eigen::Index n0f = n0 + nl;  // skip the filter's transient
  IvSolution s4 =
      SolveIv(Regressors(xf, uf, o, n0f), Regressors(yf, uf, o, n0f), yf.tail(yf.size() - n0f));
  if (!s4.ok) {
    result.model = m2;
    sum.termination = Termination::kFailure;
    sum.message = "prefiltered instrument matrix is singular; stage-2 IV estimate returned";
    return result;
  }
  result.model = ToModel(s4.theta, o, Ts);
  result.model.covariance = s4.cov;
  const Eigen::VectorXd eps = PredictionErrors(result.model, y, um);
  sum.num_rows = y.size() - n0;
  sum.loss = eps.tail(sum.num_rows).squaredNorm() / static_cast<double>(sum.num_rows);
  result.model.noise_variance =
      eps.tail(sum.num_rows).squaredNorm() / static_cast<double>(sum.num_rows - d);
  sum.initial_loss = ls.summary.loss;
  sum.condition_number = s4.cond;
  sum.scaled_condition_number = ls.summary.scaled_condition_number;
  sum.warnings = ls.summary.warnings;
  if (s4.dropped > 0)
    sum.warnings.push_back(fmt::format(
        "IV4: the instruments are nearly collinear ({} of {} directions below {} of the largest "
        "scaled singular value): the orders na = {}, nb = {} exceed what the data determine; the "
        "IV equations were solved in the subspace they determine (truncated SVD); lower orders "
        "may fit as well",
        s4.dropped, d, kIvRankTolerance, o.na, o.nb));
  sum.termination = Termination::kConvergence;
  sum.message = "four-stage instrumental variables";
  return result;
}

IvResult EstimateIv4(const Dataset& data, const IvOptions& options, int input, int output) {
  data.RequireUniform();
  data.RequireSamples(4 * (options.na + options.nb) + options.nk + 2, "IV4");
  return EstimateIv4(data.y(output), data.u(input), data.SampleTime(), options);
}

}  // namespace pneumid
