// Dynamic Matrix Control [1] and its constrained, quadratic-programming form
// QDMC [2].
//
// Model: the unit step response s_i = y(i Ts), i = 0..N, of any stable
// single-input single-output model, from its PredictionModel
// (prediction_model.hpp: a continuous transfer function sampled with an exact
// zero-order hold, a discrete one, e.g. ARX, used at its own Ts). N is the
// model horizon, after which s_i is taken as settled.
//
// Prediction over i = 1..P (P prediction horizon, M control horizon):
//   y^(k+i) = f_i + sum_{j=0}^{M-1} s_{i-j} du(k+j),   i.e.  y^ = f + A du,
// where A (P x M, A_ij = s_{i-j}, 0 for i < j) is the dynamic matrix and f the
// free response: the model's prediction with no further moves, kept in a
// vector yhat_0..yhat_N that is shifted by one sample and updated with
// s * du(k) at every step, plus the output-disturbance (bias) estimate
// d_k = y_k - yhat_0 held constant over the horizon, which makes the
// controller offset-free [1].
//
// Cost: J = sum_i q_i (w - y^(k+i))^2 + lambda sum_j r_j du(k+j)^2, with
// output weights q (default 1), move weights r (default 1) and move
// suppression lambda. Unconstrained, the first move is
//   du(k) = k' (w 1 - f),   k' = first row of (A'QA + lambda R)^-1 A'Q,
// computed once at construction, so that a step costs O(N + P).
// Constrained (QDMC [2]), the same cost is minimized subject to
//   u_min <= u(k-1) + sum_{l<=j} du(k+l) <= u_max,  |du(k+j)| <= du_max,
//   y_min - e <= y^(k+i) <= y_max + e,  e >= 0  (soft output bounds, slack e
//   penalized by rho1 e + rho2/2 e^2),
// with QpSolver (Goldfarb-Idnani, warm-started from the previous active set).
//
// [1] C. R. Cutler, B. L. Ramaker, "Dynamic matrix control - a computer
//     control algorithm", Joint Automatic Control Conf., 1980.
// [2] C. E. Garcia, A. M. Morshedi, "Quadratic programming solution of
//     dynamic matrix control (QDMC)", Chem. Eng. Commun. 46 (1986) 73-87.
// [3] E. F. Camacho, C. Bordons, Model Predictive Control, 2nd ed., 2007,
//     sec. 2.5 (DMC) and 7 (constraints).
#pragma once

#include <limits>
#include <memory>
#include <string>

#include <Eigen/Core>

#include "pneumid/control/controller.hpp"
#include "pneumid/control/prediction_model.hpp"
#include "pneumid/control/qp_solver.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// Horizons, weights, limits and (QDMC) constraint settings of the dynamic matrix controller.
struct DmcOptions {
  int P = 126;           ///< prediction horizon (samples)
  int M = 5;             ///< control horizon (samples), 1 <= M <= P
  double lambda = 2.25;  ///< move suppression (>= 0; > 0 needed when A'QA is singular)
  /// Output weights q_1..q_P (all > 0); empty means all 1.
  Eigen::VectorXd output_weights;
  /// Move weights r_1..r_M (all > 0), multiplied by lambda; empty means all 1.
  Eigen::VectorXd move_weights;
  /// Model horizon N in samples; 0 chooses PredictionModel::SettlingHorizon() (1e-9),
  /// and at least P.
  int model_horizon = 0;
  /// Input limits. Unconstrained: the computed input is clipped to them
  /// (and the model is updated with the input really applied).
  InputLimits limits;
  /// QDMC: optimize the moves subject to the limits and the soft output
  /// bounds with the QP solver, instead of clipping.
  bool constrained = false;
  /// Soft output bounds (constrained only; infinite = none).
  double y_min = -std::numeric_limits<double>::infinity();
  double y_max = std::numeric_limits<double>::infinity();  ///< soft upper output bound
  /// Slack penalty rho1 e + rho2/2 e^2 (output units; rho1 >= 0, rho2 > 0).
  double slack_linear_weight = 1e4;
  double slack_quadratic_weight = 1e2;  ///< rho2 of the slack penalty (> 0, default 100)
  QpSolverOptions qp;                   ///< the active-set QP solver's settings (constrained only)
  /// True when 1 <= M <= P, lambda is finite and >= 0, the weight vectors are empty or of
  /// sizes P and M with positive entries, model_horizon >= 0, limits are valid, y_min <=
  /// y_max, the slack weights are as stated and qp is valid; otherwise false with the
  /// reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// Dynamic matrix control (DMC, or QDMC when constrained) on the step response of a
/// stable model, with the output-disturbance feedback of the prediction.
class DmcController : public Controller {
 public:
  /// Design from a sampled model (no further discretization).
  /// @throws InvalidArgument for invalid options or an unstable model.
  DmcController(const PredictionModel& model, const DmcOptions& options);
  /// Design from a model at sample time Ts: DmcController(PredictionModel(model, Ts), options).
  /// @throws InvalidArgument for invalid options, Ts <= 0, an unstable model,
  /// or a discrete model with another sample time.
  DmcController(const TransferFunction& model, double Ts, const DmcOptions& options);
  /// Design from step coefficients s_0..s_N directly.
  DmcController(const Eigen::VectorXd& step_coefficients, double Ts, const DmcOptions& options);
  ~DmcController() override;

