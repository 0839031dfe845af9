// Initial state of a discrete state-space model that best explains measured
// data (MATLAB findstates / compare(..., 'InitialCondition', 'estimate')).
//
// The response of x(t+1) = A x(t) + B u(t - d), y(t) = C x(t) + D u(t - d)
// from x(0) = x0 is linear in x0:
//   y(t) = C A^t x0 + y_u(t),
// where y_u is the zero-state response to u (u = 0 before the record). The
// estimate solves the linear least-squares problem
//   x0 = argmin sum_t |y(t) - y_u(t) - C A^t x0|^2
// over all outputs ([1] sec. 9.2.4; the minimum-norm solution when x0 is not
// observable from the data). The rows are accumulated block by block (memory
// independent of N); the regressors C A^t of a stable model decay, so for a
// long record only its beginning carries information about x0.
//
// [1] M. Verhaegen, V. Verdult, Filtering and System Identification: A Least
//     Squares Approach, Cambridge University Press, 2007.
#pragma once

#include <Eigen/Core>

#include "pneumid/lti/state_space.hpp"

namespace pneumid {

/// Least-squares initial state of the discrete model `sys` (nx states) for
/// input u (N x nu) and output y (N x ny), samples at the model's Ts.
/// @throws InvalidArgument for a continuous model, sizes that disagree with the
///   model, N = 0 or non-finite data.
Eigen::VectorXd EstimateInitialState(const StateSpace& sys, const Eigen::MatrixXd& u,
                                     const Eigen::MatrixXd& y);

/// Output of the discrete model `sys` from initial state x0 for input u
/// (N x nu): N x ny. @throws InvalidArgument as EstimateInitialState.
Eigen::MatrixXd SimulateFromState(const StateSpace& sys, const Eigen::MatrixXd& u,
                                  const Eigen::VectorXd& x0);

}  // namespace pneumid
