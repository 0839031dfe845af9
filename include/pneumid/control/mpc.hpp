// State-space model predictive control with a steady-state Kalman filter and
// an integrating disturbance model for offset-free tracking [1, 2, 3].
//
// Model: a SISO discrete state space without direct feedthrough, stable or
// integrating (poles inside the unit circle and at z = 1); an
// input delay of d samples becomes d states of a shift register
// (DelayAsStates), a continuous transfer function with input delay is sampled
// with an exact zero-order hold first (SampledStateSpace, lti/conversion.hpp;
// a design that has sampled its model already, PredictionModel, passes that
// state space on):
//   x+ = A x + B u,   y = C x.
// Disturbance models [2, 3] (augmented state z = [x; d], d scalar):
//   output:  x+ = A x + B u,        d+ = d + w_d,   y = C x + d + v
//   input:   x+ = A x + B (u + d),  d+ = d + w_d,   y = C x + v
//   none:    z = x,                                 y = C x + v
// written z+ = Az z + Bz u, y = Cz z. Both integrating models give offset-free
// tracking of constant set-points under constant disturbances and model error
// [2, sec. 3; 3, sec. 4] when the augmented pair is detectable: always for
// the output model of a stable plant, and for the input model when the plant
// has no zero at z = 1 (nonzero static gain).
//
// Estimator: steady-state Kalman filter [1, sec. 2.6.3] with process noise
// cov [x; d] = Qz = diag(state_noise I_nx, 0 (delay states), disturbance_noise)
// and measurement noise cov v = R (measurement_noise):
//   X = Az X Az' - Az X Cz' (Cz X Cz' + R)^-1 Cz X Az' + Qz    (DARE, dare.hpp)
//   L = X Cz' (Cz X Cz' + R)^-1
// At sample k: z_k|k = z_k|k-1 + L (y_k - Cz z_k|k-1); after the move
// z_k+1|k = Az z_k|k + Bz u_k.
//
// Target calculation [2, eq. 20; 3, sec. 3] from the set-point r and the
// disturbance estimate d^ at every step, with G = C (I - A)^-1 B:
//   output: u_s = (r - d^) / G,  x_s = (I - A)^-1 B u_s
//   input:  u_s = r / G - d^,    x_s = (I - A)^-1 B (u_s + d^)
//   none:   u_s = r / G,         x_s = (I - A)^-1 B u_s
// An integrating model has no G; its steady state for the output r and the
// input v = u + d (input model; v = u otherwise) solves
//   [I - A, -B; C, 0] [x_s; v_s] = [0; r]
// [2, eq. 20], which gives v_s = 0 for a model with a pole at z = 1 and no
// zero there: u_s = -d^ (input model: the input that cancels the estimated
// friction or load), u_s = 0 (none). The output model is not detectable on an
// integrating plant (the plant's mode and d both sit at z = 1 behind one
// output) and is refused.
//
// Prediction over i = 1..P with M moves du_j = u_{k+j} - u_{k+j-1}, j < M,
// and u held from k + M - 1 on [1, sec. 2.6]:
//   y^ = Psi z_k|k + Ups u_{k-1} + Theta du,
//   Psi_i = Cz Az^i,  Ups_i = sum_{j<i} Cz Az^j Bz,  Theta_il = Ups_{i-l} (l < M).
// Cost (T the M x M lower-triangular matrix of ones, 1 vectors of ones):
//   J = 1/2 [ q |y^ - r 1|^2 + lambda |du|^2 + w_u |u_{k-1} 1 + T du - u_s 1|^2 ]
//       + rho1 e + rho2/2 e^2
//     = 1/2 du' H du + g' du + rho1 e + rho2/2 e^2 + const,
//   H = q Theta'Theta + lambda I + w_u T'T,
//   g = Gz z + Gu u_{k-1} + Gr r + Gs u_s,  Gz = q Theta'Psi,
//   Gu = q Theta'Ups + w_u T'1,  Gr = -q Theta'1,  Gs = -w_u T'1.
// Unconstrained, the first move is du_0 = -e1' H^-1 g, a gain precomputed at
// construction (MpcGain): du_0 = K_r r + K_s u_s - K_z z - K_u u_{k-1}.
// Constrained (any finite bound), J is minimized subject to
//   u_min <= u_{k-1} + T du <= u_max,   |du_j| <= du_max,
//   y_min - e <= y^ <= y_max + e,  e >= 0   (soft output bounds, slack e)
// by QpSolver (Goldfarb-Idnani, qp_solver.hpp), set up once and warm-started
// from the previous active set; a step whose unconstrained moves satisfy
// every bound (with e = 0) skips the QP, their being its solution. Update()
// allocates nothing.
//
// [1] J. M. Maciejowski, Predictive Control with Constraints, Prentice Hall,
//     2002, ch. 2 (prediction, observer) and 3 (constrained QP).
// [2] G. Pannocchia, J. B. Rawlings, "Disturbance models for offset-free
//     model-predictive control", AIChE J. 49 (2003) 426-437.
// [3] K. R. Muske, T. A. Badgwell, "Disturbance modeling for offset-free
//     linear model predictive control", J. Process Control 12 (2002)
//     617-632.
#pragma once

