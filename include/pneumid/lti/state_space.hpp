// Linear state-space model for both time domains (Drake linear_system.h).
//
//   continuous (Ts == 0):  dx/dt = A x + B u(t - delay),  y = C x + D u(t - delay)
//   discrete   (Ts  > 0):  x[k+1] = A x[k] + B u[k - d],   y[k] = C x[k] + D u[k - d]
//
//   matrix | rows | cols
//   A      | nx   | nx
//   B      | nx   | nu
//   C      | ny   | nx
//   D      | ny   | nu
// The input delay is in seconds; for a discrete model d = delay / Ts samples.
#pragma once

#include <Eigen/Core>

namespace pneumid {

/// Linear state-space model (A, B, C, D) with sample time Ts (0: continuous) and an input
/// delay in s (see above).
class StateSpace {
 public:
  /// An empty continuous model (no states, inputs or outputs).
  StateSpace() = default;
  /// Throws InvalidArgument when the matrix sizes disagree (table above), Ts < 0
  /// or delay < 0.
  StateSpace(Eigen::MatrixXd A, Eigen::MatrixXd B, Eigen::MatrixXd C, Eigen::MatrixXd D,
             double Ts = 0.0, double delay = 0.0);

  const Eigen::MatrixXd& A() const { return A_; }  ///< state matrix, nx x nx
  const Eigen::MatrixXd& B() const { return B_; }  ///< input matrix, nx x nu
  const Eigen::MatrixXd& C() const { return C_; }  ///< output matrix, ny x nx
  const Eigen::MatrixXd& D() const { return D_; }  ///< feedthrough matrix, ny x nu
  double Ts() const { return Ts_; }                ///< sample time in s; 0 for continuous
  double delay() const { return delay_; }          ///< input delay in s
  bool IsDiscrete() const { return Ts_ > 0.0; }    ///< Ts > 0
  int num_states() const { return static_cast<int>(A_.rows()); }   ///< nx
  int num_inputs() const { return static_cast<int>(B_.cols()); }   ///< nu
  int num_outputs() const { return static_cast<int>(C_.rows()); }  ///< ny

  /// Eigenvalues of A (s-plane or z-plane by Ts); empty for a model without states.
  Eigen::VectorXcd Poles() const;
  /// True when every pole has real part < 0 (continuous) or |z| < 1 (discrete); the
  /// delay does not matter. A model without states is stable.
  bool IsStable() const;
  /// Steady-state gain matrix (ny x nu): D - C A^-1 B, or D + C (I - A)^-1 B.
  Eigen::MatrixXd DcGain() const;

 private:
  Eigen::MatrixXd A_, B_, C_, D_;
  double Ts_ = 0.0;
  double delay_ = 0.0;
};

}  // namespace pneumid
