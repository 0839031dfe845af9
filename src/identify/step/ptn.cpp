#include "pneumid/identify/step/ptn.hpp"

#include <cmath>

#include "pneumid/common/check.hpp"

namespace pneumid {

std::vector<double> PtnCoefficients(double td, double tTL, int n) {
  PNEUMID_CHECK(std::isfinite(td) && td >= 0.0, "PTn: delay time td must be >= 0 s, got {}", td);
  PNEUMID_CHECK(std::isfinite(tTL) && tTL > 0.0, "PTn: time constant tTL must be > 0 s, got {}",
                tTL);
  PNEUMID_CHECK(n >= 1 && n <= 20, "PTn: order n must be in 1..20, got {}", n);
  std::vector<double> a(n + 1);
  a[0] = 1.0;
  double p = 1.0;  // td^(i-1) / (i-1)!
  for (int i = 1; i <= n; ++i) {
    a[i] = p * td / i + tTL * p;  // td^i / i! + tTL td^(i-1) / (i-1)!
    p *= td / i;
  }
  return a;
}

TransferFunction PtnModel(double kp, double td, double tTL, int n) {
  PNEUMID_CHECK(std::isfinite(kp), "PTn: gain must be finite, got {}", kp);
  const std::vector<double> a = PtnCoefficients(td, tTL, n);
  // Descending powers of s; drop vanishing leading coefficients (td = 0).
  std::vector<double> den(a.rbegin(), a.rend());
  std::size_t lead = 0;
  while (lead + 1 < den.size() && den[lead] == 0.0) ++lead;
  den.erase(den.begin(), den.begin() + static_cast<long>(lead));
  return TransferFunction::Continuous({kp}, den);
}

}  // namespace pneumid
