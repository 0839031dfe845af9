#include "pneumid/lti/interconnect.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include "pneumid/common/check.hpp"

namespace pneumid {

namespace {

using Eigen::VectorXd;

void CheckSameDomain(const char* what, const TransferFunction& a, const TransferFunction& b) {
  PNEUMID_CHECK(a.IsDiscrete() == b.IsDiscrete(),
                "{}: both models must be continuous or both discrete, got Ts = {} and Ts = {}",
                what, a.Ts(), b.Ts());
  PNEUMID_CHECK(!a.IsDiscrete() || std::abs(a.Ts() - b.Ts()) <= 1e-12 * a.Ts(),
                "{}: the sample times differ, Ts = {} and Ts = {}", what, a.Ts(), b.Ts());
}

// Sum of two polynomials of the model's convention: aligned at the constant
// term for descending powers of s, at the z^0 term for ascending powers of z^-1.
VectorXd Sum(const VectorXd& a, const VectorXd& b, bool discrete) {
  if (!discrete) return poly::Add(a, b);
  VectorXd c = VectorXd::Zero(std::max(a.size(), b.size()));
  c.head(a.size()) += a;
  c.head(b.size()) += b;
  return c;
}

// Discrete numerator with its z^-d delay absorbed (d leading zeros).
VectorXd AbsorbDelay(const TransferFunction& g) {
  if (!g.IsDiscrete() || g.DelaySamples() == 0) return g.num();
  VectorXd n = VectorXd::Zero(g.num().size() + g.DelaySamples());
  n.tail(g.num().size()) = g.num();
  return n;
}

}  // namespace

TransferFunction Series(const TransferFunction& g1, const TransferFunction& g2) {
  CheckSameDomain("series", g1, g2);
  return TransferFunction(poly::Multiply(g1.num(), g2.num()), poly::Multiply(g1.den(), g2.den()),
                          g1.Ts(), g1.delay() + g2.delay());
}

TransferFunction Parallel(const TransferFunction& g1, const TransferFunction& g2) {
  CheckSameDomain("parallel", g1, g2);
  const bool discrete = g1.IsDiscrete();
  if (discrete) {
    // Unequal discrete delays are rational: absorb them as powers of z^-1.
    const VectorXd n1 = AbsorbDelay(g1), n2 = AbsorbDelay(g2);
    return TransferFunction(Sum(poly::Multiply(n1, g2.den()), poly::Multiply(n2, g1.den()), true),
                            poly::Multiply(g1.den(), g2.den()), g1.Ts(), 0.0);
  }
  PNEUMID_CHECK(std::abs(g1.delay() - g2.delay()) <= 1e-12 * std::max(1.0, g1.delay()),
                "parallel: the delays differ ({} s and {} s); the sum is not a rational "
                "transfer function",
                g1.delay(), g2.delay());
  return TransferFunction(
      Sum(poly::Multiply(g1.num(), g2.den()), poly::Multiply(g2.num(), g1.den()), false),
      poly::Multiply(g1.den(), g2.den()), 0.0, g1.delay());
}

TransferFunction Feedback(const TransferFunction& g, const TransferFunction& h_in, int sign) {
  PNEUMID_CHECK(sign == 1 || sign == -1, "feedback: sign must be -1 (negative) or +1, got {}",
                sign);
  // The default h is the continuous unit gain; it fits a discrete g as well.
  const TransferFunction h =
      (g.IsDiscrete() && !h_in.IsDiscrete() && h_in.Order() == 0 && h_in.delay() == 0.0)
          ? TransferFunction(h_in.num(), h_in.den(), g.Ts())
          : h_in;
  CheckSameDomain("feedback", g, h);
  const bool discrete = g.IsDiscrete();
  PNEUMID_CHECK(discrete || (g.delay() == 0.0 && h.delay() == 0.0),
                "feedback: a continuous delay in the loop (g: {} s, h: {} s) gives a "
                "non-rational closed loop; use a Pade approximation or a discrete model",
                g.delay(), h.delay());
  const VectorXd ng = AbsorbDelay(g), nh = AbsorbDelay(h);
  // T = ng dh / (dg dh - sign ng nh)
  const VectorXd num = poly::Multiply(ng, h.den());
  const VectorXd den = Sum(poly::Multiply(g.den(), h.den()),
                           -static_cast<double>(sign) * poly::Multiply(ng, nh), discrete);
  const bool algebraic_loop =
      discrete ? den[0] == 0.0 : poly::TrimLeading(den).size() < poly::TrimLeading(num).size();
  PNEUMID_CHECK(!algebraic_loop && den.cwiseAbs().maxCoeff() > 0.0,
                "feedback: the loop is ill-posed (1 {} g h vanishes at high frequency)",
                sign < 0 ? "+" : "-");
  return TransferFunction(num, den, g.Ts(), 0.0);
}

TransferFunction MinimalRealization(const TransferFunction& g, double tol) {
  PNEUMID_CHECK(std::isfinite(tol) && tol >= 0.0, "minreal: tol must be >= 0, got {}", tol);
  const Eigen::VectorXcd zeros = g.Zeros(), poles = g.Poles();
  std::vector<std::complex<double>> z(zeros.data(), zeros.data() + zeros.size());
  std::vector<std::complex<double>> p(poles.data(), poles.data() + poles.size());
  if (z.empty() || p.empty()) return g;
  std::vector<bool> z_used(z.size(), false), p_used(p.size(), false);
  bool removed = false;
  for (std::size_t i = 0; i < z.size(); ++i) {
    std::size_t best = p.size();
    double best_d = 0.0;
    for (std::size_t j = 0; j < p.size(); ++j) {
      if (p_used[j]) continue;
      const double d = std::abs(z[i] - p[j]);
      if (d <= tol * std::max(1.0, std::abs(p[j])) && (best == p.size() || d < best_d)) {
        best = j;
        best_d = d;
      }
    }
    if (best < p.size()) {
      z_used[i] = p_used[best] = true;
      removed = true;
    }
  }
  if (!removed) return g;
  Eigen::VectorXcd zk(std::count(z_used.begin(), z_used.end(), false));
  Eigen::VectorXcd pk(std::count(p_used.begin(), p_used.end(), false));
  for (std::size_t i = 0, k = 0; i < z.size(); ++i) {
    if (!z_used[i]) zk[k++] = z[i];
  }
  for (std::size_t j = 0, k = 0; j < p.size(); ++j) {
    if (!p_used[j]) pk[k++] = p[j];
  }
  const VectorXd nt = poly::TrimLeading(g.num()), dt = poly::TrimLeading(g.den());
  const double gain = nt[0] / dt[0];
  const VectorXd num = gain * poly::FromRoots(zk);
  const VectorXd den = poly::FromRoots(pk);
  VectorXd padded = VectorXd::Zero(den.size());
  padded.tail(num.size()) = num;
  return TransferFunction(g.IsDiscrete() ? padded : num, den, g.Ts(), g.delay());
}

}  // namespace pneumid
