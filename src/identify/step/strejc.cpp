#include "pneumid/identify/step/strejc.hpp"

#include <algorithm>
#include <cmath>

#include "pneumid/common/check.hpp"

namespace pneumid {

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

}  // namespace pneumid
