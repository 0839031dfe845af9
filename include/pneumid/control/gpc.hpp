// Generalized Predictive Control [1].
//
// CARIMA model (polynomials in the backward shift q^-1, monic A and T):
//   A(q^-1) y(t) = B(q^-1) u(t-1) + T(q^-1) xi(t) / Delta,   Delta = 1 - q^-1,
// obtained from a discrete model (e.g. ARX, dead time folded into B as
// leading zeros) or from a continuous transfer function sampled with a
// zero-order hold. The model must be strictly proper (no direct feedthrough).
//
// j-step predictor, j = N1..N2, from the Diophantine identities [1, eqs. 6-8]
//   T = E_j (Delta A) + q^-j F_j,          deg E_j = j - 1,
//   E_j B = G'_j T + q^-j Gamma_j,         deg G'_j = j - 1,
// solved by the recursion E_{j+1} = E_j + f_{j,0} q^-j,
// F_{j+1} = q (F_j - f_{j,0} Delta A) starting from E_1 = 1, F_1 = q (T - Delta A):
//   y^(t+j|t) = G'_j Delta u(t+j-1) + F_j y_f(t) + Gamma_j Delta u_f(t-1),
// with the filtered signals y_f = y / T and Delta u_f = Delta u / T. The
// coefficients of G'_j are the step response g_0, g_1, ... of the model; they
// form the dynamic matrix G ((N2-N1+1) x Nu), and the free response
// f = F y_f + Gamma Delta u_f is computed from stored histories.
// Cost J = sum_{j=N1}^{N2} (w - y^(t+j))^2 + lambda sum_{j=1}^{Nu} Delta u(t+j-1)^2;
// the first move is Delta u(t) = k'(w 1 - f), k' the first row of
// (G'G + lambda I)^-1 G'.
//
// Relation to DMC (dmc.hpp), with N1 = 1, N2 = P, Nu = M and equal lambda:
//  * both use the same dynamic matrix (the step response), so the gains k'
//    coincide, and the moves coincide whenever the free responses do;
//  * noise-free, plant equal to the model, started at rest: both free
//    responses equal the model's own prediction, so the moves are identical
//    for any T (and any model horizon long enough for DMC's step response to
//    have settled);
//  * with model mismatch or disturbances, DMC's constant output-disturbance
//    (bias) estimate is the CARIMA predictor with T = A [2, sec. 4.2]: GPC
//    with T = A gives DMC's moves, GPC with T = 1 does not.
//
// [1] D. W. Clarke, C. Mohtadi, P. S. Tuffs, "Generalized predictive
//     control - Part I. The basic algorithm", Automatica 23(2) (1987) 137-148.
// [2] E. F. Camacho, C. Bordons, Model Predictive Control, 2nd ed., 2007,
//     ch. 4 (GPC) and sec. 4.2.2 (the T polynomial, DMC as a special case).
#pragma once

#include <string>

#include <Eigen/Core>

#include "pneumid/control/controller.hpp"
#include "pneumid/control/prediction_model.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// Horizons, move weighting, observer polynomial and input limits of GPC.
struct GpcOptions {
  int N1 = 1;            ///< first predicted sample (>= 1)
  int N2 = 126;          ///< last predicted sample (>= N1)
  int Nu = 5;            ///< control horizon, 1 <= Nu <= N2
  double lambda = 2.25;  ///< move weighting (>= 0)
  /// Observer polynomial T = 1 + t1 q^-1 + ... (ascending powers, t0 = 1,
  /// roots inside the unit circle); empty means T = 1.
  Eigen::VectorXd t_polynomial;
  /// Use T = A (the model's denominator), which reproduces DMC's disturbance
  /// model; overrides t_polynomial.
  bool t_equals_a = false;
  /// Input limits: the computed input is clipped to them and the histories
  /// record the input really applied.
  InputLimits limits;
  /// True when 1 <= N1 <= N2, 1 <= Nu <= N2, lambda is finite and >= 0, a given
  /// t_polynomial is monic and finite (unless t_equals_a) and limits are valid; otherwise
  /// false with the reason in *error (when error is not null).
  bool IsValid(std::string* error) const;
};