#include <limits>
#include <memory>
#include <string>

#include <Eigen/Core>

#include "pneumid/control/controller.hpp"
#include "pneumid/control/dare.hpp"
#include "pneumid/control/prediction_model.hpp"
#include "pneumid/control/qp_solver.hpp"
#include "pneumid/lti/state_space.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// Where the integrating disturbance of the estimator acts (file comment).
enum class DisturbanceModel { kOutput, kInput, kNone };
/// "output", "input", "none".
std::string ToString(DisturbanceModel model);
/// Inverse of ToString; throws InvalidArgument listing the valid names.
DisturbanceModel DisturbanceModelFromString(const std::string& name);

/// Horizons, weights, bounds, disturbance model and estimator noise of the state-space MPC.
struct MpcOptions {
  int P = 126;                 ///< prediction horizon (samples)
  int M = 5;                   ///< control horizon (samples), 1 <= M <= P
  double output_weight = 1.0;  ///< q (> 0)
  double lambda = 2.25;        ///< move weight on du (>= 0)
  double input_weight = 0.0;   ///< w_u on (u - u_s) (>= 0)
  /// Bounds on u and du; any finite bound makes the controller solve a QP.
  InputLimits limits;
  /// Soft output bounds (infinite = none); a finite one makes it solve a QP.
  double y_min = -std::numeric_limits<double>::infinity();
  double y_max = std::numeric_limits<double>::infinity();  ///< soft upper output bound
  /// Slack penalty rho1 e + rho2/2 e^2 (rho1 >= 0, rho2 > 0).
  double slack_linear_weight = 1e4;
  double slack_quadratic_weight = 1e2;  ///< rho2 of the slack penalty (> 0, default 100)
  /// The input model is the default: an actuator's model errors (a dead
  /// band, a gain that varies with the operating point, a bias) act at its
  /// input, where this model estimates them; the output model (MATLAB's
  /// default) only shifts the predicted output and recovers more slowly from
  /// them (docs/control.md gives both on the IPA).
  DisturbanceModel disturbance = DisturbanceModel::kInput;
  /// Kalman filter noise covariances: measurement noise R (> 0, output
  /// units squared), process noise on each model state (>= 0; delay states
  /// get none) and on the integrating disturbance (> 0 with a disturbance
  /// model). The ratio disturbance_noise / measurement_noise sets how fast
  /// the disturbance estimate follows the output (1: gain 0.62 per sample on
  /// d for the output model; larger is faster, as DMC's bias at the limit).
  double measurement_noise = 1.0;
  double state_noise = 0.0;  ///< process noise variance on each model state (>= 0, default 0)
  /// Process noise variance on the disturbance d (> 0 with a disturbance model, default 1).
  double disturbance_noise = 1.0;
  DareOptions dare;    ///< the estimator DARE's stopping rule
  QpSolverOptions qp;  ///< the QP solver's settings (constrained form)
  /// True when the options are usable (1 <= M <= P, output_weight > 0, lambda and
  /// input_weight >= 0, valid limits, y_min <= y_max, slack weights and noises as stated,
  /// valid dare and qp); otherwise false and *error says why (when error is not null).
  bool IsValid(std::string* error) const;
};

/// Unconstrained first move du_0 = K_r r + K_s u_s - K_z z_k|k - K_u u_{k-1}.
struct MpcGain {
  double K_r = 0.0;        ///< gain on the set-point r (input units per output unit)
  double K_s = 0.0;        ///< gain on the target input u_s
  Eigen::RowVectorXd K_z;  ///< gain on the state estimate z_k|k (1 x nz)
  double K_u = 0.0;        ///< gain on the previous input u_{k-1}
};

