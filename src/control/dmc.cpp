#include "pneumid/control/dmc.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include "move_qp_bounds.hpp"
#include "pneumid/common/check.hpp"

namespace pneumid {

bool DmcOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (P < 1) return fail(fmt::format("prediction horizon P must be >= 1, got {}", P));
  if (M < 1 || M > P) return fail(fmt::format("need 1 <= M <= P, got M = {}, P = {}", M, P));
  if (P > kMaxPredictionHorizon || M > kMaxControlHorizon)
    return fail(fmt::format(
        "horizons P = {} and M = {} exceed the largest ones taken, P = {} and M = {} (a sample "
        "time much shorter than the plant's time scale: choose a longer one)",
        P, M, kMaxPredictionHorizon, kMaxControlHorizon));
  if (!(lambda >= 0.0) || !std::isfinite(lambda))
    return fail(fmt::format("lambda must be finite and >= 0, got {}", lambda));
  if (output_weights.size() != 0 &&
      (output_weights.size() != P || !(output_weights.array() > 0.0).all() ||
       !output_weights.allFinite()))
    return fail(fmt::format("output_weights must have P = {} positive entries (or none), got {}", P,
                            output_weights.size()));
  if (move_weights.size() != 0 &&
      (move_weights.size() != M || !(move_weights.array() > 0.0).all() ||
       !move_weights.allFinite()))
    return fail(fmt::format("move_weights must have M = {} positive entries (or none), got {}", M,
                            move_weights.size()));
  if (model_horizon < 0)
    return fail(fmt::format("model_horizon must be >= 0, got {}", model_horizon));
  std::string e;
  if (!limits.IsValid(&e)) return fail(e);
  if (std::isnan(y_min) || std::isnan(y_max) || y_min > y_max)
    return fail(fmt::format("need y_min <= y_max, got {} and {}", y_min, y_max));
  if (!(slack_linear_weight >= 0.0) || !(slack_quadratic_weight > 0.0))
    return fail(fmt::format("slack weights must be >= 0 (linear) and > 0 (quadratic), got {}, {}",
                            slack_linear_weight, slack_quadratic_weight));
  if (!qp.IsValid(&e)) return fail("qp: " + e);
  return true;
}

DmcController::DmcController(const PredictionModel& model, const DmcOptions& options)
    : options_(options), Ts_(model.Ts()) {
  std::string error;
  PNEUMID_CHECK(options_.IsValid(&error), "invalid DMC options: {}", error);
  int N = options_.model_horizon;
  if (N == 0)
    N = model.SettlingHorizon();
  else
    PNEUMID_CHECK(model.IsStable(), "DMC needs a stable model; {} is not stable",
                  model.model().ToString());
  N = std::max(N, options_.P);
  step_ = model.StepResponse(N);
  Build();
}

DmcController::DmcController(const TransferFunction& model, double Ts, const DmcOptions& options)
    : DmcController(PredictionModel(model, Ts), options) {}

DmcController::DmcController(const Eigen::VectorXd& step_coefficients, double Ts,
                             const DmcOptions& options)
    : options_(options), Ts_(Ts) {
  std::string error;
  PNEUMID_CHECK(options_.IsValid(&error), "invalid DMC options: {}", error);
  PNEUMID_CHECK(Ts > 0.0 && std::isfinite(Ts), "sample time must be positive, got Ts = {}", Ts);
  PNEUMID_CHECK(step_coefficients.size() >= 2 && step_coefficients.allFinite(),
                "need finite step coefficients s_0..s_N with N >= 1, got {} values",
                step_coefficients.size());
  int N = static_cast<int>(step_coefficients.size()) - 1;
  if (options_.model_horizon > 0) N = std::min(N, options_.model_horizon);
  const int N_eff = std::max(N, options_.P);
  step_.resize(N_eff + 1);
  for (int i = 0; i <= N_eff; ++i) step_(i) = step_coefficients(std::min(i, N));
  Build();
}

DmcController::~DmcController() = default;

