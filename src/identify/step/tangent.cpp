#include "pneumid/identify/step/tangent.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "pneumid/common/check.hpp"

namespace pneumid {

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

}  // namespace pneumid
