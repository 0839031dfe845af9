#include "pneumid/lti/response.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <vector>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/lti/conversion.hpp"

namespace pneumid {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr Eigen::Index kMaxDefaultSamples = 200000;
// Work of an automatic horizon, samples x (states + 1)^2 multiply-adds: about a
// second. A chosen horizon may take up to kMaxWork.
constexpr double kMaxDefaultWork = 2e9;
constexpr double kMaxWork = 1e11;

void CheckDiscreteStep(double Ts, double dt) {
  PNEUMID_CHECK(std::abs(dt - Ts) <= 1e-9 * Ts,
                "lsim: a discrete model runs at its own sample time Ts = {} s, got dt = {} s", Ts,
                dt);
}

// Runs x[k+1] = A x[k] + B u[k-d], y[k] = C x[k] + D u[k-d] for a SISO model.
// Plain loops over preallocated buffers: O(N nx^2), no allocation per sample.
// The loop of SimulateSiso for a compile-time order n (registers, unrolled):
// process models (order 1-4 with a fractional-delay state) run several times
// faster on long records than with run-time sizes.
template <int n>
VectorXd SimulateSisoFixed(const StateSpace& g, const VectorXd& u, int d, const VectorXd& x0) {
  const Eigen::Index N = u.size();
  VectorXd y(N);
  const Eigen::Matrix<double, n, n> A = g.A();
  const Eigen::Matrix<double, n, 1> b = g.B().col(0);
  const Eigen::Matrix<double, 1, n> c = g.C().row(0);
  const double dd = g.D()(0, 0);
  Eigen::Matrix<double, n, 1> x =
      x0.size() == n ? Eigen::Matrix<double, n, 1>(x0) : Eigen::Matrix<double, n, 1>::Zero();
  for (Eigen::Index k = 0; k < N; ++k) {
    const double uk = k >= d ? u[k - d] : 0.0;
    y[k] = dd * uk + c.dot(x);
    x = (A * x + b * uk).eval();
  }
  return y;
}

VectorXd SimulateSiso(const StateSpace& g, const VectorXd& u, int d, const VectorXd& x0) {
  const Eigen::Index n = g.num_states();
  switch (n) {
    case 1:
      return SimulateSisoFixed<1>(g, u, d, x0);
    case 2:
      return SimulateSisoFixed<2>(g, u, d, x0);
    case 3:
      return SimulateSisoFixed<3>(g, u, d, x0);
    case 4:
      return SimulateSisoFixed<4>(g, u, d, x0);
    case 5:
      return SimulateSisoFixed<5>(g, u, d, x0);
    default:
      break;
  }
  const Eigen::Index N = u.size();
  VectorXd y(N);
  // Row-major copy of A for cache-friendly row dot products.
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> A = g.A();
  const VectorXd b = g.B().col(0);
  const VectorXd c = g.C().row(0).transpose();
  const double dd = g.D()(0, 0);
  VectorXd x = x0.size() == n ? x0 : VectorXd::Zero(n);
  VectorXd xn(n);
  const double* Ap = A.data();
  for (Eigen::Index k = 0; k < N; ++k) {
    const double uk = k >= d ? u[k - d] : 0.0;
    double yk = dd * uk;
    for (Eigen::Index i = 0; i < n; ++i) yk += c[i] * x[i];
    y[k] = yk;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double* row = Ap + i * n;
      double acc = b[i] * uk;
      for (Eigen::Index j = 0; j < n; ++j) acc += row[j] * x[j];
      xn[i] = acc;
    }
    x.swap(xn);
  }
  return y;
}

// The model Lsim runs: a discrete model as it is (at its own Ts), a
// continuous one discretized by zoh at dt with its delay.
StateSpace DiscretizeForLsim(const StateSpace& g, double dt) {
  if (g.IsDiscrete()) {
    CheckDiscreteStep(g.Ts(), dt);
    return g;
  }
  return C2D(g, dt, DiscretizationMethod::kZoh);
}

