#include "pneumid/lti/fopdt.hpp"

#include <algorithm>

namespace pneumid {

TransferFunction FopdtParams::ToTransferFunction() const {
  return TransferFunction::Fopdt(K, tau, theta);
}

FopdtParams SmithTwoPoint(double K, double t1, double t2) {
  FopdtParams p;
  p.K = K;
  p.tau = 1.5 * (t2 - t1);
  p.theta = std::max(t2 - p.tau, 0.0);
  return p;
}

}  // namespace pneumid