/// The discrete model of `model` at Ts with its input delay as states: a
/// continuous model sampled by zoh (fractional delay exact), a discrete one
/// converted (its Ts must equal Ts), both by way of the controllable
/// canonical realization (ToStateSpace).
/// @throws InvalidArgument for Ts <= 0 or a discrete model with another Ts.
StateSpace SampledStateSpace(const TransferFunction& model, double Ts);
/// A discrete model whose input delay of d samples is replaced by d states
/// v_1..v_d (v_1+ = u, v_{i+1}+ = v_i, the model driven by v_d; D moves to C).
/// @throws InvalidArgument for a continuous model.
StateSpace DelayAsStates(const StateSpace& model);

/// State-space MPC with a steady-state Kalman filter, an integrating disturbance model and
/// (with finite bounds) a QP per sample (file comment).
class MpcController : public Controller {
 public:
  /// Design from a discrete SISO state space (input delay as extra states).
  /// @throws InvalidArgument for invalid options, a continuous, unstable
  /// (a pole outside the unit circle or repeated at z = 1), non-SISO or not
  /// strictly proper model, a zero static gain (or a zero at z = 1 of an
  /// integrating model), the output disturbance model on an integrating
  /// model, or an estimator whose DARE has no stabilizing solution.
  MpcController(const StateSpace& model, const MpcOptions& options);
  /// Design from a transfer function at sample time Ts (SampledStateSpace).
  /// @throws InvalidArgument as above, and for Ts <= 0 or a discrete model
  /// with another sample time.
  MpcController(const TransferFunction& model, double Ts, const MpcOptions& options);
  /// Design from a model a design has sampled already: its state space
  /// (PredictionModel::sampled_state_space) with the delay as states, the
  /// same model as SampledStateSpace(model.model(), model.Ts()) without a
  /// second discretization; the controller equals MpcController(model.model(),
  /// model.Ts(), options).
  /// @throws InvalidArgument as the design from a state space above.
  MpcController(const PredictionModel& model, const MpcOptions& options);
  ~MpcController() override;

  double Ts() const override { return Ts_; }
  /// e.g. "mpc P=126 M=5 lambda=2.25 disturbance=output" (+ " constrained").
  std::string Describe() const override;
  /// Calls visitor.Visit(*this).
  void Accept(ControllerVisitor& visitor) const override { visitor.Visit(*this); }

  const MpcOptions& options() const { return options_; }  ///< The options as designed.
  /// Augmented model Az, Bz, Cz (file comment); nz = nx + delay + 1 (0 for none).
  const Eigen::MatrixXd& Az() const { return Az_; }
  const Eigen::VectorXd& Bz() const { return Bz_; }     ///< Input vector Bz (nz).
  const Eigen::RowVectorXd& Cz() const { return Cz_; }  ///< Output row Cz (1 x nz).
  /// Static gain G of the plant model (infinite for an integrating model).
  double static_gain() const { return G_; }
  /// True for a model with a pole at z = 1 (file comment).
  bool integrating() const { return integrating_; }
  /// Kalman gain L (nz) and the DARE behind it (X the a priori covariance).
  const Eigen::VectorXd& kalman_gain() const { return L_; }
  /// X (nz x nz), the a priori error covariance of the estimator's DARE.
  const Eigen::MatrixXd& estimator_covariance() const { return X_; }
  /// How the estimator's DARE was solved (status, iterations, residual).
  const DareSummary& dare_summary() const { return dare_summary_; }
  /// Unconstrained first-move gain.
  const MpcGain& gain() const { return gain_; }
  /// H (M x M), Theta (P x M), Psi (P x nz).
  const Eigen::MatrixXd& hessian() const { return H_; }
  const Eigen::MatrixXd& dynamic_matrix() const { return Theta_; }      ///< Theta (P x M).
  const Eigen::MatrixXd& free_response_matrix() const { return Psi_; }  ///< Psi (P x nz).
  /// Ups_1..Ups_P, the response of y^ to u_{k-1} (P).
  const Eigen::VectorXd& input_response() const { return Ups_; }
  /// (I - A)^-1 B of the model with its delay states (nx): the steady state per unit input
  /// (an integrating model: the state at rest per unit output, v_s = 0; file comment).
  const Eigen::VectorXd& unit_steady_state() const { return xs_unit_; }
  /// Model states nx (delay states included; nz = nx + 1 with a disturbance model).
  int num_model_states() const { return nx_; }
  /// The QP's linear term g = Gz z + Gu u_{k-1} + Gr r + Gs u_s: Gz (M x nz), Gu, Gr, Gs (M).
  const Eigen::MatrixXd& gradient_state() const { return Gz_; }
  const Eigen::VectorXd& gradient_input() const { return Gu_; }     ///< Gu (M), on u_{k-1}.
  const Eigen::VectorXd& gradient_setpoint() const { return Gr_; }  ///< Gr (M), on r.
  const Eigen::VectorXd& gradient_target() const { return Gs_; }    ///< Gs (M), on u_s.
  /// The unconstrained moves -H^-1 g = Fz z + Fu u_{k-1} + Fr r + Fs u_s: Fz (M x nz), Fu, Fr, Fs
  /// (M).
  const Eigen::MatrixXd& moves_state() const { return Fz_; }
  const Eigen::VectorXd& moves_input() const { return Fu_; }     ///< Fu (M), on u_{k-1}.
  const Eigen::VectorXd& moves_setpoint() const { return Fr_; }  ///< Fr (M), on r.
  const Eigen::VectorXd& moves_target() const { return Fs_; }    ///< Fs (M), on u_s.
  /// The QP solver of the constrained form (not set up when unconstrained).
  const QpSolver& qp_solver() const { return *qp_; }
  /// True when Update() solves a QP (a finite bound on u, du or y).
  bool constrained() const { return constrained_; }

