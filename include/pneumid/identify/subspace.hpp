// Subspace identification of a discrete state-space model by PO-MOESP
// (past-output multivariable output-error state space, [1], [2] ch. 9), SISO.
//
//   x(t+1) = A x(t) + B u(t),   y(t) = C x(t) + D u(t) + v(t)
//
// With horizon s and block-Hankel matrices of past/future data (j = N - 2s + 1
// columns) U_p, Y_p (samples t .. t+s-1) and U_f, Y_f (t+s .. t+2s-1), the LQ
// factorization
//   [U_f; U_p; Y_p; Y_f] = L Q',   L lower triangular (4s x 4s)
// gives the extended observability matrix from the SVD of the block L_42
// (rows Y_f, columns [U_p; Y_p]) = U S V':  Gamma_s = U_1 S_1^(1/2), n columns
// ([2] sec. 9.6.1). C is the first row of Gamma_s and A solves the shift
// equation Gamma_s(1:s-1) A = Gamma_s(2:s) by least squares. B, D and the
// initial state x0 follow from the linear least-squares problem
//   y(t) = C A^t x0 + sum_{k<t} C A^(t-k-1) B u(k) + D u(t)
// ([2] sec. 9.2.4).
// Memory is linear in N: L is R' of the QR factorization of the j x 4s matrix
// of Hankel rows, accumulated row block by row block (TallSkinnyQr), and the
// B, D, x0 regression is accumulated the same way while its regressors are
// propagated sample by sample. No N x N (or j x j) matrix is ever formed.
//
// [1] M. Verhaegen, Identification of the deterministic part of MIMO state
//     space models given in innovations form from input-output data,
//     Automatica 30 (1994) 61-74.
// [2] M. Verhaegen, V. Verdult, Filtering and System Identification: A Least
//     Squares Approach, Cambridge University Press, 2007.
#pragma once

#include <string>

#include <Eigen/Core>

#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/parametric_model.hpp"
#include "pneumid/lti/state_space.hpp"

namespace pneumid {

struct SubspaceOptions {
  /// Model order n; 0 chooses it at the largest gap of log singular values
  /// among the first max_order.
  int order = 0;
  int max_order = 10;  ///< >= 1
  /// Block rows s (past and future horizon); 0 = max(2 n_max, 10). Must exceed the order.
  int horizon = 0;
  bool feedthrough = false;  ///< estimate D (otherwise D = 0)
  bool IsValid(std::string* error) const;
};

struct SubspaceResult {
  StateSpace model;                 ///< discrete, Ts of the data
  Eigen::VectorXd singular_values;  ///< of L_42, for the order decision
  Eigen::VectorXd x0;               ///< estimated initial state
  int order = 0;
  EstimationSummary summary;
};

/// PO-MOESP from output y and input u (N samples), sample time Ts seconds.
/// @throws InvalidArgument for invalid options, sizes or too short data.
SubspaceResult EstimateSubspace(const Eigen::VectorXd& y, const Eigen::VectorXd& u, double Ts,
                                const SubspaceOptions& options = {});
/// From a data set (input/output columns given).
/// @throws DataError for non-uniform sampling or too few samples.
SubspaceResult EstimateSubspace(const Dataset& data, const SubspaceOptions& options = {},
                                int input = 0, int output = 0);

}  // namespace pneumid
