#include "pneumid/lti/frequency.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <vector>

#include "pneumid/common/check.hpp"

namespace pneumid {

namespace {

using Eigen::VectorXd;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kRadToDeg = 180.0 / M_PI;

// Magnitude and continuous phase (radians) of the model at w: the phase is the
// sum of the angles of the gain and of each factor (x - zero) / (x - pole), so
// it needs no unwrapping except where a root lies on the imaginary axis / unit
// circle; the delay adds -w delay exactly.
struct Factored {
  std::complex<double> gain;
  std::vector<std::complex<double>> zeros, poles;
  double Ts = 0.0, delay = 0.0;

  explicit Factored(const TransferFunction& g) : Ts(g.Ts()), delay(g.delay()) {
    const VectorXd n = poly::TrimLeading(g.num()), d = poly::TrimLeading(g.den());
    gain = n[0] / d[0];
    const Eigen::VectorXcd z = g.Zeros(), p = g.Poles();
    zeros.assign(z.data(), z.data() + z.size());
    poles.assign(p.data(), p.data() + p.size());
  }

  std::complex<double> Point(double w) const {
    const std::complex<double> j(0.0, 1.0);
    return Ts > 0 ? std::exp(j * w * Ts) : j * w;
  }

  void Eval(double w, double* mag, double* phase) const {
    const std::complex<double> x = Point(w);
    double m = std::abs(gain), ph = std::arg(gain);
    for (const auto& z : zeros) {
      m *= std::abs(x - z);
      ph += std::arg(x - z);
    }
    for (const auto& p : poles) {
      m /= std::abs(x - p);
      ph -= std::arg(x - p);
    }
    if (gain == 0.0) m = 0.0;
    *mag = m;
    *phase = ph - w * delay;
  }
};

// Frequencies (rad/s) of the poles and zeros, discrete ones mapped by s = ln(z)/Ts.
void RootRange(const TransferFunction& g, double* lo, double* hi) {
  std::vector<double> f;
  auto add = [&](std::complex<double> r) {
    if (g.IsDiscrete()) {
      if (std::abs(r) == 0.0) return;
      r = std::log(r) / g.Ts();
    }
    if (std::abs(r) > 1e-12) f.push_back(std::abs(r));
  };
  const Eigen::VectorXcd z = g.Zeros(), p = g.Poles();
  for (Eigen::Index i = 0; i < z.size(); ++i) add(z[i]);
  for (Eigen::Index i = 0; i < p.size(); ++i) add(p[i]);
  if (g.delay() > 0) f.push_back(1.0 / g.delay());
  if (f.empty()) f.push_back(1.0);
  *lo = *std::min_element(f.begin(), f.end());
  *hi = *std::max_element(f.begin(), f.end());
}

double Nyquist(const TransferFunction& g) { return M_PI / g.Ts(); }

VectorXd AutoGrid(const TransferFunction& g, double decades_margin, int per_decade) {
  double lo = 1.0, hi = 1.0;
  RootRange(g, &lo, &hi);
  double a = std::floor(std::log10(lo)) - decades_margin;
  double b = std::ceil(std::log10(hi)) + decades_margin;
  if (g.IsDiscrete()) {
    b = std::log10(Nyquist(g));
    a = std::min(a, b - 2.0);
  }
  const int n = std::max(50, static_cast<int>(std::ceil((b - a) * per_decade)) + 1);
  return LogSpace(a, b, n);
}

}  // namespace

Eigen::VectorXd LogSpace(double lo, double hi, int n) {
  PNEUMID_CHECK(std::isfinite(lo) && std::isfinite(hi) && lo <= hi,
                "LogSpace: need finite exponents lo <= hi, got lo = {}, hi = {}", lo, hi);
  PNEUMID_CHECK(n >= 1, "LogSpace: need n >= 1 points, got {}", n);
  if (n == 1) return VectorXd::Constant(1, std::pow(10.0, lo));
  VectorXd w(n);
  for (int i = 0; i < n; ++i) w[i] = std::pow(10.0, lo + (hi - lo) * i / (n - 1));
  return w;
}

BodeData Bode(const TransferFunction& g, const Eigen::VectorXd& omega_in) {
  const VectorXd omega = omega_in.size() > 0 ? omega_in : AutoGrid(g, 1.0, 50);
  for (Eigen::Index i = 0; i < omega.size(); ++i) {
    PNEUMID_CHECK(std::isfinite(omega[i]) && omega[i] >= 0.0,
                  "bode: frequencies must be finite and >= 0 rad/s, got omega[{}] = {}", i,
                  omega[i]);
    PNEUMID_CHECK(!g.IsDiscrete() || omega[i] <= Nyquist(g) * (1 + 1e-12),
                  "bode: omega[{}] = {} rad/s exceeds the Nyquist frequency pi/Ts = {} rad/s", i,
                  omega[i], Nyquist(g));
  }
  const Factored f(g);
  BodeData b;
  b.omega = omega;
  b.magnitude.resize(omega.size());
  b.magnitude_db.resize(omega.size());
  b.phase_deg.resize(omega.size());
  // The rational part's phase is unwrapped along a fine grid between the
  // requested frequencies (at least 200 per decade; a discrete factor's
  // angle can cross the branch cut, a root on the axis jumps), so that a
  // coarse grid (bode --points 5) gets the same continuous phase as a fine
  // one; the delay's -w delay is exact and added afterwards.
  double previous = 0.0;  // rational phase (deg) at the last evaluated frequency
  double w_prev = -1.0;
  auto rational_deg = [&f](double x) {
    double mx = 0.0, px = 0.0;
    f.Eval(x, &mx, &px);
    return (px + x * f.delay) * kRadToDeg;
  };
  auto unwrap_to = [&previous](double deg) {
    while (deg - previous > 180.0) deg -= 360.0;
    while (deg - previous < -180.0) deg += 360.0;
    return deg;
  };
  for (Eigen::Index i = 0; i < omega.size(); ++i) {
    const double w = omega[i];
    if (w_prev >= 0.0) {
      const double lo = std::max(w_prev, 1e-300), hi = std::max(w, 1e-300);
      const int sub =
          std::min(20000, static_cast<int>(std::ceil(200.0 * std::abs(std::log10(hi / lo)))));
      for (int k = 1; k < sub; ++k)
        previous = unwrap_to(rational_deg(lo * std::pow(hi / lo, static_cast<double>(k) / sub)));
    }
    double m = 0.0, ph = 0.0;
    f.Eval(w, &m, &ph);
    const double at_w = (ph + w * f.delay) * kRadToDeg;
    const double rational = i == 0 ? at_w : unwrap_to(at_w);
    previous = rational;
    w_prev = w;
    b.magnitude[i] = m;
    b.magnitude_db[i] = 20.0 * std::log10(m);
    b.phase_deg[i] = rational - w * f.delay * kRadToDeg;
  }
  // Start in (-180, 180] at the first frequency.
  if (omega.size() > 0) {
    const double shift = 360.0 * std::round((b.phase_deg[0] - 1e-9) / 360.0);
    b.phase_deg.array() -= shift;
  }
  return b;
}

Margins ComputeMargins(const TransferFunction& g) {
  const Factored f(g);
  VectorXd w = AutoGrid(g, 3.0, 100);
  if (!g.IsDiscrete() && g.delay() > 0) {
    // A delay turns the phase without bound: extend the grid far enough for a
    // -180 degree crossing at high frequency.
    const double hi = std::log10(w[w.size() - 1]);
    const double need = std::log10(100.0 / g.delay());
    if (need > hi) {
      const VectorXd extra = LogSpace(hi, need, static_cast<int>((need - hi) * 100) + 2);
      VectorXd ww(w.size() + extra.size() - 1);
      ww << w, extra.tail(extra.size() - 1);
      w = ww;
    }
  }
  const Eigen::Index n = w.size();
  VectorXd mag(n), ph(n);
  for (Eigen::Index i = 0; i < n; ++i) f.Eval(w[i], &mag[i], &ph[i]);
  // Unwrap along the grid.
  for (Eigen::Index i = 1; i < n; ++i) {
    while (ph[i] - ph[i - 1] > M_PI) ph[i] -= 2 * M_PI;
    while (ph[i] - ph[i - 1] < -M_PI) ph[i] += 2 * M_PI;
  }
  auto eval = [&](double x, double* m, double* p) { f.Eval(x, m, p); };
  // Bisection in log frequency on a bracketed sign change of fn.
  auto refine = [&](double a, double b, auto fn) {
    double fa = fn(a);
    for (int it = 0; it < 100; ++it) {
      const double mid = std::sqrt(a * b);
      const double fm = fn(mid);
      if ((fm < 0) == (fa < 0)) {
        a = mid;
        fa = fm;
      } else {
        b = mid;
      }
      if (b / a - 1.0 < 1e-14) break;
    }
    return std::sqrt(a * b);
  };
  Margins out;
  out.gain_margin = kInf;
  out.gain_margin_db = kInf;
  out.phase_crossover = kNaN;
  out.phase_margin = kInf;
  out.gain_crossover = kNaN;
  // Gain crossovers: log|G| changes sign.
  for (Eigen::Index i = 1; i < n; ++i) {
    const double a = std::log(mag[i - 1]), b = std::log(mag[i]);
    if (!(std::isfinite(a) && std::isfinite(b)) || (a < 0) == (b < 0)) continue;
    const double wc = refine(w[i - 1], w[i], [&](double x) {
      double m, p;
      eval(x, &m, &p);
      return std::log(m);
    });
    double m, p;
    eval(wc, &m, &p);
    // Phase at wc on the unwrapped branch of the grid.
    const double branch = ph[i - 1] + std::remainder(p - ph[i - 1], 2 * M_PI);
    const double pm = std::remainder(branch + M_PI, 2 * M_PI) * kRadToDeg;
    if (std::abs(pm) < std::abs(out.phase_margin)) {
      out.phase_margin = pm;
      out.gain_crossover = wc;
    }
  }
  // Phase crossovers: phase + 180 deg = 0 mod 360.
  for (Eigen::Index i = 1; i < n; ++i) {
    const double k = std::floor((ph[i - 1] + M_PI) / (2 * M_PI));
    const double k2 = std::floor((ph[i] + M_PI) / (2 * M_PI));
    if (k == k2) continue;
    // Level crossed: -pi + 2 pi max(k, k2).
    const double level = -M_PI + 2 * M_PI * std::max(k, k2);
    const double base = ph[i - 1];
    const double wc = refine(w[i - 1], w[i], [&](double x) {
      double m, p;
      eval(x, &m, &p);
      const double cont = base + std::remainder(p - base, 2 * M_PI);
      return cont - level;
    });
    double m, p;
    eval(wc, &m, &p);
    const double gm = 1.0 / m;
    if (std::abs(std::log(gm)) < std::abs(std::log(out.gain_margin))) {
      out.gain_margin = gm;
      out.gain_margin_db = 20.0 * std::log10(gm);
      out.phase_crossover = wc;
    }
  }
  return out;
}

}  // namespace pneumid
