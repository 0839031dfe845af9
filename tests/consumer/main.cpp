// Downstream use of an installed pneumid: the paper's ARX force model (Eq. 5)
// converted to continuous time by zero-order hold must give Eq. 6.
#include <cmath>
#include <cstdio>

#include <pneumid/common/version.hpp>
#include <pneumid/lti/conversion.hpp>
#include <pneumid/lti/transfer_function.hpp>

int main() {
  using pneumid::TransferFunction;
  const TransferFunction arx = TransferFunction::Discrete(
      {0.0, 0.03938, 0.04506, 0.01286}, {1.0, -0.60870, -0.27020, -0.06021}, 0.01);
  const TransferFunction g = pneumid::D2C(arx, pneumid::DiscretizationMethod::kZoh);
  const double dc = g.DcGain();
  std::printf("pneumid %s: d2c(ARX) DC gain = %.5f\n", pneumid::Version(), dc);
  return std::abs(dc - 1.59796) < 1e-4 ? 0 : 1;
}
