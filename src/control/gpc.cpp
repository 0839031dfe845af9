#include "pneumid/control/gpc.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Cholesky>

#include "pneumid/common/check.hpp"

namespace pneumid {

namespace {

// Product of polynomials in ascending powers of q^-1.
Eigen::VectorXd Conv(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  Eigen::VectorXd c = Eigen::VectorXd::Zero(a.size() + b.size() - 1);
  for (Eigen::Index i = 0; i < a.size(); ++i) c.segment(i, b.size()) += a(i) * b;
  return c;
}

Eigen::VectorXd Padded(const Eigen::VectorXd& a, Eigen::Index n) {
  Eigen::VectorXd p = Eigen::VectorXd::Zero(std::max(n, a.size()));
  p.head(a.size()) = a;
  return p;
}

Eigen::VectorXd TrimTrailingZeros(const Eigen::VectorXd& a) {
  Eigen::Index n = a.size();
  const double scale = a.cwiseAbs().maxCoeff();
  while (n > 1 && std::abs(a(n - 1)) <= 1e-14 * scale) --n;
  return a.head(n);
}

}  // namespace

CarimaModel ToCarima(const TransferFunction& model, double Ts) {
  return ToCarima(PredictionModel(model, Ts));
}

CarimaModel ToCarima(const PredictionModel& model) {
  const TransferFunction& g = model.sampled();
  const double a0 = g.den()(0);
  PNEUMID_CHECK(a0 != 0.0, "the model's leading denominator coefficient is zero");
  const int d = g.DelaySamples();
  Eigen::VectorXd bbar = Eigen::VectorXd::Zero(d + g.num().size());
  bbar.tail(g.num().size()) = g.num() / a0;
  const double bmax = bbar.cwiseAbs().maxCoeff();
  PNEUMID_CHECK(bmax > 0.0, "the model has a zero numerator");
  PNEUMID_CHECK(std::abs(bbar(0)) <= 1e-12 * bmax,
                "GPC needs a strictly proper model (no direct feedthrough); b0 = {}", bbar(0));
  CarimaModel c;
  c.Ts = model.Ts();
  c.A = TrimTrailingZeros(g.den() / a0);
  c.B = TrimTrailingZeros(bbar.tail(bbar.size() - 1));
  return c;
}

bool GpcOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (N1 < 1 || N2 < N1)
    return fail(fmt::format("need 1 <= N1 <= N2, got N1 = {}, N2 = {}", N1, N2));
  if (Nu < 1 || Nu > N2) return fail(fmt::format("need 1 <= Nu <= N2, got Nu = {}", Nu));
  if (N2 > kMaxPredictionHorizon || Nu > kMaxControlHorizon)
    return fail(fmt::format(
        "horizons N2 = {} and Nu = {} exceed the largest ones taken, N2 = {} and Nu = {} (a "
        "sample time much shorter than the plant's time scale: choose a longer one)",
        N2, Nu, kMaxPredictionHorizon, kMaxControlHorizon));
  if (!(lambda >= 0.0) || !std::isfinite(lambda))
    return fail(fmt::format("lambda must be finite and >= 0, got {}", lambda));
  if (!t_equals_a && t_polynomial.size() > 0 &&
      (!t_polynomial.allFinite() || std::abs(t_polynomial(0) - 1.0) > 1e-12))
    return fail("the T polynomial must be monic (t0 = 1) with finite coefficients");
  std::string e;
  if (!limits.IsValid(&e)) return fail(e);
  return true;
}

GpcController::GpcController(const TransferFunction& model, double Ts, const GpcOptions& options)
    : GpcController(PredictionModel(model, Ts), options) {}