// Time scales of a model in seconds: the slowest (1/|Re p|, largest) and the
// fastest (1/|p|, smallest), with discrete poles mapped by s = ln(z) / Ts.
void TimeScales(const TransferFunction& g, double* slow, double* fast) {
  const Eigen::VectorXcd poles = g.Poles();
  double s_max = 0.0, f_min = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < poles.size(); ++i) {
    std::complex<double> p = poles[i];
    if (g.IsDiscrete()) {
      if (std::abs(p) == 0.0) continue;
      p = std::log(p) / g.Ts();
    }
    const double re = std::abs(p.real());
    if (re > 1e-12 * std::max(1.0, std::abs(p))) s_max = std::max(s_max, 1.0 / re);
    if (std::abs(p) > 0.0) f_min = std::min(f_min, 1.0 / std::abs(p));
  }
  if (s_max == 0.0)
    s_max = std::isfinite(f_min) ? 10.0 * f_min : (g.IsDiscrete() ? 10 * g.Ts() : 1.0);
  if (!std::isfinite(f_min)) f_min = s_max;
  *slow = s_max;
  *fast = f_min;
}

void ChooseGrid(const TransferFunction& g, double* t_final, double* dt) {
  PNEUMID_CHECK(std::isfinite(*t_final) && *t_final >= 0.0,
                "time response: t_final must be >= 0 s (0 = automatic), got {}", *t_final);
  PNEUMID_CHECK(std::isfinite(*dt) && *dt >= 0.0,
                "time response: dt must be >= 0 s (0 = automatic), got {}", *dt);
  double slow = 1.0, fast = 1.0;
  const bool auto_horizon = *t_final == 0.0, auto_dt = *dt == 0.0;
  if (auto_horizon || auto_dt) TimeScales(g, &slow, &fast);
  if (auto_horizon) *t_final = 7.0 * slow + g.delay();
  // Samples an automatic choice may take: bounded in number and in work, so
  // that a high order or a pole near the stability limit cannot run for hours.
  const double states = std::max(1, g.Order()) + 1.0;
  const double max_auto_samples =
      std::min(static_cast<double>(kMaxDefaultSamples), kMaxDefaultWork / (states * states));
  if (auto_dt) {
    if (g.IsDiscrete()) {
      *dt = g.Ts();
    } else {
      *dt = std::min(slow / 200.0, fast / 20.0);
      if (*t_final / *dt > max_auto_samples) *dt = *t_final / max_auto_samples;
    }
  }
  if (g.IsDiscrete()) CheckDiscreteStep(g.Ts(), *dt);
  if (auto_horizon && *t_final / *dt > max_auto_samples) *t_final = *dt * max_auto_samples;
  PNEUMID_CHECK(*t_final / *dt < 1e8 && *t_final / *dt * states * states < kMaxWork,
                "time response: t_final / dt = {:.4g} samples of a model of order {} is too much "
                "work (t_final = {} s, dt = {} s); shorten t_final or lengthen dt",
                *t_final / *dt, g.Order(), *t_final, *dt);
}

Eigen::Index NumSamples(double t_final, double dt) {
  return static_cast<Eigen::Index>(std::ceil(t_final / dt - 1e-9)) + 1;
}

// A response of a finite input must be finite: NaN or Inf means the model
// could not be simulated at this step (ill-conditioned, or unstable and overflowing).
void CheckFinite(const TransferFunction& g, const TimeResponse& r, const char* what) {
  for (Eigen::Index k = 0; k < r.y.size(); ++k) {
    PNEUMID_CHECK(std::isfinite(r.y[k]),
                  "{} response: not finite ({}) from t = {} s on: the order-{} {} model is "
                  "{} at dt = {} s",
                  what, r.y[k], r.t[k], g.Order(), g.IsDiscrete() ? "discrete" : "continuous",
                  g.IsStable() ? "numerically ill-conditioned (try a lower order or a balanced "
                                 "form)"
                               : "unstable and its response overflows",
                  r.t.size() > 1 ? r.t[1] - r.t[0] : 0.0);
  }
}

}  // namespace

