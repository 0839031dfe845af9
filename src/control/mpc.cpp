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
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

namespace {
constexpr EnumName<DisturbanceModel> kDisturbanceModelNames[] = {
    {DisturbanceModel::kOutput, "output"},
    {DisturbanceModel::kInput, "input"},
    {DisturbanceModel::kNone, "none"},
};
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
  if (P > kMaxPredictionHorizon || M > kMaxControlHorizon)
    return fail(fmt::format(
        "horizons P = {} and M = {} exceed the largest ones taken, P = {} and M = {} (a sample "
        "time much shorter than the plant's time scale: choose a longer one)",
        P, M, kMaxPredictionHorizon, kMaxControlHorizon));
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
  const int d = DelayInSamples(model.delay(), model.Ts());
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

MpcController::MpcController(const PredictionModel& model, const MpcOptions& options)
    : options_(options) {
  Build(DelayAsStates(model.sampled_state_space()));
}

MpcController::~MpcController() = default;

namespace {

// The options and the model as Build() needs them (before the delay becomes
// states).
void CheckOptionsAndModel(const MpcOptions& options, const StateSpace& model_in) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid MPC options: {}", error);
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
}

// True for an integrating model. Stable, or integrating: one pole at z = 1,
// the others inside the circle; any other model is refused.
bool IsIntegratingModel(const StateSpace& model) {
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
  return at_one == 1;
}

// The model's steady state per unit input (per unit output when integrating)
// and its static gain.
struct UnitSteadyState {
  Eigen::VectorXd xs_unit;  // (I - A)^-1 B; integrating: x_s per unit r
  double G = 0.0;           // static gain; infinite for an integrating model
};

UnitSteadyState ComputeUnitSteadyState(const StateSpace& model, bool integrating,
                                       const MpcOptions& options) {
  const Eigen::MatrixXd& A = model.A();
  const int nx = model.num_states();
  UnitSteadyState steady;
  if (!integrating) {
    steady.xs_unit = (Eigen::MatrixXd::Identity(nx, nx) - A).partialPivLu().solve(model.B().col(0));
    steady.G = model.C().row(0).dot(steady.xs_unit);
    PNEUMID_CHECK(std::isfinite(steady.G) &&
                      std::abs(steady.G) > 1e-12 * std::max(1.0, steady.xs_unit.norm()),
                  "MPC needs a model with a nonzero static gain, got {}", steady.G);
    return steady;
  }
  // [I - A, -B; C, 0] [x_s; v_s] = [0; r] (file comment): x_s per unit r.
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(nx + 1, nx + 1);
  T.topLeftCorner(nx, nx) = Eigen::MatrixXd::Identity(nx, nx) - A;
  T.topRightCorner(nx, 1) = -model.B();
  T.bottomLeftCorner(1, nx) = model.C();
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(T);
  // A pole at z = 1 cancelled (to rounding) by a zero there, as least
  // squares can fit on noise-free data, leaves T all but singular.
  PNEUMID_CHECK(lu.isInvertible() && lu.rcond() > 1e-9,
                "MPC needs a stable model, or an integrating one without a zero at z = 1; "
                "the model has a pole at z = 1 {}",
                lu.isInvertible()
                    ? fmt::format("all but cancelled by a zero (rcond {:.3g})", lu.rcond())
                    : std::string("cancelled by a zero"));
  const Eigen::VectorXd col = lu.solve(Eigen::VectorXd::Unit(nx + 1, nx));
  steady.xs_unit = col.head(nx);
  steady.G = std::numeric_limits<double>::infinity();
  PNEUMID_CHECK(options.disturbance != DisturbanceModel::kOutput,
                "MPC on an integrating model needs the input disturbance model (or none): an "
                "output disturbance is not detectable behind the model's own integrator");
  PNEUMID_CHECK(options.disturbance != DisturbanceModel::kNone || options.state_noise > 0.0,
                "MPC on an integrating model without a disturbance model needs process noise "
                "on its states (state_noise > 0, --state-noise): the Kalman filter has nothing "
                "else to follow the integrator with");
  return steady;
}

// z+ = Az z + Bz u, y = Cz z: the model and its disturbance (file comment).
struct AugmentedModel {
  Eigen::MatrixXd Az;
  Eigen::VectorXd Bz;
  Eigen::RowVectorXd Cz;
};

AugmentedModel AugmentWithDisturbance(const StateSpace& model, DisturbanceModel dm) {
  const int nx = model.num_states();
  const int nd = dm == DisturbanceModel::kNone ? 0 : 1;
  const int nz = nx + nd;
  AugmentedModel aug;
  aug.Az.setZero(nz, nz);
  aug.Az.topLeftCorner(nx, nx) = model.A();
  aug.Bz.setZero(nz);
  aug.Bz.head(nx) = model.B().col(0);
  aug.Cz.setZero(nz);
  aug.Cz.head(nx) = model.C().row(0);
  if (dm == DisturbanceModel::kOutput) {
    aug.Az(nx, nx) = 1.0;
    aug.Cz(nx) = 1.0;
  } else if (dm == DisturbanceModel::kInput) {
    aug.Az.block(0, nx, nx, 1) = model.B();
    aug.Az(nx, nx) = 1.0;
  }
  return aug;
}

// The estimator's a priori covariance X and gain L.
struct KalmanDesign {
  Eigen::MatrixXd X;
  Eigen::VectorXd L;
  DareSummary summary;
};

// Steady-state Kalman filter: X = DARE(Az', Cz', Qz, R). The first n_plant
// states get process noise, the delay states none.
KalmanDesign DesignKalmanFilter(const AugmentedModel& aug, int nx, int n_plant,
                                const MpcOptions& options) {
  const int nz = static_cast<int>(aug.Az.rows());
  const bool with_disturbance = options.disturbance != DisturbanceModel::kNone;
  Eigen::MatrixXd Qz = Eigen::MatrixXd::Zero(nz, nz);
  Qz.diagonal().head(n_plant).setConstant(options.state_noise);
  if (with_disturbance) Qz(nx, nx) = options.disturbance_noise;
  const Eigen::MatrixXd Rm = Eigen::MatrixXd::Constant(1, 1, options.measurement_noise);
  const DareResult dare = SolveDare(aug.Az.transpose(), aug.Cz.transpose(), Qz, Rm, options.dare);
  PNEUMID_CHECK(dare.summary.status == DareStatus::kConverged,
                "the Kalman filter cannot be designed ({}): the disturbance model '{}' may not "
                "be detectable for this plant",
                dare.summary.BriefReport(), ToString(options.disturbance));
  KalmanDesign kalman;
  kalman.summary = dare.summary;
  kalman.X = dare.X;
  kalman.L = kalman.X * aug.Cz.transpose() /
             (aug.Cz.dot(kalman.X * aug.Cz.transpose()) + options.measurement_noise);
  return kalman;
}

// y^ = Psi z_k|k + Ups u_{k-1} + Theta du over the horizon P with M moves.
struct PredictionMatrices {
  Eigen::MatrixXd Psi;    // P x nz
  Eigen::VectorXd Ups;    // P
  Eigen::MatrixXd Theta;  // P x M
};

PredictionMatrices ComputePredictionMatrices(const AugmentedModel& aug, int P, int M) {
  PredictionMatrices pred;
  pred.Psi.resize(P, aug.Az.rows());
  pred.Ups.resize(P);
  Eigen::RowVectorXd row = aug.Cz;  // Cz Az^(i-1)
  double ups_sum = 0.0;
  for (int i = 0; i < P; ++i) {
    ups_sum += row.dot(aug.Bz);
    pred.Ups(i) = ups_sum;  // Ups_{i+1}
    row = (row * aug.Az).eval();
    pred.Psi.row(i) = row;  // Cz Az^(i+1)
  }
  pred.Theta.setZero(P, M);
  for (int l = 0; l < M; ++l) pred.Theta.col(l).tail(P - l) = pred.Ups.head(P - l);
  return pred;
}

// The cost 1/2 du' H du + g' du with g = Gz z + Gu u_{k-1} + Gr r + Gs u_s,
// and its unconstrained minimizer du = Fz z + Fu u_{k-1} + Fr r + Fs u_s.
struct MoveCost {
  Eigen::MatrixXd H;
  Eigen::MatrixXd Gz;
  Eigen::VectorXd Gu, Gr, Gs;
  Eigen::MatrixXd Fz;
  Eigen::VectorXd Fu, Fr, Fs;
};

MoveCost ComputeMoveCost(const PredictionMatrices& pred, const MpcOptions& options) {
  const int P = options.P, M = options.M;
  const double q = options.output_weight, wu = options.input_weight;
  // T: the M x M lower-triangular ones, the inputs being u_{k-1} 1 + T du.
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(M, M);
  for (int j = 0; j < M; ++j) T.row(j).head(j + 1).setOnes();
  const Eigen::VectorXd Tt1 = T.transpose() * Eigen::VectorXd::Ones(M);
  MoveCost cost;
  cost.H = q * pred.Theta.transpose() * pred.Theta;
  cost.H.diagonal().array() += options.lambda;
  cost.H += wu * T.transpose() * T;
  Eigen::LLT<Eigen::MatrixXd> llt(cost.H);
  PNEUMID_CHECK(llt.info() == Eigen::Success && llt.matrixLLT().diagonal().minCoeff() >
                                                    1e-10 * std::sqrt(cost.H.diagonal().maxCoeff()),
                "the MPC Hessian q Theta'Theta + lambda I is singular (the model's dead time "
                "may exceed the horizon); increase lambda (now {}) or P (now {})",
                options.lambda, P);
  cost.Gz = q * pred.Theta.transpose() * pred.Psi;
  cost.Gu = q * pred.Theta.transpose() * pred.Ups + wu * Tt1;
  cost.Gr = -q * pred.Theta.transpose() * Eigen::VectorXd::Ones(P);
  cost.Gs = -wu * Tt1;
  // F = -H^-1 G: the unconstrained moves; the gain is its first row.
  cost.Fz = -llt.solve(cost.Gz);
  cost.Fu = -llt.solve(cost.Gu);
  cost.Fr = -llt.solve(cost.Gr);
  cost.Fs = -llt.solve(cost.Gs);
  return cost;
}

}  // namespace

