// Private helper of the constrained predictive controllers (QDMC in dmc.cpp,
// MPC in mpc.cpp): their move QP over the variables [du; e] (e, the slack of
// the soft output bounds, only with a finite y_min or y_max), with the
// constraint rows in the order
//   rows 0..M-1         u_min - u_prev <= T du <= u_max - u_prev   (when u_rows)
//   next P rows         y_min - f <= Theta du + e                  (y_min finite)
//   next P rows         Theta du - e <= y_max - f                  (y_max finite)
// with T the M x M lower-triangular matrix of ones, Theta the P x M dynamic
// matrix and f the free response over the prediction horizon.
// BuildMoveQp makes the fixed data (at construction); FillMoveQpBounds the
// row bounds of each step, allocating nothing.
#pragma once

#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "pneumid/control/controller.hpp"

namespace pneumid::internal {

// The fixed data of the move QP: Hessian [H, 0; 0, rho2], the constraint
// matrix in the row order above, and the bounds |du_j| <= du_max, e >= 0.
struct MoveQp {
  Eigen::MatrixXd hessian;      // nvar x nvar, nvar = M (+ 1 with the slack)
  Eigen::MatrixXd constraints;  // rows x nvar
  Eigen::VectorXd lbx, ubx;     // nvar
};

// H is the M x M Hessian of the moves, dynamic_matrix Theta (P x M), and
// slack_quadratic_weight rho2.
inline MoveQp BuildMoveQp(const Eigen::MatrixXd& H, const Eigen::MatrixXd& dynamic_matrix,
                          const InputLimits& lim, double y_min, double y_max,
                          double slack_quadratic_weight) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const int M = static_cast<int>(H.rows()), P = static_cast<int>(dynamic_matrix.rows());
  const bool soft_output = std::isfinite(y_min) || std::isfinite(y_max);
  const bool u_rows = std::isfinite(lim.u_min) || std::isfinite(lim.u_max);
  const int nvar = M + (soft_output ? 1 : 0);
  const int rows =
      (u_rows ? M : 0) + (std::isfinite(y_min) ? P : 0) + (std::isfinite(y_max) ? P : 0);
  MoveQp qp;
  qp.hessian = Eigen::MatrixXd::Zero(nvar, nvar);
  qp.hessian.topLeftCorner(M, M) = H;
  if (soft_output) qp.hessian(M, M) = slack_quadratic_weight;
  qp.constraints = Eigen::MatrixXd::Zero(rows, nvar);
  int row = 0;
  if (u_rows) {
    for (int j = 0; j < M; ++j) qp.constraints.row(row + j).head(j + 1).setOnes();  // T
    row += M;
  }
  if (std::isfinite(y_min)) {
    qp.constraints.block(row, 0, P, M) = dynamic_matrix;
    qp.constraints.block(row, M, P, 1).setOnes();  // Theta du + e >= y_min - f
    row += P;
  }
  if (std::isfinite(y_max)) {
    qp.constraints.block(row, 0, P, M) = dynamic_matrix;
    qp.constraints.block(row, M, P, 1).setConstant(-1.0);  // Theta du - e <= y_max - f
    row += P;
  }
  qp.lbx.setConstant(nvar, -lim.du_max);
  qp.ubx.setConstant(nvar, lim.du_max);
  if (soft_output) {
    qp.lbx(M) = 0.0;
    qp.ubx(M) = kInf;
  }
  return qp;
}

inline void FillMoveQpBounds(bool u_rows, const InputLimits& lim, double u_prev, double y_min,
                             double y_max, const Eigen::VectorXd& free, int M, int P,
                             Eigen::VectorXd& lb, Eigen::VectorXd& ub) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  int row = 0;
  if (u_rows) {
    lb.head(M).setConstant(lim.u_min - u_prev);
    ub.head(M).setConstant(lim.u_max - u_prev);
    row += M;
  }
  if (std::isfinite(y_min)) {
    lb.segment(row, P).setConstant(y_min);
    lb.segment(row, P) -= free.head(P);
    ub.segment(row, P).setConstant(kInf);
    row += P;
  }
  if (std::isfinite(y_max)) {
    lb.segment(row, P).setConstant(-kInf);
    ub.segment(row, P).setConstant(y_max);
    ub.segment(row, P) -= free.head(P);
  }
}

}  // namespace pneumid::internal