double FirstCrossing(const Eigen::VectorXd& t, const Eigen::VectorXd& x, double level,
                     Eigen::Index start, Eigen::Index* index) {
  PNEUMID_CHECK(t.size() == x.size(), "FirstCrossing: t has {} samples, x has {}", t.size(),
                x.size());
  start = std::max<Eigen::Index>(start, 0);
  for (Eigen::Index k = start; k < x.size(); ++k) {
    if (x[k] >= level) {
      if (index) *index = k;
      if (k == start || x[k] == x[k - 1]) return t[k];
      return t[k - 1] + (level - x[k - 1]) / (x[k] - x[k - 1]) * (t[k] - t[k - 1]);
    }
  }
  if (index) *index = x.size();
  return std::numeric_limits<double>::quiet_NaN();
}

Eigen::MatrixXd Lsim(const StateSpace& g, const Eigen::MatrixXd& u, double dt,
                     const Eigen::VectorXd& x0) {
  PNEUMID_CHECK(std::isfinite(dt) && dt > 0.0, "lsim: dt must be > 0 s, got {}", dt);
  PNEUMID_CHECK(u.cols() == g.num_inputs(), "lsim: u must have nu = {} columns, got {}",
                g.num_inputs(), u.cols());
  PNEUMID_CHECK(u.allFinite(), "lsim: the input contains NaN or Inf");
  PNEUMID_CHECK(x0.size() == 0 || x0.size() == g.num_states(),
                "lsim: x0 must have nx = {} entries (or none), got {}", g.num_states(), x0.size());
  PNEUMID_CHECK(x0.allFinite(), "lsim: the initial state x0 contains NaN or Inf");
  const StateSpace gd = DiscretizeForLsim(g, dt);
  const int d = DelayInSamples(gd.delay(), dt);
  const Eigen::Index n = gd.num_states();
  VectorXd x = VectorXd::Zero(n);
  if (x0.size() > 0) x.head(x0.size()) = x0;  // extra delay states start at rest
  if (gd.num_inputs() == 1 && gd.num_outputs() == 1) {
    return SimulateSiso(gd, u.col(0), d, x);
  }
  const Eigen::Index N = u.rows();
  MatrixXd y(N, gd.num_outputs());
  VectorXd xn(n), uk(gd.num_inputs());
  for (Eigen::Index k = 0; k < N; ++k) {
    if (k >= d) {
      uk = u.row(k - d).transpose();
    } else {
      uk.setZero();
    }
    y.row(k).noalias() = (gd.C() * x + gd.D() * uk).transpose();
    xn.noalias() = gd.A() * x;
    xn.noalias() += gd.B() * uk;
    x.swap(xn);
  }
  return y;
}

Eigen::VectorXd Lsim(const TransferFunction& g, const Eigen::VectorXd& u, double dt) {
  // SISO directly on u: no copy of the input or output (long records).
  PNEUMID_CHECK(std::isfinite(dt) && dt > 0.0, "lsim: dt must be > 0 s, got {}", dt);
  PNEUMID_CHECK(u.allFinite(), "lsim: the input contains NaN or Inf");
  const VectorXd den = poly::TrimLeading(g.den()), num = poly::TrimLeading(g.num());
  if (g.IsDiscrete() && num.size() <= den.size()) {
    // Difference equation den(q) y = num(q) u in q^-1 form, O(N (deg num +
    // deg den)) instead of O(N n^2) for an order-n realization (a FIR model of
    // a few hundred taps has as many states). Zero initial conditions equal
    // the zero state of the realization.
    CheckDiscreteStep(g.Ts(), dt);
    const Eigen::Index n = den.size();
    VectorXd b = VectorXd::Zero(n);
    b.tail(num.size()) = num / den[0];
    const VectorXd a = den / den[0];
    const Eigen::Index d = DelayInSamples(g.delay(), dt), N = u.size();
    VectorXd y(N);
    for (Eigen::Index k = 0; k < N; ++k) {
      double acc = 0.0;
      const Eigen::Index kb = std::min<Eigen::Index>(n - 1, k - d);
      for (Eigen::Index i = 0; i <= kb; ++i) acc += b[i] * u[k - d - i];
      const Eigen::Index ka = std::min<Eigen::Index>(n - 1, k);
      for (Eigen::Index i = 1; i <= ka; ++i) acc -= a[i] * y[k - i];
      y[k] = acc;
    }
    return y;
  }
  const StateSpace gd = DiscretizeForLsim(ToStateSpace(g), dt);
  const int d = DelayInSamples(gd.delay(), dt);
  return SimulateSiso(gd, u, d, VectorXd::Zero(gd.num_states()));
}

