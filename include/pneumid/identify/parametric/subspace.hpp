// Subspace identification of a discrete state-space model (SISO) by the
// unifying theorem of [3]: N4SID, PO-MOESP ([1], [2] ch. 9) and CVA differ
// only in the weights W1, W2 on the oblique projection O = Y_f /_{U_f} W_p.
//
//   x(t+1) = A x(t) + B u(t),   y(t) = C x(t) + D u(t) + v(t)
//
// With horizon s and block-Hankel matrices of past/future data (j = N - 2s + 1
// columns) U_p, Y_p (samples t .. t+s-1), W_p = [U_p; Y_p] and U_f, Y_f
// (t+s .. t+2s-1), the LQ factorization
//   [U_f; W_p; Y_f] = L Q',   L = [L11 0 0; L21 L22 0; L31 L32 L33] (s, 2s, s rows)
// gives O = L32 L22^+ [L21 L22] [Q1'; Q2'] and O Pi_{U_f^perp} = L32 Q2'. The
// SVD of the weighted matrix M = U S V' ([3] Theorem 2, Table 1):
//   N4SID  W1 = I, W2 = I                 M = L32 L22^+ [L21 L22]
//   MOESP  W1 = I, W2 = Pi_{U_f^perp}     M = L32                 ([2] sec. 9.6.1)
//   CVA    W1 = (Y_f Pi_{U_f^perp} Y_f')^(-1/2) = (L32 L32' + L33 L33')^(-1/2),
//          W2 = Pi_{U_f^perp}             M = W1 L32
// gives the extended observability matrix Gamma_s = W1^(-1) U_1 S_1^(1/2) (n
// columns). C is the first row of Gamma_s and A solves the shift equation
// Gamma_s(1:s-1) A = Gamma_s(2:s) by least squares. B, D and the initial state
// x0 follow from the linear least-squares problem
//   y(t) = C A^t x0 + sum_{k<t} C A^(t-k-1) B u(k) + D u(t)
// ([2] sec. 9.2.4), as MATLAB's n4sid does for its default 'estimate' of x0.
// Memory is linear in N: L is R' of the QR factorization of the j x 4s matrix
// of Hankel rows, accumulated row block by row block (TallSkinnyQr), and the
// B, D, x0 regression is accumulated the same way while its regressors are
// propagated sample by sample. No N x N (or j x j) matrix is ever formed.
// A record whose input is constant for a long stretch (a step test) makes the
// input Hankel columns exactly collinear there; the accumulated QR treats
// columns that are zero to rounding as zero (see arx.cpp), so such records of
// any length (10^6 samples) give the same model as their informative part.
//
// [1] M. Verhaegen, Identification of the deterministic part of MIMO state
//     space models given in innovations form from input-output data,
//     Automatica 30 (1994) 61-74.
// [2] M. Verhaegen, V. Verdult, Filtering and System Identification: A Least
//     Squares Approach, Cambridge University Press, 2007.
// [3] P. Van Overschee, B. De Moor, A unifying theorem for three subspace
//     system identification algorithms, Automatica 31 (1995) 1853-1864.
#pragma once

#include <string>

#include <Eigen/Core>

#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/parametric/parametric_model.hpp"
#include "pneumid/lti/state_space.hpp"

namespace pneumid {

/// The weights W1, W2 of [3] (MATLAB n4sidOptions 'N4Weight').
enum class SubspaceWeighting {
  kMoesp,  ///< PO-MOESP: W1 = I, W2 = Pi_{U_f^perp} (the default)
  kN4sid,  ///< N4SID (Van Overschee & De Moor): W1 = W2 = I
  kCva,    ///< canonical variate analysis (Larimore): W1 = (Y_f Pi Y_f')^(-1/2)
};
/// "moesp", "n4sid", "cva".
std::string ToString(SubspaceWeighting w);
/// From "moesp", "n4sid", "cva" (case-insensitive, as MATLAB's option values).
/// @throws InvalidArgument naming the valid values.
SubspaceWeighting SubspaceWeightingFromString(const std::string& name);

/// Order, horizon and weighting of the subspace estimate (n4sid family).
struct SubspaceOptions {
  /// Model order n; 0 chooses it at the largest gap of log singular values
  /// among the first max_order.
  int order = 0;
  int max_order = 10;  ///< >= 1
  /// Block rows s (past and future horizon); 0 = max(2 n_max, 10). Must exceed the order.
  int horizon = 0;
  bool feedthrough = false;  ///< estimate D (otherwise D = 0)
  SubspaceWeighting weighting = SubspaceWeighting::kMoesp;  ///< W1/W2 (default PO-MOESP)
  /// True when order >= 0, max_order >= 1, horizon >= 0 and a given horizon exceeds the
  /// (maximum) order; otherwise false with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// Discrete state-space model from the subspace method, with its order decision.
struct SubspaceResult {
  StateSpace model;                 ///< discrete, Ts of the data
  Eigen::VectorXd singular_values;  ///< of the weighted matrix M, for the order decision
  Eigen::VectorXd x0;               ///< estimated initial state
  int order = 0;  ///< state dimension n used (given, or chosen from singular_values)
  /// kConvergence, or kFailure for non-finite matrices; message "PO-MOESP, order n, horizon
  /// s"; loss (one-step error power), warnings (unstable model).
  EstimationSummary summary;
};

/// Subspace estimate (options.weighting) from output y and input u (N
/// samples), sample time Ts seconds. A numerical failure (non-finite B, D,
/// x0, e.g. for a strongly unstable A on long data) is reported in the summary
/// (termination kFailure, B = D = 0).
/// @throws InvalidArgument for invalid options, sizes or too short data.
SubspaceResult EstimateSubspace(const Eigen::VectorXd& y, const Eigen::VectorXd& u, double Ts,
                                const SubspaceOptions& options = {});
/// From a data set (input/output columns given).
/// @throws DataError for non-uniform sampling or too few samples.
SubspaceResult EstimateSubspace(const Dataset& data, const SubspaceOptions& options = {},
                                int input = 0, int output = 0);

}  // namespace pneumid
