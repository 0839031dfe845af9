// Private helper of the constrained predictive controllers (QDMC in dmc.cpp,
// MPC in mpc.cpp): the row bounds of their move QP, whose constraint matrix
// both build in the same order,
//   rows 0..M-1         u_min - u_prev <= T du <= u_max - u_prev   (when u_rows)
//   next P rows         y_min - f <= Theta du + e                  (y_min finite)
//   next P rows         Theta du - e <= y_max - f                  (y_max finite)
// with f the free response over the prediction horizon. Allocates nothing.
#pragma once

#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "pneumid/control/controller.hpp"

namespace pneumid::internal {

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
