#include "pneumid/identify/step/areas.hpp"

#include <algorithm>
#include <numbers>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "pneumid/common/check.hpp"

namespace pneumid {

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