TimeResponse Step(const TransferFunction& g, double t_final, double dt) {
  ChooseGrid(g, &t_final, &dt);
  const Eigen::Index N = NumSamples(t_final, dt);
  TimeResponse r;
  r.t = VectorXd::LinSpaced(N, 0.0, (N - 1) * dt);
  r.y = Lsim(g, VectorXd::Ones(N), dt);
  CheckFinite(g, r, "step");
  return r;
}

TimeResponse Impulse(const TransferFunction& g, double t_final, double dt) {
  ChooseGrid(g, &t_final, &dt);
  const Eigen::Index N = NumSamples(t_final, dt);
  TimeResponse r;
  r.t = VectorXd::LinSpaced(N, 0.0, (N - 1) * dt);
  if (g.IsDiscrete()) {
    VectorXd u = VectorXd::Zero(N);
    u[0] = 1.0;
    r.y = Lsim(g, u, dt);
    CheckFinite(g, r, "impulse");
    return r;
  }
  // Continuous: the impulse response of the strictly proper part G - D is the
  // step response of s (G - D), exact on the grid; the D delta(t) term is dropped.
  const VectorXd den = poly::TrimLeading(g.den());
  const VectorXd nt = poly::TrimLeading(g.num());
  VectorXd num = VectorXd::Zero(den.size());
  num.tail(nt.size()) = nt;
  num -= (num[0] / den[0]) * den;
  VectorXd snum = VectorXd::Zero(den.size());
  snum.head(den.size() - 1) = num.tail(den.size() - 1);
  r.y = Lsim(TransferFunction(snum, den, 0.0, g.delay()), VectorXd::Ones(N), dt);
  CheckFinite(g, r, "impulse");
  return r;
}

bool StepInfoOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& m) {
    if (error != nullptr) *error = m;
    return false;
  };
  if (!(settling_threshold > 0.0 && settling_threshold < 1.0)) {
    return fail(fmt::format("settling_threshold must be in (0, 1), got {}", settling_threshold));
  }
  if (!(rise_low >= 0.0 && rise_low < rise_high && rise_high <= 1.0)) {
    return fail(
        fmt::format("rise limits must satisfy 0 <= rise_low < rise_high <= 1, got {} and {}",
                    rise_low, rise_high));
  }
  if (std::isinf(y_initial) || std::isinf(y_final)) {
    return fail("y_initial and y_final must be finite or NaN (automatic)");
  }
  return true;
}

