#include "pneumid/control/mpc.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include "move_qp_bounds.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"
#include "pneumid/lti/conversion.hpp"

namespace pneumid {

namespace {
constexpr EnumName<DisturbanceModel> kDisturbanceModelNames[] = {
    {DisturbanceModel::kOutput, "output"},
    {DisturbanceModel::kInput, "input"},
    {DisturbanceModel::kNone, "none"},
};
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

std::string ToString(DisturbanceModel v) {
  return std::string(EnumToString(kDisturbanceModelNames, v));
}

DisturbanceModel DisturbanceModelFromString(const std::string& name) {
  return EnumFromString(kDisturbanceModelNames, name, "disturbance model");
}

bool MpcOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (P < 1) return fail(fmt::format("prediction horizon P must be >= 1, got {}", P));
  if (M < 1 || M > P) return fail(fmt::format("need 1 <= M <= P, got M = {}, P = {}", M, P));
  if (!(output_weight > 0.0) || !std::isfinite(output_weight))
    return fail(fmt::format("output weight q must be finite and > 0, got {}", output_weight));
  if (!(lambda >= 0.0) || !std::isfinite(lambda))
    return fail(fmt::format("lambda must be finite and >= 0, got {}", lambda));
  if (!(input_weight >= 0.0) || !std::isfinite(input_weight))
    return fail(fmt::format("input weight must be finite and >= 0, got {}", input_weight));
  std::string e;
  if (!limits.IsValid(&e)) return fail(e);
  if (std::isnan(y_min) || std::isnan(y_max) || y_min > y_max)
    return fail(fmt::format("need y_min <= y_max, got {} and {}", y_min, y_max));
  if (!(slack_linear_weight >= 0.0) || !std::isfinite(slack_linear_weight) ||
      !(slack_quadratic_weight > 0.0) || !std::isfinite(slack_quadratic_weight))
    return fail(fmt::format("slack weights must be >= 0 (linear) and > 0 (quadratic), got {}, {}",
                            slack_linear_weight, slack_quadratic_weight));
  if (!(measurement_noise > 0.0) || !std::isfinite(measurement_noise))
    return fail(fmt::format("measurement noise must be finite and > 0, got {}", measurement_noise));
  if (!(state_noise >= 0.0) || !std::isfinite(state_noise))
    return fail(fmt::format("state noise must be finite and >= 0, got {}", state_noise));
  if (disturbance != DisturbanceModel::kNone &&
      (!(disturbance_noise > 0.0) || !std::isfinite(disturbance_noise)))
    return fail(
        fmt::format("disturbance noise must be finite and > 0 with the {} disturbance "
                    "model, got {}",
                    ToString(disturbance), disturbance_noise));
  if (!dare.IsValid(&e)) return fail("dare: " + e);
  if (!qp.IsValid(&e)) return fail("qp: " + e);
  return true;
}

StateSpace SampledStateSpace(const TransferFunction& model, double Ts) {
  PNEUMID_CHECK(Ts > 0.0 && std::isfinite(Ts), "sample time must be positive, got Ts = {}", Ts);
  if (model.IsDiscrete()) {
    PNEUMID_CHECK(std::abs(model.Ts() - Ts) <= 1e-9 * Ts,
                  "the discrete model has Ts = {} s, the controller Ts = {} s", model.Ts(), Ts);
    return DelayAsStates(ToStateSpace(model));
  }
  return DelayAsStates(C2D(ToStateSpace(model), Ts, DiscretizationMethod::kZoh));
}

StateSpace DelayAsStates(const StateSpace& model) {
  PNEUMID_CHECK(model.IsDiscrete(), "DelayAsStates needs a discrete model (Ts > 0)");
  const int d = static_cast<int>(std::lround(model.delay() / model.Ts()));
  if (d == 0) return StateSpace(model.A(), model.B(), model.C(), model.D(), model.Ts(), 0.0);
  const int nx = model.num_states(), nu = model.num_inputs(), ny = model.num_outputs();
  const int n = nx + d * nu;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(n, nu);
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(ny, n);
  A.topLeftCorner(nx, nx) = model.A();
  const int last = nx + (d - 1) * nu;  // v_d
  A.block(0, last, nx, nu) = model.B();
  for (int i = 1; i < d; ++i)  // v_{i+1}+ = v_i
    A.block(nx + i * nu, nx + (i - 1) * nu, nu, nu).setIdentity();
  B.block(nx, 0, nu, nu).setIdentity();  // v_1+ = u
  C.leftCols(nx) = model.C();
  C.block(0, last, ny, nu) = model.D();
  return StateSpace(A, B, C, Eigen::MatrixXd::Zero(ny, nu), model.Ts(), 0.0);
}

MpcController::MpcController(const StateSpace& model, const MpcOptions& options)
    : options_(options) {
  Build(model);
}

MpcController::MpcController(const TransferFunction& model, double Ts, const MpcOptions& options)
    : options_(options) {
  Build(SampledStateSpace(model, Ts));
}

MpcController::~MpcController() = default;

void MpcController::Build(const StateSpace& model_in) {
  std::string error;
  PNEUMID_CHECK(options_.IsValid(&error), "invalid MPC options: {}", error);
  PNEUMID_CHECK(model_in.IsDiscrete(),
                "MPC needs a discrete model (Ts > 0); sample a continuous one first "
                "(SampledStateSpace or the TransferFunction constructor)");
  PNEUMID_CHECK(model_in.num_inputs() == 1 && model_in.num_outputs() == 1,
                "MPC needs a single-input single-output model, got {} inputs and {} outputs",
                model_in.num_inputs(), model_in.num_outputs());
  PNEUMID_CHECK(model_in.num_states() >= 1, "MPC needs a model with at least one state");
  PNEUMID_CHECK(model_in.A().allFinite() && model_in.B().allFinite() && model_in.C().allFinite() &&
                    model_in.D().allFinite(),
                "the model's matrices must be finite");
  const StateSpace model = DelayAsStates(model_in);
  PNEUMID_CHECK(model.D()(0, 0) == 0.0,
                "MPC needs a strictly proper model: D = {} makes y_k depend on u_k, which is "
                "computed from y_k (use an input delay of at least one sample, e.g. nk >= 1)",
                model.D()(0, 0));
  // Stable, or integrating: one pole at z = 1, the others inside the circle.
  const Eigen::VectorXcd poles = model.Poles();
  int at_one = 0;
  double outside = 0.0;
  for (Eigen::Index i = 0; i < poles.size(); ++i) {
    if (std::abs(poles(i) - 1.0) <= 1e-9)
      ++at_one;
    else
      outside = std::max(outside, std::abs(poles(i)));
  }
  PNEUMID_CHECK(outside < 1.0 && at_one <= 1,
                "MPC needs a stable or integrating model; the model has {}",
                at_one > 1 ? fmt::format("{} poles at z = 1", at_one)
                           : fmt::format("a pole of magnitude {:.6g} (>= 1)", outside));
  integrating_ = at_one == 1;
  Ts_ = model.Ts();
  const Eigen::MatrixXd& A = model.A();
  nx_ = model.num_states();
  if (!integrating_) {
    xs_unit_ = (Eigen::MatrixXd::Identity(nx_, nx_) - A).partialPivLu().solve(model.B().col(0));
    G_ = model.C().row(0).dot(xs_unit_);
    PNEUMID_CHECK(std::isfinite(G_) && std::abs(G_) > 1e-12 * std::max(1.0, xs_unit_.norm()),
                  "MPC needs a model with a nonzero static gain, got {}", G_);
  } else {
    // [I - A, -B; C, 0] [x_s; v_s] = [0; r] (file comment): x_s per unit r.
    Eigen::MatrixXd T = Eigen::MatrixXd::Zero(nx_ + 1, nx_ + 1);
    T.topLeftCorner(nx_, nx_) = Eigen::MatrixXd::Identity(nx_, nx_) - A;
    T.topRightCorner(nx_, 1) = -model.B();
    T.bottomLeftCorner(1, nx_) = model.C();
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(T);
    // A pole at z = 1 cancelled (to rounding) by a zero there, as least
    // squares can fit on noise-free data, leaves T all but singular.
    PNEUMID_CHECK(lu.isInvertible() && lu.rcond() > 1e-9,
                  "MPC needs a stable model, or an integrating one without a zero at z = 1; "
                  "the model has a pole at z = 1 {}",
                  lu.isInvertible()
                      ? fmt::format("all but cancelled by a zero (rcond {:.3g})", lu.rcond())
                      : std::string("cancelled by a zero"));
    const Eigen::VectorXd col = lu.solve(Eigen::VectorXd::Unit(nx_ + 1, nx_));
    xs_unit_ = col.head(nx_);
    G_ = std::numeric_limits<double>::infinity();
    PNEUMID_CHECK(options_.disturbance != DisturbanceModel::kOutput,
                  "MPC on an integrating model needs the input disturbance model (or none): an "
                  "output disturbance is not detectable behind the model's own integrator");
    PNEUMID_CHECK(options_.disturbance != DisturbanceModel::kNone || options_.state_noise > 0.0,
                  "MPC on an integrating model without a disturbance model needs process noise "
                  "on its states (state_noise > 0, --state-noise): the Kalman filter has nothing "
                  "else to follow the integrator with");
  }

  // Augmented model.
  const DisturbanceModel dm = options_.disturbance;
  const int nd = dm == DisturbanceModel::kNone ? 0 : 1;
  nz_ = nx_ + nd;
  Az_.setZero(nz_, nz_);
  Az_.topLeftCorner(nx_, nx_) = A;
  Bz_.setZero(nz_);
  Bz_.head(nx_) = model.B().col(0);
  Cz_.setZero(nz_);
  Cz_.head(nx_) = model.C().row(0);
  if (dm == DisturbanceModel::kOutput) {
    Az_(nx_, nx_) = 1.0;
    Cz_(nx_) = 1.0;
  } else if (dm == DisturbanceModel::kInput) {
    Az_.block(0, nx_, nx_, 1) = model.B();
    Az_(nx_, nx_) = 1.0;
  }

  // Steady-state Kalman filter: X = DARE(Az', Cz', Qz, R).
  const int n_plant = model_in.num_states();  // delay states get no process noise
  Eigen::MatrixXd Qz = Eigen::MatrixXd::Zero(nz_, nz_);
  Qz.diagonal().head(n_plant).setConstant(options_.state_noise);
  if (nd) Qz(nx_, nx_) = options_.disturbance_noise;
  const Eigen::MatrixXd Rm = Eigen::MatrixXd::Constant(1, 1, options_.measurement_noise);
  const DareResult dare = SolveDare(Az_.transpose(), Cz_.transpose(), Qz, Rm, options_.dare);
  dare_summary_ = dare.summary;
  PNEUMID_CHECK(dare.summary.status == DareStatus::kConverged,
                "the Kalman filter cannot be designed ({}): the disturbance model '{}' may not "
                "be detectable for this plant",
                dare.summary.BriefReport(), ToString(dm));
  X_ = dare.X;
  L_ = X_ * Cz_.transpose() / (Cz_.dot(X_ * Cz_.transpose()) + options_.measurement_noise);

  // Prediction matrices.
  const int P = options_.P, M = options_.M;
  Psi_.resize(P, nz_);
  Ups_.resize(P);
  Eigen::RowVectorXd row = Cz_;  // Cz Az^(i-1)
  double s = 0.0;
  for (int i = 0; i < P; ++i) {
    s += row.dot(Bz_);
    Ups_(i) = s;  // Ups_{i+1}
    row = (row * Az_).eval();
    Psi_.row(i) = row;  // Cz Az^(i+1)
  }
  Theta_.setZero(P, M);
  for (int l = 0; l < M; ++l) Theta_.col(l).tail(P - l) = Ups_.head(P - l);

  const double q = options_.output_weight, wu = options_.input_weight;
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(M, M);
  for (int j = 0; j < M; ++j) T.row(j).head(j + 1).setOnes();
  const Eigen::VectorXd Tt1 = T.transpose() * Eigen::VectorXd::Ones(M);
  H_ = q * Theta_.transpose() * Theta_;
  H_.diagonal().array() += options_.lambda;
  H_ += wu * T.transpose() * T;
  Eigen::LLT<Eigen::MatrixXd> llt(H_);
  PNEUMID_CHECK(llt.info() == Eigen::Success && llt.matrixLLT().diagonal().minCoeff() >
                                                    1e-10 * std::sqrt(H_.diagonal().maxCoeff()),
                "the MPC Hessian q Theta'Theta + lambda I is singular (the model's dead time "
                "may exceed the horizon); increase lambda (now {}) or P (now {})",
                options_.lambda, P);
  Gz_ = q * Theta_.transpose() * Psi_;
  Gu_ = q * Theta_.transpose() * Ups_ + wu * Tt1;
  Gr_ = -q * Theta_.transpose() * Eigen::VectorXd::Ones(P);
  Gs_ = -wu * Tt1;
  // F = -H^-1 G: the unconstrained moves; the gain is its first row.
  Fz_ = -llt.solve(Gz_);
  Fu_ = -llt.solve(Gu_);
  Fr_ = -llt.solve(Gr_);
  Fs_ = -llt.solve(Gs_);
  gain_.K_z = -Fz_.row(0);
  gain_.K_u = -Fu_(0);
  gain_.K_r = Fr_(0);
  gain_.K_s = Fs_(0);

  // Constrained form.
  const InputLimits& lim = options_.limits;
  soft_output_ = std::isfinite(options_.y_min) || std::isfinite(options_.y_max);
  u_rows_ = std::isfinite(lim.u_min) || std::isfinite(lim.u_max);
  constrained_ = u_rows_ || std::isfinite(lim.du_max) || soft_output_;
  qp_ = std::make_unique<QpSolver>(options_.qp);
  moves_.setZero(M);
  z_prior_.setZero(nz_);
  z_post_.setZero(nz_);
  z_tmp_.setZero(nz_);
  if (constrained_) {
    nvar_ = M + (soft_output_ ? 1 : 0);
    const int rows = (u_rows_ ? M : 0) + (std::isfinite(options_.y_min) ? P : 0) +
                     (std::isfinite(options_.y_max) ? P : 0);
    Eigen::MatrixXd Hq = Eigen::MatrixXd::Zero(nvar_, nvar_);
    Hq.topLeftCorner(M, M) = H_;
    if (soft_output_) Hq(M, M) = options_.slack_quadratic_weight;
    Eigen::MatrixXd Cq = Eigen::MatrixXd::Zero(rows, nvar_);
    int r = 0;
    if (u_rows_) {
      Cq.block(0, 0, M, M) = T;
      r += M;
    }
    if (std::isfinite(options_.y_min)) {
      Cq.block(r, 0, P, M) = Theta_;
      Cq.block(r, M, P, 1).setOnes();  // Theta du + e >= y_min - f
      r += P;
    }
    if (std::isfinite(options_.y_max)) {
      Cq.block(r, 0, P, M) = Theta_;
      Cq.block(r, M, P, 1).setConstant(-1.0);  // Theta du - e <= y_max - f
      r += P;
    }
    PNEUMID_CHECK(qp_->Setup(Hq, Cq), "the MPC QP Hessian is not positive definite: {}",
                  qp_->summary().BriefReport());
    g_.setZero(nvar_);
    lb_.setZero(rows);
    ub_.setZero(rows);
    lbx_.setConstant(nvar_, -lim.du_max);
    ubx_.setConstant(nvar_, lim.du_max);
    if (soft_output_) {
      lbx_(M) = 0.0;
      ubx_(M) = kInf;
    }
    free_.setZero(P);
  }
  Reset();
}

void MpcController::DoReset(double u0, double y0) {
  switch (options_.disturbance) {
    case DisturbanceModel::kOutput:
      z_prior_.head(nx_) = xs_unit_ * u0;
      z_prior_(nx_) = y0 - Cz_.head(nx_).dot(z_prior_.head(nx_));
      break;
    case DisturbanceModel::kInput: {
      // Integrating: at rest at y0, the disturbance cancelling u0.
      const double d = integrating_ ? -u0 : y0 / G_ - u0;
      z_prior_.head(nx_) = integrating_ ? Eigen::VectorXd(xs_unit_ * y0) : xs_unit_ * (u0 + d);
      z_prior_(nx_) = d;
      break;
    }
    case DisturbanceModel::kNone:
      z_prior_ = integrating_ ? Eigen::VectorXd(xs_unit_ * y0) : xs_unit_ * u0;
      break;
  }
  z_post_ = z_prior_;
  u_prev_ = u0;
  us_ = u0;
  moves_.setZero();
  qp_failures_ = 0;
  last_active_ = false;
  qp_->ClearWarmStart();
}

bool MpcController::UnconstrainedMovesFeasible() {
  const InputLimits& lim = options_.limits;
  const int M = options_.M;
  double u = u_prev_;
  for (int j = 0; j < M; ++j) {
    const double du = moves_(j);
    u += du;
    if (!(std::abs(du) <= lim.du_max) || !(u >= lim.u_min) || !(u <= lim.u_max)) return false;
  }
  if (soft_output_) {
    // free_ holds the free response; y^ = free_ + Theta du.
    const int P = options_.P;
    for (int i = 0; i < P; ++i) {
      const int n = std::min(i + 1, M);
      const double y = free_(i) + Theta_.row(i).head(n).dot(moves_.head(n));
      if (!(y >= options_.y_min) || !(y <= options_.y_max)) return false;
    }
  }
  return true;
}

double MpcController::disturbance_estimate() const {
  return options_.disturbance == DisturbanceModel::kNone ? 0.0 : z_post_(nx_);
}

double MpcController::DoUpdate(double setpoint, double measurement) {
  const int M = options_.M;
  // Kalman correction.
  const double innovation = measurement - Cz_.dot(z_prior_);
  z_post_ = z_prior_;
  z_post_ += L_ * innovation;
  // Target.
  double us = 0.0;
  switch (options_.disturbance) {
    case DisturbanceModel::kOutput:
      us = (setpoint - z_post_(nx_)) / G_;
      break;
    case DisturbanceModel::kInput:
      us = (integrating_ ? 0.0 : setpoint / G_) - z_post_(nx_);
      break;
    case DisturbanceModel::kNone:
      us = integrating_ ? 0.0 : setpoint / G_;
      break;
  }
  // The unconstrained moves; in constrained mode they are the QP's solution
  // whenever they satisfy every bound (and the soft output bounds with e = 0:
  // the cost is separable in du and e, and e = 0 minimizes rho1 e + rho2/2 e^2).
  moves_.noalias() = Fz_ * z_post_;
  moves_ += Fu_ * u_prev_ + Fr_ * setpoint + Fs_ * us;
  last_active_ = false;
  if (constrained_) {
    const InputLimits& lim = options_.limits;
    if (soft_output_) {
      free_.noalias() = Psi_ * z_post_;
      free_ += Ups_ * u_prev_;
    }
    if (!UnconstrainedMovesFeasible()) {
      last_active_ = true;
      const int P = options_.P;
      g_.head(M).noalias() = Gz_ * z_post_;
      g_.head(M) += Gu_ * u_prev_ + Gr_ * setpoint + Gs_ * us;
      if (soft_output_) g_(M) = options_.slack_linear_weight;
      internal::FillMoveQpBounds(u_rows_, lim, u_prev_, options_.y_min, options_.y_max, free_, M, P,
                                 lb_, ub_);
      const QpSummary& s = qp_->Solve(g_, lb_, ub_, lbx_, ubx_);
      if (s.status == QpStatus::kSolved) {
        moves_ = qp_->x().head(M);
      } else {
        ++qp_failures_;  // keep the unconstrained moves (clipped below)
      }
    }
  }
  const double u = options_.limits.Clip(u_prev_ + moves_(0), u_prev_);
  // Prediction to the next sample with the input applied.
  z_tmp_.noalias() = Az_ * z_post_;
  z_tmp_ += Bz_ * u;
  z_prior_.swap(z_tmp_);
  u_prev_ = u;
  us_ = us;
  return u;
}

void MpcController::DoApplied(double u) {
  const double delta = u - u_prev_;
  if (delta == 0.0 || !std::isfinite(delta)) return;
  // z_k+1|k was predicted with u_prev_; correct it for the input really applied.
  z_prior_ += Bz_ * delta;
  u_prev_ = u;
}

std::string MpcController::Describe() const {
  return fmt::format("mpc P={} M={} lambda={:g} disturbance={}{}", options_.P, options_.M,
                     options_.lambda, ToString(options_.disturbance),
                     constrained_ ? " constrained" : "");
}

}  // namespace pneumid
