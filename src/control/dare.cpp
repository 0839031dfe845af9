#include "pneumid/control/dare.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"

namespace pneumid {

namespace {
constexpr EnumName<DareStatus> kDareStatusNames[] = {
    {DareStatus::kConverged, "converged"},
    {DareStatus::kMaxIterations, "max_iterations"},
    {DareStatus::kNotStabilizing, "not_stabilizing"},
    {DareStatus::kNumericalFailure, "numerical_failure"},
};

bool IsSymmetric(const Eigen::MatrixXd& M) {
  return (M - M.transpose()).norm() <= 1e-10 * std::max(1.0, M.norm());
}
}  // namespace

std::string ToString(DareStatus v) { return std::string(EnumToString(kDareStatusNames, v)); }

DareStatus DareStatusFromString(const std::string& name) {
  return EnumFromString(kDareStatusNames, name, "DARE status");
}

bool DareOptions::IsValid(std::string* error) const {
  if (max_iterations < 1) {
    if (error) *error = fmt::format("max_iterations must be >= 1, got {}", max_iterations);
    return false;
  }
  if (!(tolerance > 0.0) || !(tolerance < 1.0)) {
    if (error) *error = fmt::format("tolerance must be in (0, 1), got {}", tolerance);
    return false;
  }
  return true;
}

std::string DareSummary::BriefReport() const {
  return fmt::format("DARE {}: {} iterations, residual {:.3g}, rho(A-BK) {:.6g}{}{}",
                     ToString(status), iterations, residual, closed_loop_spectral_radius,
                     message.empty() ? "" : "; ", message);
}

DareResult SolveDare(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                     const Eigen::MatrixXd& R, const DareOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid DARE options: {}", error);
  const Eigen::Index n = A.rows(), m = B.cols();
  PNEUMID_CHECK(n >= 1 && A.cols() == n, "A must be square and non-empty, got {} x {}", A.rows(),
                A.cols());
  PNEUMID_CHECK(B.rows() == n && m >= 1, "B must be {} x m with m >= 1, got {} x {}", n, B.rows(),
                B.cols());
  PNEUMID_CHECK(Q.rows() == n && Q.cols() == n, "Q must be {} x {}, got {} x {}", n, n, Q.rows(),
                Q.cols());
  PNEUMID_CHECK(R.rows() == m && R.cols() == m, "R must be {} x {}, got {} x {}", m, m, R.rows(),
                R.cols());
  PNEUMID_CHECK(A.allFinite() && B.allFinite() && Q.allFinite() && R.allFinite(),
                "the DARE matrices must be finite");
  PNEUMID_CHECK(IsSymmetric(Q), "Q must be symmetric");
  PNEUMID_CHECK(IsSymmetric(R), "R must be symmetric");
  const Eigen::MatrixXd Qs = 0.5 * (Q + Q.transpose());
  const Eigen::MatrixXd Rs = 0.5 * (R + R.transpose());
  Eigen::LLT<Eigen::MatrixXd> r_llt(Rs);
  PNEUMID_CHECK(r_llt.info() == Eigen::Success && r_llt.matrixLLT().diagonal().minCoeff() > 0.0,
                "R must be positive definite");
  const double q_min = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Qs).eigenvalues().minCoeff();
  PNEUMID_CHECK(q_min >= -1e-12 * std::max(1.0, Qs.norm()),
                "Q must be positive semidefinite, smallest eigenvalue {}", q_min);

  DareResult result;
  DareSummary& s = result.summary;
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(n, n);
  Eigen::MatrixXd Ak = A;
  Eigen::MatrixXd Gk = B * r_llt.solve(B.transpose());
  Gk = 0.5 * (Gk + Gk.transpose()).eval();
  Eigen::MatrixXd Hk = Qs;
  bool converged = false;
  s.status = DareStatus::kMaxIterations;
  for (int it = 1; it <= options.max_iterations; ++it) {
    s.iterations = it;
    Eigen::PartialPivLU<Eigen::MatrixXd> lu(I + Gk * Hk);
    const Eigen::MatrixXd WA = lu.solve(Ak);  // W^-1 A_k
    const Eigen::MatrixXd WG = lu.solve(Gk);  // W^-1 G_k
    Eigen::MatrixXd G_next = Gk + Ak * WG * Ak.transpose();
    Eigen::MatrixXd H_next = Hk + Ak.transpose() * Hk * WA;
    Eigen::MatrixXd A_next = Ak * WA;
    if (!G_next.allFinite() || !H_next.allFinite() || !A_next.allFinite()) {
      s.status = DareStatus::kNumericalFailure;
      s.message = "non-finite iterate (I + G H singular)";
      break;
    }
    G_next = 0.5 * (G_next + G_next.transpose()).eval();
    H_next = 0.5 * (H_next + H_next.transpose()).eval();
    const double change = (H_next - Hk).norm();
    Ak = std::move(A_next);
    Gk = std::move(G_next);
    Hk = std::move(H_next);
    if (change <= options.tolerance * Hk.norm()) {
      converged = true;
      break;
    }
  }
  result.X = Hk;
  const Eigen::MatrixXd& X = result.X;
  const Eigen::MatrixXd S = Rs + B.transpose() * X * B;
  result.K = S.ldlt().solve(B.transpose() * X * A);
  if (!result.K.allFinite()) {
    s.status = DareStatus::kNumericalFailure;
    if (s.message.empty()) s.message = "R + B'XB is singular";
    return result;
  }
  const Eigen::MatrixXd rhs = A.transpose() * X * A - A.transpose() * X * B * result.K + Qs;
  s.residual = (X - rhs).norm() / std::max(1.0, X.norm());
  s.closed_loop_spectral_radius = (A - B * result.K).eigenvalues().cwiseAbs().maxCoeff();
  if (s.status == DareStatus::kNumericalFailure) return result;
  if (!converged) {
    s.message = fmt::format("no convergence in {} doubling steps", options.max_iterations);
    return result;
  }
  if (!(s.closed_loop_spectral_radius < 1.0)) {
    s.status = DareStatus::kNotStabilizing;
    s.message =
        "the solution does not stabilize A - BK ((A, B) not stabilizable, or "
        "(A, Q) with an unobservable mode on the unit circle)";
    return result;
  }
  s.status = DareStatus::kConverged;
  return result;
}

}  // namespace pneumid
