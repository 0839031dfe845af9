#include "pneumid/lti/state_space.hpp"

#include <cmath>
#include <limits>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "pneumid/common/check.hpp"

namespace pneumid {

StateSpace::StateSpace(Eigen::MatrixXd A, Eigen::MatrixXd B, Eigen::MatrixXd C, Eigen::MatrixXd D,
                       double Ts, double delay)
    : A_(std::move(A)),
      B_(std::move(B)),
      C_(std::move(C)),
      D_(std::move(D)),
      Ts_(Ts),
      delay_(delay) {
  PNEUMID_CHECK(A_.rows() == A_.cols(), "state space: A must be square, got {}x{}", A_.rows(),
                A_.cols());
  const Eigen::Index nx = A_.rows();
  PNEUMID_CHECK(B_.rows() == nx, "state space: B must have nx = {} rows, got {}x{}", nx, B_.rows(),
                B_.cols());
  PNEUMID_CHECK(C_.cols() == nx, "state space: C must have nx = {} columns, got {}x{}", nx,
                C_.rows(), C_.cols());
  PNEUMID_CHECK(D_.rows() == C_.rows() && D_.cols() == B_.cols(),
                "state space: D must be ny x nu = {}x{}, got {}x{}", C_.rows(), B_.cols(),
                D_.rows(), D_.cols());
  PNEUMID_CHECK(A_.allFinite() && B_.allFinite() && C_.allFinite() && D_.allFinite(),
                "state space: matrices must be finite");
  PNEUMID_CHECK(std::isfinite(Ts) && Ts >= 0.0,
                "state space: sample time must be >= 0 (0 = continuous), got Ts = {}", Ts);
  PNEUMID_CHECK(std::isfinite(delay) && delay >= 0.0,
                "state space: delay must be >= 0 seconds, got delay = {}", delay);
}

Eigen::VectorXcd StateSpace::Poles() const {
  if (A_.rows() == 0) return Eigen::VectorXcd(0);
  Eigen::EigenSolver<Eigen::MatrixXd> es(A_, false);
  return es.eigenvalues();
}

bool StateSpace::IsStable() const {
  const Eigen::VectorXcd p = Poles();
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    if (IsDiscrete() ? std::abs(p[i]) >= 1.0 : p[i].real() >= 0.0) return false;
  }
  return true;
}

Eigen::MatrixXd StateSpace::DcGain() const {
  const Eigen::Index nx = A_.rows();
  if (nx == 0) return D_;
  const Eigen::MatrixXd M =
      IsDiscrete() ? Eigen::MatrixXd(Eigen::MatrixXd::Identity(nx, nx) - A_) : Eigen::MatrixXd(-A_);
  Eigen::FullPivLU<Eigen::MatrixXd> lu(M);
  if (!lu.isInvertible()) {
    return Eigen::MatrixXd::Constant(D_.rows(), D_.cols(), std::numeric_limits<double>::infinity());
  }
  return D_ + C_ * lu.solve(B_);
}

}  // namespace pneumid