  /// z_k|k of the last Update() (z_0|-1 after Reset()).
  const Eigen::VectorXd& state_estimate() const { return z_post_; }
  /// d^ of the last Update() (0 with model none).
  double disturbance_estimate() const;
  /// u_s of the last Update().
  double target_input() const { return us_; }
  /// The M moves planned at the last Update() (unconstrained or QP).
  const Eigen::VectorXd& planned_moves() const { return moves_; }
  /// True when the last Update() solved the QP: its unconstrained moves
  /// violated a bound (otherwise they are the constrained solution too).
  bool last_step_constrained() const { return last_active_; }
  /// Summary of the last QP solved (constrained only).
  const QpSummary& last_qp_summary() const { return qp_->summary(); }
  /// Constrained steps whose QP did not return kSolved (the clipped
  /// unconstrained move was applied instead).
  int qp_failures() const { return qp_failures_; }

 protected:
  /// Observer at the steady state of u0, the disturbance estimate chosen so
  /// that the estimated output is y0 (with model none: the steady state of u0).
  void DoReset(double u0, double y0) override;
  /// One step; constant set-point over the horizon.
  double DoUpdate(double setpoint, double measurement) override;
  /// The input actually applied after the last Update() when a later layer
  /// changed it (anti-windup): the observer's prediction and u_{k-1} use it.
  /// Allocates no memory.
  void DoApplied(double u) override;

 private:
  void Build(const StateSpace& model);
  // The unconstrained moves_ satisfy the bounds on u, du and (free_ set) y.
  bool UnconstrainedMovesFeasible();

  MpcOptions options_;
  double Ts_ = 0.0;
  int nx_ = 0;  // model states incl. delay states
  int nz_ = 0;  // augmented
  Eigen::MatrixXd Az_;
  Eigen::VectorXd Bz_;
  Eigen::RowVectorXd Cz_;
  double G_ = 0.0;
  bool integrating_ = false;
  Eigen::VectorXd xs_unit_;  // (I - A)^-1 B; integrating: x_s per unit r
  Eigen::VectorXd L_;
  Eigen::MatrixXd X_;
  DareSummary dare_summary_;
  Eigen::MatrixXd Psi_, Theta_, H_;
  Eigen::VectorXd Ups_;
  Eigen::MatrixXd Gz_;
  Eigen::VectorXd Gu_, Gr_, Gs_;
  Eigen::MatrixXd Fz_;  // -H^-1 Gz, and so on: the unconstrained moves
  Eigen::VectorXd Fu_, Fr_, Fs_;
  MpcGain gain_;
  bool constrained_ = false;
  bool soft_output_ = false;
  bool u_rows_ = false;
  int nvar_ = 0;
  std::unique_ptr<QpSolver> qp_;
  // State and work arrays (sized at construction).
  Eigen::VectorXd z_prior_, z_post_, z_tmp_, g_, lb_, ub_, lbx_, ubx_, free_, moves_;
  double u_prev_ = 0.0;
  double us_ = 0.0;
  int qp_failures_ = 0;
  bool last_active_ = false;
};

}  // namespace pneumid
