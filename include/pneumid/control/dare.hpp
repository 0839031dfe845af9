// Discrete-time algebraic Riccati equation (DARE)
//
//   X = A' X A - A' X B (R + B' X B)^-1 B' X A + Q                        (1)
//
//   matrix | rows | cols
//   A      | n    | n
//   B      | n    | m
//   Q      | n    | n     symmetric positive semidefinite
//   R      | m    | m     symmetric positive definite
//   X      | n    | n     the stabilizing solution
//
// With G = B R^-1 B' and the matrix inversion lemma, (1) reads
// X = A' X (I + G X)^-1 A + Q, which the structure-preserving doubling
// algorithm (SDA) [1, 2] solves by
//   W_k     = I + G_k H_k
//   A_{k+1} = A_k W_k^-1 A_k
//   G_{k+1} = G_k + A_k W_k^-1 G_k A_k'
//   H_{k+1} = H_k + A_k' H_k W_k^-1 A_k,      A_0 = A, G_0 = G, H_0 = Q,
// where H_k converges quadratically to X when (A, B) is stabilizable and
// (A, Q^1/2) has no unobservable mode on the unit circle [2]. The iteration
// stops when ||H_{k+1} - H_k||_F <= tolerance ||H_{k+1}||_F. The solution is
// then checked: the residual of (1) and the spectral radius of the closed
// loop A - B K, K = (R + B' X B)^-1 B' X A, which must be below 1 (the
// stabilizing solution, as scipy.linalg.solve_discrete_are returns).
//
// The control form (1) also gives the steady-state Kalman filter of
// x+ = A x + w, y = C x + v (cov w = Q, cov v = R): X = DARE(A', C', Q, R) is
// the a priori error covariance and L = X C' (C X C' + R)^-1 the gain [3].
//
// [1] E. K.-W. Chu, H.-Y. Fan, W.-W. Lin, C.-S. Wang, "Structure-preserving
//     algorithms for periodic discrete-time algebraic Riccati equations",
//     Int. J. Control 77 (2004) 767-788.
// [2] W.-W. Lin, S.-F. Xu, "Convergence analysis of structure-preserving
//     doubling algorithms for Riccati-type matrix equations", SIAM J. Matrix
//     Anal. Appl. 28 (2006) 26-39.
// [3] B. D. O. Anderson, J. B. Moore, Optimal Filtering, Prentice Hall,
//     1979, ch. 4.
#pragma once

#include <string>

#include <Eigen/Core>

namespace pneumid {

/// Outcome of SolveDare.
enum class DareStatus {
  kConverged,         ///< X found, residual small, closed loop stable
  kMaxIterations,     ///< the doubling did not converge within the cap
  kNotStabilizing,    ///< converged, but A - B K is not stable (no stabilizing solution)
  kNumericalFailure,  ///< a singular I + G H or non-finite values
};

/// "converged", "max_iterations", "not_stabilizing", "numerical_failure".
std::string ToString(DareStatus status);
/// Inverse of ToString; throws InvalidArgument listing the valid names.
DareStatus DareStatusFromString(const std::string& name);

/// Stopping rule of the doubling iteration.
struct DareOptions {
  int max_iterations = 100;  ///< doubling steps (each squares the convergence factor)
  double tolerance = 1e-13;  ///< relative change of H_k that counts as converged
  /// True when max_iterations >= 1 and tolerance is in (0, 1); otherwise false with the
  /// reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// How the DARE solve ended and how good the solution is.
struct DareSummary {
  DareStatus status = DareStatus::kNumericalFailure;  ///< see DareStatus
  std::string message;  ///< why it did not converge (empty or a short note otherwise)
  int iterations = 0;   ///< doubling steps taken
  /// ||X - (right-hand side of (1))||_F / max(1, ||X||_F).
  double residual = 0.0;
  /// Spectral radius of A - B K.
  double closed_loop_spectral_radius = 0.0;
  /// One line, e.g. "DARE converged: 7 iterations, residual 3e-16, rho(A-BK) 0.61".
  std::string BriefReport() const;
};

/// Solution of the DARE with its feedback gain and the solve's summary.
struct DareResult {
  Eigen::MatrixXd X;  ///< solution (n x n, symmetric); the last iterate unless converged
  Eigen::MatrixXd K;  ///< (R + B'XB)^-1 B'XA (m x n)
  DareSummary summary;  ///< status, iterations, residual and closed-loop spectral radius
};

/// Solves (1) by the SDA. Numerical failure is reported in the summary.
/// @throws InvalidArgument when the sizes disagree (table above), an entry is
/// not finite, Q or R is not symmetric, R is not positive definite, Q is not
/// positive semidefinite, or the options are invalid.
DareResult SolveDare(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                     const Eigen::MatrixXd& R, const DareOptions& options = {});

}  // namespace pneumid
