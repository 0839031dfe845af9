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

class StateSpace {
 public:
  StateSpace() = default;
  /// Throws InvalidArgument when the matrix sizes disagree (table above), Ts < 0
  /// or delay < 0.
  StateSpace(Eigen::MatrixXd A, Eigen::MatrixXd B, Eigen::MatrixXd C, Eigen::MatrixXd D,
             double Ts = 0.0, double delay = 0.0);

  const Eigen::MatrixXd& A() const { return A_; }
  const Eigen::MatrixXd& B() const { return B_; }
  const Eigen::MatrixXd& C() const { return C_; }
  const Eigen::MatrixXd& D() const { return D_; }
  double Ts() const { return Ts_; }
  double delay() const { return delay_; }
  bool IsDiscrete() const { return Ts_ > 0.0; }
  int num_states() const { return static_cast<int>(A_.rows()); }
  int num_inputs() const { return static_cast<int>(B_.cols()); }
  int num_outputs() const { return static_cast<int>(C_.rows()); }

  Eigen::VectorXcd Poles() const;
  bool IsStable() const;
  /// Steady-state gain matrix (ny x nu): D - C A^-1 B, or D + C (I - A)^-1 B.
  Eigen::MatrixXd DcGain() const;

 private:
  Eigen::MatrixXd A_, B_, C_, D_;
  double Ts_ = 0.0;
  double delay_ = 0.0;
};

}  // namespace pneumid