void DmcController::Build() {
  const int P = options_.P, M = options_.M;
  N_ = static_cast<int>(step_.size()) - 1;
  A_ = DynamicMatrix(step_, P, M);
  const Eigen::VectorXd q =
      options_.output_weights.size() ? options_.output_weights : Eigen::VectorXd::Ones(P);
  const Eigen::VectorXd r =
      options_.move_weights.size() ? options_.move_weights : Eigen::VectorXd::Ones(M);
  AtQ_ = A_.transpose() * q.asDiagonal();
  Eigen::MatrixXd H = AtQ_ * A_;
  H.diagonal() += options_.lambda * r;
  Eigen::LLT<Eigen::MatrixXd> llt(H);
  PNEUMID_CHECK(llt.info() == Eigen::Success && llt.matrixLLT().diagonal().minCoeff() >
                                                    1e-10 * std::sqrt(H.diagonal().maxCoeff()),
                "A'QA + lambda R is singular (the model's dead time may exceed the horizon); "
                "increase lambda (now {}) or P (now {})",
                options_.lambda, P);
  const Eigen::MatrixXd Kmat = llt.solve(AtQ_);
  gain_ = Kmat.row(0);
  gain_sum_ = gain_.sum();
  yhat_.setZero(N_ + 1);
  free_.setZero(P);
  err_.setZero(P);

  if (options_.constrained) {
    soft_output_ = std::isfinite(options_.y_min) || std::isfinite(options_.y_max);
    const internal::MoveQp move_qp = internal::BuildMoveQp(
        H, A_, options_.limits, options_.y_min, options_.y_max, options_.slack_quadratic_weight);
    nvar_ = static_cast<int>(move_qp.hessian.rows());
    qp_ = std::make_unique<QpSolver>(options_.qp);
    PNEUMID_CHECK(qp_->Setup(move_qp.hessian, move_qp.constraints),
                  "the QDMC Hessian is not positive definite: {}", qp_->summary().BriefReport());
    g_.setZero(nvar_);
    lb_.setZero(move_qp.constraints.rows());
    ub_.setZero(move_qp.constraints.rows());
    lbx_ = move_qp.lbx;
    ubx_ = move_qp.ubx;
  } else {
    qp_ = std::make_unique<QpSolver>(options_.qp);  // summary reports "not set up"
  }
  Reset();
}

void DmcController::DoReset(double u0, double y0) {
  yhat_.setConstant(y0);
  free_.setConstant(y0);
  u_prev_ = u0;
  last_du_ = 0.0;
  qp_failures_ = 0;
  if (qp_) qp_->ClearWarmStart();
}

double DmcController::DoUpdate(double setpoint, double measurement) {
  const int P = options_.P, M = options_.M;
  const double bias = measurement - yhat_(0);
  for (int i = 0; i < P; ++i) free_(i) = yhat_(i + 1) + bias;
  double du = gain_sum_ * setpoint - gain_.dot(free_);
  if (!std::isfinite(du)) return du;  // an overflow: a fault (Controller::Update)
  if (options_.constrained) {
    const InputLimits& lim = options_.limits;
    err_.setConstant(setpoint);
    err_ -= free_;
    g_.head(M).noalias() = -AtQ_ * err_;
    if (soft_output_) g_(M) = options_.slack_linear_weight;
    if (!g_.allFinite()) return std::numeric_limits<double>::quiet_NaN();
    internal::FillMoveQpBounds(std::isfinite(lim.u_min) || std::isfinite(lim.u_max), lim, u_prev_,
                               options_.y_min, options_.y_max, free_, M, P, lb_, ub_);
    const QpSummary& s = qp_->Solve(g_, lb_, ub_, lbx_, ubx_);
    if (s.status == QpStatus::kSolved) {
      du = qp_->x()(0);
    } else {
      ++qp_failures_;
    }
  }
  const double u = options_.limits.Clip(u_prev_ + du, u_prev_);
  du = u - u_prev_;
  // Shift the prediction one sample and add the effect of the move.
  double* y = yhat_.data();
  const double* s = step_.data();
  for (int i = 0; i < N_; ++i) y[i] = y[i + 1] + s[i + 1] * du;
  y[N_] += s[N_] * du;
  u_prev_ = u;
  last_du_ = du;
  return u;
}

void DmcController::DoApplied(double u) {
  const double delta = u - u_prev_;
  if (delta == 0.0 || !std::isfinite(delta)) return;
  // The prediction was shifted with the move du; it should have been du + delta.
  double* y = yhat_.data();
  const double* s = step_.data();
  for (int i = 0; i < N_; ++i) y[i] += s[i + 1] * delta;
  y[N_] += s[N_] * delta;
  u_prev_ = u;
  last_du_ += delta;
}

std::string DmcController::Describe() const {
  return fmt::format("dmc P={} M={} lambda={:g} N={}{}", options_.P, options_.M, options_.lambda,
                     N_, options_.constrained ? " constrained" : "");
}

}  // namespace pneumid
