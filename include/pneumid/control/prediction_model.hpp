// The sampled prediction model shared by the predictive controllers (DMC,
// GPC), the tuning rules and the controller factory.
//
// A design samples its model once, at the controller's period Ts, and passes
// the result down: a continuous model G(s) exp(-theta s) is discretized with
// an exact zero-order hold (delay included, lti/conversion.hpp C2D), a
// discrete one (e.g. ARX) is used at its own Ts. The discretization is done
// on the controllable canonical realization (ToStateSpace); that discrete
// state space is kept (sampled_state_space(), the state-space MPC's model,
// mpc.hpp) and the sampled transfer function is its transfer function, as
// C2D of the transfer function computes it. From the sampled model
//   b(q^-1) / a(q^-1) q^-d
// follow
//   * the unit step-response coefficients s_0..s_n, s_i = y(i Ts) for u = 1
//     from k = 0 on, by the difference equation
//       a_0 s_k = sum_i b_i [k - d - i >= 0] - sum_{i>=1} a_i s_{k-i};
//   * the model horizon N: the smallest N with |s_N - s_inf| <= tol |s_inf|
//     (s_inf the static gain), after which s_i is taken as settled;
//   * the P x M dynamic matrix A_ij = s_{i+1-j} (0 for j > i), rows the
//     predicted outputs y(k+1..k+P), columns the moves du(k..k+M-1) [1, 2]:
//       y^ = f + A du.
// The Shridhar-Cooper rule (tuning.hpp) takes its lambda from A'A, DMC
// (dmc.hpp) its predictor from s and A, GPC (gpc.hpp) its CARIMA polynomials
// from the sampled model.
//
// [1] C. R. Cutler, B. L. Ramaker, "Dynamic matrix control - a computer
//     control algorithm", Joint Automatic Control Conf., 1980.
// [2] E. F. Camacho, C. Bordons, Model Predictive Control, 2nd ed., 2007,
//     sec. 2.5.
#pragma once

#include <Eigen/Core>

#include "pneumid/lti/state_space.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// Largest prediction horizon (samples) the predictive controllers take
/// (DMC, GPC, MPC options and the tuning rules): beyond it the dynamic
/// matrix alone needs gigabytes, and a sample time that fine for the plant's
/// time scale is the thing to change.
inline constexpr int kMaxPredictionHorizon = 100000;
/// Largest control horizon (moves): the QP's Hessian is M x M.
inline constexpr int kMaxControlHorizon = 1000;

/// A model sampled once at the controller's period Ts, with its step response, model
/// horizon and dynamic matrix (file comment).
class PredictionModel {
 public:
  /// Samples `model` at Ts (the only discretization of a design): zoh for a
  /// continuous model, unchanged for a discrete one.
  /// @throws InvalidArgument for Ts <= 0 or not finite, a discrete model with
  /// another sample time (relative 1e-9), or a zero leading denominator
  /// coefficient of the sampled model.
  PredictionModel(const TransferFunction& model, double Ts);

  /// The model as given (continuous or discrete).
  const TransferFunction& model() const { return model_; }
  /// The model sampled at Ts (discrete).
  const TransferFunction& sampled() const { return sampled_; }
  /// The model sampled at Ts as a discrete state space, its delay a whole
  /// number of samples of input delay: the zoh discretization of the
  /// controllable canonical realization of a continuous model (sampled() is
  /// its transfer function), the realization of a discrete one. With the
  /// delay as states (DelayAsStates, mpc.hpp) it equals SampledStateSpace(
  /// model(), Ts()) exactly: the MPC of a design uses it instead of sampling
  /// the model again.
  const StateSpace& sampled_state_space() const { return sampled_state_space_; }
  /// Controller sample time (s).
  double Ts() const { return Ts_; }
  /// Stability of the sampled model (poles inside the unit circle).
  bool IsStable() const;

  /// Unit step-response coefficients s_0..s_n (n + 1 values).
  /// @throws InvalidArgument for n < 1.
  Eigen::VectorXd StepResponse(int n) const;
  /// Smallest model horizon N <= max_n with |s_N - s_inf| <= tol |s_inf|.
  /// @throws InvalidArgument for an unstable model, a zero or infinite static
  /// gain, tol <= 0 or max_n < 1.
  int SettlingHorizon(double tol = 1e-9, int max_n = 5000) const;
  /// The P x M dynamic matrix of s_0..s_P (see the file comment).
  /// @throws InvalidArgument for P < 1, M < 1 or M > P.
  Eigen::MatrixXd DynamicMatrix(int P, int M) const;

 private:
  TransferFunction model_;
  StateSpace sampled_state_space_;
  TransferFunction sampled_;
  double Ts_ = 0.0;
};

/// P x M dynamic matrix A_ij = s_{i+1-j} from step coefficients s_0..s_N
/// (entries beyond N are taken as s_N).
/// @throws InvalidArgument for P < 1, M < 1, M > P or empty coefficients.
Eigen::MatrixXd DynamicMatrix(const Eigen::VectorXd& step, int P, int M);

}  // namespace pneumid
