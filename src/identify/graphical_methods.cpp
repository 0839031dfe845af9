// Reaction curve, tangent, two-point, three-point SOPDT, Strejc and area
// methods (see the headers for the formulas and references).
#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"
#include "pneumid/identify/areas.hpp"
#include "pneumid/identify/reaction_curve.hpp"
#include "pneumid/identify/sopdt.hpp"
#include "pneumid/identify/strejc.hpp"
#include "pneumid/identify/tangent.hpp"
#include "pneumid/identify/two_point.hpp"

namespace pneumid {

// ---------------------------------------------------------------- reaction curve
FopdtParams ReactionCurve(const StepAnalysis& step) {
  const double t63 = step.CrossingTime(1.0 - std::exp(-1.0));
  FopdtParams p;
  p.K = step.gain;
  p.theta = std::min(step.departure_time, t63);
  p.tau = t63 - p.theta;
  if (!(p.tau > 0.0)) {
    throw DataError(
        fmt::format("reaction curve: the response reaches 63.2 % at {} s, no later "
                    "than its departure from the baseline at {} s",
                    t63, step.departure_time));
  }
  return p;
}

// ---------------------------------------------------------------- tangent
bool TangentOptions::IsValid(std::string* error) const {
  if (half_width < 0) {
    if (error) *error = fmt::format("half_width must be >= 0, got {}", half_width);
    return false;
  }
  return true;
}

TangentResult InflectionTangent(const StepAnalysis& step, const TangentOptions& options) {
  std::string why;
  PNEUMID_CHECK(options.IsValid(&why), "invalid TangentOptions: {}", why);
  const Eigen::Index n = step.r.size();
  int m = options.half_width;
  if (m == 0) {
    const double t63 = step.CrossingTime(1.0 - std::exp(-1.0));
    m = static_cast<int>(std::clamp<long>(std::lround(t63 / step.Ts / 8.0), 2, 50));
  }
  if (n < 2 * m + 3) {
    throw DataError(
        fmt::format("tangent: {} samples are fewer than the filter window of {}", n, 2 * m + 1));
  }
  // Savitzky-Golay: least-squares quadratic over j = -m..m (sample units).
  Eigen::MatrixXd V(2 * m + 1, 3);
  for (int j = -m; j <= m; ++j) V.row(j + m) << 1.0, j, static_cast<double>(j) * j;
  const Eigen::MatrixXd P = (V.transpose() * V).ldlt().solve(V.transpose());  // 3 x (2m+1)
  Eigen::VectorXd slope = Eigen::VectorXd::Constant(n, -std::numeric_limits<double>::infinity());
  Eigen::Index best = -1;
  for (Eigen::Index k = m; k < n - m; ++k) {
    if (step.t[k] < 0.0) continue;  // the inflection lies after the step
    slope[k] = P.row(1).dot(step.r.segment(k - m, 2 * m + 1)) / step.Ts;
    if (best < 0 || slope[k] > slope[best]) best = k;
  }
  if (best < 0 || !(slope[best] > 0.0)) {
    throw DataError("tangent: the response never rises (no positive slope)");
  }
  double delta = 0.0, s_max = slope[best];
  if (best > m && best + 1 < n - m && std::isfinite(slope[best - 1])) {
    const double s0 = slope[best - 1], s1 = slope[best], s2 = slope[best + 1];
    const double curvature = s0 - 2.0 * s1 + s2;
    if (curvature < 0.0) {
      delta = std::clamp(0.5 * (s0 - s2) / curvature, -0.5, 0.5);
      s_max = s1 - 0.25 * (s0 - s2) * delta;
    }
  }
  const Eigen::Vector3d c = P * step.r.segment(best - m, 2 * m + 1);
  TangentResult res;
  res.half_width = m;
  res.inflection_time = step.t[best] + delta * step.Ts;
  res.inflection_value = c[0] + c[1] * delta + c[2] * delta * delta;
  res.slope = s_max;
  res.L = res.inflection_time - res.inflection_value / s_max;
  res.T = 1.0 / s_max;
  return res;
}

FopdtParams TangentFopdt(const StepAnalysis& step, const TangentResult& tangent) {
  return FopdtParams{step.gain, tangent.T, std::max(tangent.L, 0.0)};
}

// ---------------------------------------------------------------- two-point
namespace {
constexpr EnumName<TwoPointMethod> kTwoPointMethodNames[] = {
    {TwoPointMethod::kSmith, "smith"},
    {TwoPointMethod::kSundaresanKrishnaswamy, "sundaresan"},
    {TwoPointMethod::kBroida, "broida"},
};
}  // namespace

std::string ToString(TwoPointMethod v) {
  return std::string(EnumToString(kTwoPointMethodNames, v));
}

TwoPointMethod TwoPointMethodFromString(const std::string& name) {
  return EnumFromString(kTwoPointMethodNames, name, "two-point method");
}

std::pair<double, double> TwoPointLevels(TwoPointMethod method) {
  switch (method) {
    case TwoPointMethod::kSmith:
      return {kSmithLevel1, kSmithLevel2};
    case TwoPointMethod::kSundaresanKrishnaswamy:
      return {0.353, 0.853};
    case TwoPointMethod::kBroida:
      return {0.28, 0.40};
  }
  return {0.0, 0.0};
}

FopdtParams TwoPoint(const StepAnalysis& step, TwoPointMethod method) {
  const auto [p1, p2] = TwoPointLevels(method);
  const double t1 = step.CrossingTime(p1);
  const double t2 = step.CrossingTime(p2);
  FopdtParams p;
  p.K = step.gain;
  switch (method) {
    case TwoPointMethod::kSmith:
      p = SmithTwoPoint(step.gain, t1, t2);
      break;
    case TwoPointMethod::kSundaresanKrishnaswamy:
      p.tau = 0.67 * (t2 - t1);
      p.theta = 1.3 * t1 - 0.29 * t2;
      break;
    case TwoPointMethod::kBroida:
      p.tau = 5.5 * (t2 - t1);
      p.theta = 2.8 * t1 - 1.8 * t2;
      break;
  }
  if (!(p.tau > 0.0)) {
    throw DataError(
        fmt::format("{}: the response reaches {} % at {} s and {} % at {} s; no "
                    "positive time constant",
                    ToString(method), 100 * p1, t1, 100 * p2, t2));
  }
  p.theta = std::max(p.theta, 0.0);
  return p;
}

// ---------------------------------------------------------------- three-point SOPDT
double SopdtNormalizedStep(double q, double x) {
  if (x <= 0.0) return 0.0;
  if (q < 1e-12) return 1.0 - std::exp(-x);
  if (std::abs(1.0 - q) < 1e-5) return 1.0 - (1.0 + x) * std::exp(-x);
  return 1.0 - (std::exp(-x) - q * std::exp(-x / q)) / (1.0 - q);
}

double SopdtNormalizedTime(double q, double p) {
  PNEUMID_CHECK(q >= 0.0 && q <= 1.0, "lag ratio q must be in [0, 1], got {}", q);
  PNEUMID_CHECK(p > 0.0 && p < 1.0, "level must be in (0, 1), got {}", p);
  double lo = 0.0, hi = 1.0;
  while (SopdtNormalizedStep(q, hi) < p) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-14 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (SopdtNormalizedStep(q, mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

namespace {
double SopdtRatio(double q) {
  const double x1 = SopdtNormalizedTime(q, 0.2), x2 = SopdtNormalizedTime(q, 0.5),
               x3 = SopdtNormalizedTime(q, 0.8);
  return (x3 - x2) / (x2 - x1);
}
}  // namespace

ThreePointSopdtResult ThreePointSopdt(const StepAnalysis& step) {
  const double t1 = step.CrossingTime(0.2), t2 = step.CrossingTime(0.5),
               t3 = step.CrossingTime(0.8);
  if (!(t1 < t2 && t2 < t3)) {
    throw DataError(
        fmt::format("sopdt: the 20/50/80 % times {}, {}, {} s are not increasing", t1, t2, t3));
  }
  ThreePointSopdtResult res;
  res.ratio = (t3 - t2) / (t2 - t1);
  double q;
  const double r0 = SopdtRatio(0.0), r1 = SopdtRatio(1.0);
  if (res.ratio >= r0) {
    q = 0.0;
    res.clamped = res.ratio > r0;
  } else if (res.ratio <= r1) {
    q = 1.0;
    res.clamped = res.ratio < r1;
  } else {
    double lo = 0.0, hi = 1.0;  // SopdtRatio decreases in q
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      (SopdtRatio(mid) > res.ratio ? lo : hi) = mid;
    }
    q = 0.5 * (lo + hi);
  }
  const double x1 = SopdtNormalizedTime(q, 0.2), x2 = SopdtNormalizedTime(q, 0.5),
               x3 = SopdtNormalizedTime(q, 0.8);
  res.params.K = step.gain;
  res.params.tau1 = (t3 - t1) / (x3 - x1);
  res.params.tau2 = q * res.params.tau1;
  res.params.theta = std::max(0.0, t2 - res.params.tau1 * x2);
  return res;
}

// ---------------------------------------------------------------- Strejc
std::pair<double, double> StrejcTable(int n) {
  PNEUMID_CHECK(n >= 1, "Strejc order must be >= 1, got {}", n);
  if (n == 1) return {0.0, 1.0};
  const double xi = n - 1.0;
  double sum = 0.0, term = 1.0;  // sum_{k<n} xi^k / k!
  for (int k = 0; k < n; ++k) {
    if (k > 0) term *= xi / k;
    sum += term;
  }
  const double h = 1.0 - std::exp(-xi) * sum;
  const double dh = std::exp((n - 1) * std::log(xi) - xi - std::lgamma(static_cast<double>(n)));
  return {xi - h / dh, 1.0 / dh};
}

StrejcResult Strejc(const TangentResult& tangent, double K, int max_order) {
  PNEUMID_CHECK(tangent.T > 0.0, "Strejc: tangent time constant must be positive, got {}",
                tangent.T);
  PNEUMID_CHECK(max_order >= 1, "Strejc: max_order must be >= 1, got {}", max_order);
  StrejcResult res;
  const double Tu = std::max(tangent.L, 0.0), Tn = tangent.T;
  res.ratio = Tu / Tn;
  res.n = 1;
  for (int n = 2; n <= max_order; ++n) {
    const auto [tu, tn] = StrejcTable(n);
    if (tu / tn <= res.ratio) res.n = n;
  }
  const auto [tu, tn] = StrejcTable(res.n);
  res.K = K;
  res.T = Tn / tn;
  res.Td = std::max(0.0, Tu - tu * res.T);
  return res;
}

// ---------------------------------------------------------------- areas
AreaResult CharacteristicAreas(const StepAnalysis& step) {
  const Eigen::Index k0 = step.step_index, n = step.r.size();
  // Repeated integration (trapezoidal) of the normalized response after the step.
  auto cumulative = [&](const Eigen::VectorXd& f) {
    Eigen::VectorXd F(n - k0);
    F[0] = 0.0;
    for (Eigen::Index k = 1; k < n - k0; ++k) {
      F[k] = F[k - 1] + 0.5 * (f[k] + f[k - 1]) * (step.t[k0 + k] - step.t[k0 + k - 1]);
    }
    return F;
  };
  const Eigen::VectorXd r = step.r.segment(k0, n - k0);
  const Eigen::VectorXd f0 = (1.0 - r.array()).matrix();
  const Eigen::VectorXd y1 = cumulative(f0);
  const double a1 = y1[y1.size() - 1];
  const Eigen::VectorXd f1 = (a1 - y1.array()).matrix();
  const Eigen::VectorXd y2 = cumulative(f1);
  const double a2 = y2[y2.size() - 1];
  const Eigen::VectorXd f2 = (a2 - y2.array()).matrix();
  const double a3 = cumulative(f2)[n - k0 - 1];
  AreaResult res;
  res.A0 = step.gain;
  res.A1 = step.gain * a1;
  res.A2 = step.gain * a2;
  res.A3 = step.gain * a3;
  res.T_ar = a1;
  const double t_end = step.t[n - 1];
  if (!(a1 > 0.0) || a1 >= t_end) {
    throw DataError(
        fmt::format("areas: the average residence time {} s is not inside the record "
                    "(0, {}] s",
                    a1, t_end));
  }
  // int_0^T_ar r dt, trapezoidal with the last partial interval interpolated.
  double area = 0.0;
  for (Eigen::Index k = k0 + 1; k < n; ++k) {
    const double ta = step.t[k - 1], tb = step.t[k];
    if (ta >= a1) break;
    const double te = std::min(tb, a1);
    const double re = step.r[k - 1] + (step.r[k] - step.r[k - 1]) * (te - ta) / (tb - ta);
    area += 0.5 * (step.r[k - 1] + re) * (te - ta);
  }
  res.fopdt.K = step.gain;
  res.fopdt.tau = std::numbers::e * area;
  res.fopdt.theta = std::max(0.0, a1 - res.fopdt.tau);
  if (!(res.fopdt.tau > 0.0)) {
    throw DataError("areas: the response has no positive area up to its residence time");
  }
  return res;
}

}  // namespace pneumid
