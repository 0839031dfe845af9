#include "pneumid/identify/step/sopdt.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"

namespace pneumid {

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

}  // namespace pneumid
