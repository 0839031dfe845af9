#include "pneumid/identify/step/half_rule.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/lti/conversion.hpp"

namespace pneumid {
namespace {

// Effective FOPDT delay by the half rule for sorted lags (without LHP zeros).
double FopdtDelay(const std::vector<double>& lags, double theta0) {
  double theta = theta0;
  for (std::size_t i = 1; i < lags.size(); ++i) theta += i == 1 ? 0.5 * lags[i] : lags[i];
  return theta;
}

}  // namespace

HalfRuleResult HalfRule(const TransferFunction& g_in, double h) {
  PNEUMID_CHECK(std::isfinite(h) && h >= 0.0, "half rule: sample time h must be >= 0 s, got {}", h);
  HalfRuleResult res;
  TransferFunction g = g_in;
  if (g.IsDiscrete()) {
    g = D2C(g_in, DiscretizationMethod::kZoh);
    res.notes.push_back("discrete model converted to continuous time (zoh d2c)");
  }
  PNEUMID_CHECK(g.IsStable(), "half rule: the model must be stable, poles of {}", g.ToString());
  const double K = g.DcGain();
  PNEUMID_CHECK(std::isfinite(K) && K != 0.0,
                "half rule: the model needs a finite non-zero static gain, got {}", K);

  std::vector<double> lags;  // denominator time constants
  std::vector<double> lhp;   // LHP zero time constants T0 > 0 in (T0 s + 1)
  double inverse = 0.0;      // sum of RHP zero time constants
  const Eigen::VectorXcd poles = g.Poles();
  for (Eigen::Index i = 0; i < poles.size(); ++i) {
    const auto p = poles[i];
    if (std::abs(p.imag()) <= 1e-9 * std::abs(p)) {
      lags.push_back(-1.0 / p.real());
    } else if (p.imag() > 0.0) {
      const double w = std::abs(p), zeta = -p.real() / w;
      lags.push_back(2.0 * zeta / w);
      res.notes.push_back(fmt::format(
          "complex pole pair w = {:.6g} rad/s, zeta = {:.4g} replaced by a lag of {:.6g} s", w,
          zeta, 2.0 * zeta / w));
    }
  }
  const Eigen::VectorXcd zeros = g.Zeros();
  for (Eigen::Index i = 0; i < zeros.size(); ++i) {
    const auto z = zeros[i];
    double T0 = 0.0;  // factor (T0 s + 1); T0 < 0 = inverse response
    if (std::abs(z.imag()) <= 1e-9 * std::abs(z)) {
      T0 = -1.0 / z.real();
    } else if (z.imag() > 0.0) {
      const double w = std::abs(z);
      T0 = -2.0 * z.real() / (w * w);
      res.notes.push_back(
          fmt::format("complex zero pair w = {:.6g} rad/s replaced by a factor "
                      "({:.6g} s + 1)",
                      w, T0));
    } else {
      continue;
    }
    if (T0 < 0.0) {
      inverse += -T0;
    } else if (T0 > 0.0) {
      lhp.push_back(T0);
    }
  }
  std::sort(lags.begin(), lags.end(), std::greater<double>());
  double gain = K;
  const double theta0 = g.delay() + inverse + 0.5 * h;
  // Left-half-plane zeros, largest first (Skogestad 2003, Eq. 11).
  std::sort(lhp.begin(), lhp.end(), std::greater<double>());
  for (double T0 : lhp) {
    const double theta = FopdtDelay(lags, theta0);
    auto larger = lags.end();
    for (auto it = lags.begin(); it != lags.end(); ++it) {
      if (*it >= T0) larger = it;  // lags are sorted: the last one >= T0 is the closest
    }
    if (larger != lags.end()) {
      const double tau0 = *larger;
      if (T0 >= 5.0 * theta) {
        gain *= T0 / tau0;
        lags.erase(larger);
        res.notes.push_back(
            fmt::format("zero ({:.6g} s + 1) / ({:.6g} s + 1) ~ {:.6g}", T0, tau0, T0 / tau0));
      } else {
        const double tt = std::min(tau0, 5.0 * theta);
        gain *= tt / tau0;
        *larger = tt - T0;
        res.notes.push_back(
            fmt::format("zero ({:.6g} s + 1) / ({:.6g} s + 1) ~ {:.6g} / ({:.6g} s "
                        "+ 1)",
                        T0, tau0, tt / tau0, tt - T0));
        if (*larger <= 0.0) lags.erase(larger);
      }
    } else if (!lags.empty()) {
      const double tau0 = lags.back();  // the largest lag below T0
      double factor = 1.0;
      if (tau0 >= theta) {
        factor = T0 / tau0;
      } else if (T0 >= theta) {
        factor = T0 / theta;
      }
      gain *= factor;
      lags.pop_back();
      res.notes.push_back(
          fmt::format("zero ({:.6g} s + 1) / ({:.6g} s + 1) ~ {:.6g}", T0, tau0, factor));
    } else {
      res.notes.push_back(fmt::format("zero ({:.6g} s + 1) without a lag to cancel: dropped", T0));
    }
    std::sort(lags.begin(), lags.end(), std::greater<double>());
  }
  PNEUMID_CHECK(!lags.empty(), "half rule: the model has no lag left to approximate ({})",
                g.ToString());
  auto lag = [&](std::size_t i) { return i < lags.size() ? lags[i] : 0.0; };
  res.fopdt.K = gain;
  res.fopdt.tau = lag(0) + 0.5 * lag(1);
  res.fopdt.theta = FopdtDelay(lags, theta0);
  res.sopdt.K = gain;
  res.sopdt.tau1 = lag(0);
  res.sopdt.tau2 = lag(1) + 0.5 * lag(2);
  double theta = theta0 + 0.5 * lag(2);
  for (std::size_t i = 3; i < lags.size(); ++i) theta += lags[i];
  res.sopdt.theta = theta;
  return res;
}

}  // namespace pneumid