void MpcController::Build(const StateSpace& model_in) {
  CheckOptionsAndModel(options_, model_in);
  const StateSpace model = DelayAsStates(model_in);
  PNEUMID_CHECK(model.D()(0, 0) == 0.0,
                "MPC needs a strictly proper model: D = {} makes y_k depend on u_k, which is "
                "computed from y_k (use an input delay of at least one sample, e.g. nk >= 1)",
                model.D()(0, 0));
  integrating_ = IsIntegratingModel(model);
  Ts_ = model.Ts();
  nx_ = model.num_states();
  UnitSteadyState steady = ComputeUnitSteadyState(model, integrating_, options_);
  xs_unit_ = std::move(steady.xs_unit);
  G_ = steady.G;

  AugmentedModel aug = AugmentWithDisturbance(model, options_.disturbance);
  nz_ = static_cast<int>(aug.Az.rows());
  // Process noise on the states of model_in only: the delay states get none.
  KalmanDesign kalman = DesignKalmanFilter(aug, nx_, model_in.num_states(), options_);
  dare_summary_ = kalman.summary;
  X_ = std::move(kalman.X);
  L_ = std::move(kalman.L);

  PredictionMatrices pred = ComputePredictionMatrices(aug, options_.P, options_.M);
  Az_ = std::move(aug.Az);
  Bz_ = std::move(aug.Bz);
  Cz_ = std::move(aug.Cz);
  MoveCost cost = ComputeMoveCost(pred, options_);
  Psi_ = std::move(pred.Psi);
  Ups_ = std::move(pred.Ups);
  Theta_ = std::move(pred.Theta);
  H_ = std::move(cost.H);
  Gz_ = std::move(cost.Gz);
  Gu_ = std::move(cost.Gu);
  Gr_ = std::move(cost.Gr);
  Gs_ = std::move(cost.Gs);
  Fz_ = std::move(cost.Fz);
  Fu_ = std::move(cost.Fu);
  Fr_ = std::move(cost.Fr);
  Fs_ = std::move(cost.Fs);
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
  moves_.setZero(options_.M);
  z_prior_.setZero(nz_);
  z_post_.setZero(nz_);
  z_tmp_.setZero(nz_);
  if (constrained_) {
    const internal::MoveQp move_qp = internal::BuildMoveQp(
        H_, Theta_, lim, options_.y_min, options_.y_max, options_.slack_quadratic_weight);
    PNEUMID_CHECK(qp_->Setup(move_qp.hessian, move_qp.constraints),
                  "the MPC QP Hessian is not positive definite: {}", qp_->summary().BriefReport());
    nvar_ = static_cast<int>(move_qp.hessian.rows());
    g_.setZero(nvar_);
    lb_.setZero(move_qp.constraints.rows());
    ub_.setZero(move_qp.constraints.rows());
    lbx_ = move_qp.lbx;
    ubx_ = move_qp.ubx;
    free_.setZero(options_.P);
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
  // An overflow (a finite but huge measurement through the observer) is a
  // fault (Controller::Update), not a QP of non-finite data.
  if (!moves_.allFinite() || !z_post_.allFinite()) return std::numeric_limits<double>::quiet_NaN();
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
      if (!g_.allFinite()) return std::numeric_limits<double>::quiet_NaN();
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