/// CARIMA polynomials in ascending powers of q^-1: y = q^-1 B / A u.
struct CarimaModel {
  Eigen::VectorXd A;  ///< monic denominator 1 + a1 q^-1 + ...
  Eigen::VectorXd B;  ///< numerator of u(t-1): b0 + b1 q^-1 + ... (delay as leading zeros)
  double Ts = 0.0;    ///< sample time, s
};

/// CARIMA form of a sampled model.
/// @throws InvalidArgument for direct feedthrough or a zero numerator.
CarimaModel ToCarima(const PredictionModel& model);
/// ToCarima(PredictionModel(model, Ts)) (continuous models by zoh).
/// @throws InvalidArgument for Ts <= 0, a discrete model with another Ts, or
/// direct feedthrough.
CarimaModel ToCarima(const TransferFunction& model, double Ts);

/// Generalized predictive control on the CARIMA form of a sampled model (unconstrained;
/// the input is clipped to the limits).
class GpcController : public Controller {
 public:
  /// Design from a sampled model (no further discretization).
  /// @throws InvalidArgument for invalid options, a T polynomial that is not
  /// monic or not stable, or the conditions of ToCarima().
  GpcController(const PredictionModel& model, const GpcOptions& options);
  /// GpcController(PredictionModel(model, Ts), options).
  GpcController(const TransferFunction& model, double Ts, const GpcOptions& options);

  double Ts() const override { return Ts_; }
  std::string Describe() const override;
  /// Calls visitor.Visit(*this).
  void Accept(ControllerVisitor& visitor) const override { visitor.Visit(*this); }

  const GpcOptions& options() const { return options_; }  ///< The options as designed.
  const CarimaModel& carima() const { return model_; }    ///< The CARIMA model A, B, Ts.
  /// Dynamic matrix G ((N2-N1+1) x Nu).
  const Eigen::MatrixXd& dynamic_matrix() const { return G_; }
  /// Rows F_j (j = N1..N2) acting on y_f(t), y_f(t-1), ...
  const Eigen::MatrixXd& f_matrix() const { return F_; }
  /// Rows Gamma_j acting on Delta u_f(t-1), Delta u_f(t-2), ...
  const Eigen::MatrixXd& gamma_matrix() const { return Gamma_; }
  /// k' (1 x (N2-N1+1)), the first row of (G'G + lambda I)^-1 G'.
  const Eigen::RowVectorXd& gain() const { return gain_; }
  /// Sum of the entries of k' (the set-point's gain).
  double gain_sum() const { return gain_sum_; }
  /// The observer polynomial T in use (ascending powers of q^-1, t0 = 1).
  const Eigen::VectorXd& t_polynomial() const { return T_; }
  /// Lengths of the stored histories of y_f and Delta u_f.
  Eigen::Index y_history_length() const { return yf_hist_.size(); }
  Eigen::Index move_history_length() const { return duf_hist_.size(); }  ///< See above.
  /// Free response f = F y_f + Gamma Delta u_f (N2-N1+1 entries) of the last Update().
  const Eigen::VectorXd& free_response() const { return free_; }
  /// Delta u of the last Update() as applied (clipped, corrected by Applied()), input units.
  double last_move() const { return last_du_; }

 protected:
  void DoReset(double u0, double y0) override;
  double DoUpdate(double setpoint, double measurement) override;
  void DoApplied(double u) override;

 private:
  GpcOptions options_;
  double Ts_ = 0.0;
  CarimaModel model_;
  Eigen::VectorXd T_;
  Eigen::MatrixXd G_, F_, Gamma_;
  Eigen::RowVectorXd gain_;
  double gain_sum_ = 0.0;
  Eigen::VectorXd yf_hist_;   // y_f(t), y_f(t-1), ...
  Eigen::VectorXd duf_hist_;  // Delta u_f(t-1), Delta u_f(t-2), ...
  Eigen::VectorXd free_;
  double u_prev_ = 0.0;
  double last_du_ = 0.0;
};

}  // namespace pneumid