  double Ts() const override { return Ts_; }
  std::string Describe() const override;
  /// Calls visitor.Visit(*this).
  void Accept(ControllerVisitor& visitor) const override { visitor.Visit(*this); }

  const DmcOptions& options() const { return options_; }  ///< The options as designed.
  /// s_0..s_N.
  const Eigen::VectorXd& step_coefficients() const { return step_; }
  /// A (P x M).
  const Eigen::MatrixXd& dynamic_matrix() const { return A_; }
  /// k' (1 x P), the first row of (A'QA + lambda R)^-1 A'Q.
  const Eigen::RowVectorXd& gain() const { return gain_; }
  /// Sum of the entries of k' (the set-point's gain).
  double gain_sum() const { return gain_sum_; }
  /// A'Q (M x P), whose product with w 1 - f is minus the QP's linear term.
  const Eigen::MatrixXd& weighted_dynamic_matrix_transpose() const { return AtQ_; }
  /// The QP solver of the constrained mode (not set up when unconstrained).
  const QpSolver& qp_solver() const { return *qp_; }
  /// Free response f_1..f_P used at the last Update() (bias included).
  const Eigen::VectorXd& free_response() const { return free_; }
  /// Move applied at the last Update().
  double last_move() const { return last_du_; }
  /// Summary of the last QP (constrained mode only).
  const QpSummary& last_qp_summary() const { return qp_->summary(); }
  /// Number of constrained steps whose QP did not return kSolved (the
  /// clipped unconstrained move was applied instead).
  int qp_failures() const { return qp_failures_; }

 protected:
  void DoReset(double u0, double y0) override;
  /// One step; constant reference w = setpoint over the horizon.
  double DoUpdate(double setpoint, double measurement) override;
  void DoApplied(double u) override;

 private:
  void Build();

  DmcOptions options_;
  double Ts_ = 0.0;
  int N_ = 0;
  Eigen::VectorXd step_;  // s_0..s_N
  Eigen::MatrixXd A_;
  Eigen::RowVectorXd gain_;
  double gain_sum_ = 0.0;
  Eigen::VectorXd yhat_;  // yhat_0..yhat_N
  Eigen::VectorXd free_;  // f_1..f_P
  double u_prev_ = 0.0;
  double last_du_ = 0.0;
  // Constrained mode.
  std::unique_ptr<QpSolver> qp_;
  int nvar_ = 0;
  bool soft_output_ = false;
  Eigen::MatrixXd AtQ_;  // A'Q (M x P)
  Eigen::VectorXd g_, lb_, ub_, lbx_, ubx_, err_;
  int qp_failures_ = 0;
};

}  // namespace pneumid