GpcController::GpcController(const PredictionModel& model, const GpcOptions& options)
    : options_(options), Ts_(model.Ts()) {
  std::string error;
  PNEUMID_CHECK(options_.IsValid(&error), "invalid GPC options: {}", error);
  model_ = ToCarima(model);
  const Eigen::VectorXd& A = model_.A;
  const Eigen::VectorXd& B = model_.B;
  if (options_.t_equals_a) {
    T_ = A;
  } else if (options_.t_polynomial.size() > 0) {
    T_ = TrimTrailingZeros(options_.t_polynomial);
  } else {
    T_ = Eigen::VectorXd::Ones(1);
  }
  if (T_.size() > 1) {
    const Eigen::VectorXcd roots = poly::Roots(T_);
    PNEUMID_CHECK(roots.size() == 0 || roots.cwiseAbs().maxCoeff() < 1.0,
                  "the T polynomial must have its roots inside the unit circle (max |root| = {})",
                  roots.cwiseAbs().maxCoeff());
  }
  const int N1 = options_.N1, N2 = options_.N2, Nu = options_.Nu;
  const int rows = N2 - N1 + 1;
  Eigen::VectorXd delta(2);
  delta << 1.0, -1.0;
  const Eigen::VectorXd At = Conv(A, delta);  // Delta A
  const Eigen::Index nF = std::max(At.size(), T_.size()) - 1;
  const Eigen::Index nT = T_.size();

  // Diophantine recursion [1, eqs. 7-8].
  Eigen::VectorXd E = Eigen::VectorXd::Ones(1);
  Eigen::VectorXd F = (Padded(T_, nF + 1) - Padded(At, nF + 1)).tail(nF);
  std::vector<Eigen::VectorXd> Fs, Gammas;
  Eigen::VectorXd gprime;  // step response g_0..g_{N2-1}
  for (int j = 1; j <= N2; ++j) {
    if (j >= N1) {
      // Second identity: E_j B = G'_j T + q^-j Gamma_j.
      const Eigen::VectorXd Gj = Conv(E, B);
      Eigen::VectorXd gp = Eigen::VectorXd::Zero(j);
      for (int i = 0; i < j; ++i) {
        double v = i < Gj.size() ? Gj(i) : 0.0;
        for (int l = 1; l <= i && l < nT; ++l) v -= T_(l) * gp(i - l);
        gp(i) = v;
      }
      const Eigen::VectorXd GpT = Conv(gp, T_);
      const Eigen::Index len = std::max(Gj.size(), GpT.size());
      const Eigen::VectorXd rest = Padded(Gj, len) - Padded(GpT, len);
      Gammas.push_back(rest.tail(len - j));
      Fs.push_back(F);
      if (j == N2) gprime = gp;
    }
    const double f0 = F(0);
    E.conservativeResize(j + 1);
    E(j) = f0;
    const Eigen::VectorXd next = Padded(F, nF + 1) - f0 * Padded(At, nF + 1);
    F = next.tail(nF);
  }
  Eigen::Index nGamma = 1;
  for (const auto& g : Gammas) nGamma = std::max(nGamma, g.size());
  F_.setZero(rows, std::max<Eigen::Index>(nF, 1));
  Gamma_.setZero(rows, nGamma);
  G_.setZero(rows, Nu);
  for (int r = 0; r < rows; ++r) {
    const int j = N1 + r;
    F_.row(r).head(Fs[r].size()) = Fs[r].transpose();
    Gamma_.row(r).head(Gammas[r].size()) = Gammas[r].transpose();
    for (int c = 0; c < Nu && c <= j - 1; ++c) G_(r, c) = gprime(j - 1 - c);
  }
  Eigen::MatrixXd H = G_.transpose() * G_;
  H.diagonal().array() += options_.lambda;
  Eigen::LLT<Eigen::MatrixXd> llt(H);
  PNEUMID_CHECK(llt.info() == Eigen::Success && llt.matrixLLT().diagonal().minCoeff() >
                                                    1e-10 * std::sqrt(H.diagonal().maxCoeff()),
                "G'G + lambda I is singular (dead time beyond the horizon?); increase lambda (now "
                "{}) or N2 (now {})",
                options_.lambda, N2);
  gain_ = llt.solve(G_.transpose()).row(0);
  gain_sum_ = gain_.sum();
  yf_hist_.setZero(std::max<Eigen::Index>(F_.cols(), nT));
  duf_hist_.setZero(std::max<Eigen::Index>(Gamma_.cols(), nT));
  free_.setZero(rows);
  Reset();
}

void GpcController::DoReset(double u0, double y0) {
  yf_hist_.setConstant(y0 / T_.sum());
  duf_hist_.setZero();
  free_.setConstant(y0);
  u_prev_ = u0;
  last_du_ = 0.0;
}

double GpcController::DoUpdate(double setpoint, double measurement) {
  const Eigen::Index nT = T_.size();
  // y_f(t) = y(t) - sum_i t_i y_f(t-i).
  std::copy_backward(yf_hist_.data(), yf_hist_.data() + yf_hist_.size() - 1,
                     yf_hist_.data() + yf_hist_.size());
  double yf = measurement;
  for (Eigen::Index i = 1; i < nT; ++i) yf -= T_(i) * yf_hist_(i);
  yf_hist_(0) = yf;
  free_.noalias() = F_ * yf_hist_.head(F_.cols());
  free_.noalias() += Gamma_ * duf_hist_.head(Gamma_.cols());
  double du = gain_sum_ * setpoint - gain_.dot(free_);
  if (!std::isfinite(du)) return du;  // an overflow: a fault (Controller::Update)
  const double u = options_.limits.Clip(u_prev_ + du, u_prev_);
  du = u - u_prev_;
  // Delta u_f(t) = Delta u(t) - sum_i t_i Delta u_f(t-i), for the next step.
  std::copy_backward(duf_hist_.data(), duf_hist_.data() + duf_hist_.size() - 1,
                     duf_hist_.data() + duf_hist_.size());
  double duf = du;
  for (Eigen::Index i = 1; i < nT; ++i) duf -= T_(i) * duf_hist_(i);
  duf_hist_(0) = duf;
  u_prev_ = u;
  last_du_ = du;
  return u;
}

void GpcController::DoApplied(double u) {
  const double delta = u - u_prev_;
  if (delta == 0.0 || !std::isfinite(delta)) return;
  // Delta u_f(t) is linear in Delta u(t): the correction adds delta to it.
  duf_hist_(0) += delta;
  u_prev_ = u;
  last_du_ += delta;
}

std::string GpcController::Describe() const {
  return fmt::format("gpc N1={} N2={} Nu={} lambda={:g} T={}", options_.N1, options_.N2,
                     options_.Nu, options_.lambda,
                     options_.t_equals_a ? "A" : (T_.size() > 1 ? "custom" : "1"));
}

}  // namespace pneumid