StepInfo ComputeStepInfo(const Eigen::VectorXd& t, const Eigen::VectorXd& y,
                         const StepInfoOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "stepinfo: invalid options: {}", error);
  PNEUMID_CHECK(t.size() == y.size(), "stepinfo: t has {} samples but y has {}", t.size(),
                y.size());
  PNEUMID_CHECK(t.size() >= 2, "stepinfo: need at least 2 samples, got {}", t.size());
  PNEUMID_CHECK(t.allFinite(), "stepinfo: t contains NaN or Inf");
  PNEUMID_CHECK(y.allFinite(), "stepinfo: y contains NaN or Inf");
  for (Eigen::Index k = 1; k < t.size(); ++k) {
    PNEUMID_CHECK(t[k] > t[k - 1],
                  "stepinfo: t must be strictly increasing, t[{}] = {} <= t[{}] = {}", k, t[k],
                  k - 1, t[k - 1]);
  }
  const Eigen::Index N = y.size();
  const double y0 = std::isnan(options.y_initial) ? y[0] : options.y_initial;
  const double yf = std::isnan(options.y_final) ? y[N - 1] : options.y_final;
  const double step = yf - y0;
  StepInfo info;
  info.steady_state = yf;
  Eigen::Index ipeak = 0;
  y.cwiseAbs().maxCoeff(&ipeak);
  info.peak = std::abs(y[ipeak]);
  info.peak_time = t[ipeak] - t[0];
  if (step == 0.0) {
    info.rise_time = info.settling_time = kNaN;
    info.settling_min = y.minCoeff();
    info.settling_max = y.maxCoeff();
    info.overshoot = info.undershoot = 0.0;
    return info;
  }
  const double mag = std::abs(step);
  const double sign = step > 0 ? 1.0 : -1.0;
  // Normalized response r = (y - y0) / step rises from 0 towards 1.
  const Eigen::VectorXd normalized = ((y.array() - y0) / step).matrix();
  Eigen::Index ilow = 0, ihigh = 0;
  const double t_low = FirstCrossing(t, normalized, options.rise_low, 0, &ilow);
  const double t_high = FirstCrossing(t, normalized, options.rise_high, 0, &ihigh);
  info.rise_time = t_high - t_low;

  // Settling: last sample outside the band, then the interpolated band entry.
  const double band = options.settling_threshold * mag;
  Eigen::Index last_out = -1;
  for (Eigen::Index k = N - 1; k >= 0; --k) {
    if (std::abs(y[k] - yf) > band) {
      last_out = k;
      break;
    }
  }
  if (last_out < 0) {
    info.settling_time = 0.0;
  } else if (last_out == N - 1) {
    info.settling_time = kNaN;
  } else {
    const double e0 = y[last_out] - yf, e1 = y[last_out + 1] - yf;
    const double level = e0 > 0 ? band : -band;
    const double f = (level - e0) / (e1 - e0);
    info.settling_time = t[last_out] + f * (t[last_out + 1] - t[last_out]) - t[0];
  }
  if (ihigh < N) {
    info.settling_min = y.tail(N - ihigh).minCoeff();
    info.settling_max = y.tail(N - ihigh).maxCoeff();
  } else {
    info.settling_min = y.minCoeff();
    info.settling_max = y.maxCoeff();
  }
  const double over = (sign * (y.array() - yf)).maxCoeff();
  const double under = (-sign * (y.array() - y0)).maxCoeff();
  info.overshoot = 100.0 * std::max(0.0, over) / mag;
  info.undershoot = 100.0 * std::max(0.0, under) / mag;
  return info;
}

StepInfo ComputeStepInfo(const TransferFunction& g, const StepInfoOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "stepinfo: invalid options: {}", error);
  const double dc = g.DcGain();
  if (!g.IsStable() || !std::isfinite(dc)) {
    StepInfo info;
    info.rise_time = info.settling_time = info.settling_min = info.settling_max = kNaN;
    info.overshoot = info.undershoot = info.peak = info.peak_time = kNaN;
    info.steady_state = dc;
    return info;
  }
  StepInfoOptions o = options;
  if (std::isnan(o.y_initial)) o.y_initial = 0.0;
  if (std::isnan(o.y_final)) o.y_final = dc;
  // About 7 slowest time constants is short for a high order (n equal poles
  // settle after about n + 3 sqrt(n) of them): double the horizon until the
  // response settles, within twice the work of an automatic grid.
  TimeResponse r = Step(g);
  StepInfo info = ComputeStepInfo(r.t, r.y, o);
  const double states = std::max(1, g.Order()) + 1.0;
  for (int i = 0; i < 10 && std::isnan(info.settling_time) && dc != 0.0; ++i) {
    const double dt = r.t[1] - r.t[0];
    const double t_final = 2.0 * r.t[r.t.size() - 1];
    if (t_final / dt * states * states > 2.0 * kMaxDefaultWork) break;
    r = Step(g, t_final, dt);
    info = ComputeStepInfo(r.t, r.y, o);
  }
  return info;
}

}  // namespace pneumid
