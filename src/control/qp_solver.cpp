#include "pneumid/control/qp_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"

namespace pneumid {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kEps = std::numeric_limits<double>::epsilon();
}  // namespace

namespace {
constexpr EnumName<QpStatus> kQpStatusNames[] = {
    {QpStatus::kSolved, "solved"},
    {QpStatus::kInfeasible, "infeasible"},
    {QpStatus::kMaxIterations, "max_iterations"},
    {QpStatus::kNotConvex, "not_convex"},
    {QpStatus::kNotSetUp, "not_set_up"},
};
}  // namespace

std::string ToString(QpStatus v) { return std::string(EnumToString(kQpStatusNames, v)); }

QpStatus QpStatusFromString(const std::string& name) {
  return EnumFromString(kQpStatusNames, name, "QP status");
}

bool QpSolverOptions::IsValid(std::string* error) const {
  if (max_iterations < 0) {
    if (error) *error = fmt::format("max_iterations must be >= 0, got {}", max_iterations);
    return false;
  }
  if (!(feasibility_tolerance > 0.0) || !std::isfinite(feasibility_tolerance)) {
    if (error)
      *error = fmt::format("feasibility_tolerance must be positive and finite, got {}",
                           feasibility_tolerance);
    return false;
  }
  return true;
}

std::string QpSummary::BriefReport() const {
  return fmt::format("QP {}: {} iterations, {} active, objective {:.6g} ({})", ToString(status),
                     iterations, num_active, objective, message);
}

QpSolver::QpSolver(const QpSolverOptions& options) : options_(options) {
  std::string error;
  PNEUMID_CHECK(options_.IsValid(&error), "invalid QpSolverOptions: {}", error);
}

bool QpSolver::Setup(const Eigen::MatrixXd& H, const Eigen::MatrixXd& C) {
  PNEUMID_CHECK(H.rows() > 0 && H.rows() == H.cols(), "H must be square and non-empty, got {}x{}",
                H.rows(), H.cols());
  PNEUMID_CHECK(C.rows() == 0 || C.cols() == H.cols(),
                "C must have as many columns as H ({}), got {}x{}", H.cols(), C.rows(), C.cols());
  PNEUMID_CHECK(H.allFinite(), "H has a non-finite entry");
  PNEUMID_CHECK(C.allFinite(), "C has a non-finite entry");
  n_ = static_cast<int>(H.rows());
  m_ = static_cast<int>(C.rows());
  H_ = H.selfadjointView<Eigen::Lower>();
  C_ = C.rows() == 0 ? Eigen::MatrixXd(0, n_) : C;
  llt_.compute(H_);
  set_up_ = false;
  active_.assign(n_, -1);
  is_active_.assign(2 * (m_ + n_), 0);
  warm_.clear();
  warm_.reserve(n_);
  q_ = 0;
  x_.setZero(n_);
  y_c_.setZero(m_);
  y_x_.setZero(n_);
  summary_ = QpSummary{};
  if (llt_.info() != Eigen::Success) {
    summary_.status = QpStatus::kNotConvex;
    summary_.message = "H is not positive definite";
    return false;
  }
  // Positive definite in floating point: reject a tiny pivot relative to the
  // largest diagonal entry, which would make J = L^-T useless.
  const Eigen::VectorXd diag = llt_.matrixL().toDenseMatrix().diagonal();
  if (diag.minCoeff() <= 1e-12 * std::sqrt(H_.diagonal().cwiseAbs().maxCoeff())) {
    summary_.status = QpStatus::kNotConvex;
    summary_.message = "H is numerically singular";
    return false;
  }
  // J0 = L^-T.
  J0_ = Eigen::MatrixXd::Identity(n_, n_);
  llt_.matrixU().solveInPlace(J0_);  // U = L', so J0 = U^-1 = L^-T
  J_ = J0_;
  R_.setZero(n_, n_);
  row_norm_.resize(2 * (m_ + n_));
  for (int i = 0; i < m_; ++i) {
    const double nrm = C_.row(i).norm();
    row_norm_(2 * i) = row_norm_(2 * i + 1) = nrm > 0.0 ? nrm : 1.0;
  }
  for (int j = 0; j < n_; ++j) row_norm_(2 * m_ + 2 * j) = row_norm_(2 * m_ + 2 * j + 1) = 1.0;
  g_.setZero(n_);
  lb_.setZero(m_);
  ub_.setZero(m_);
  lbx_.setZero(n_);
  ubx_.setZero(n_);
  np_.setZero(n_);
  d_.setZero(n_);
  z_.setZero(n_);
  r_.setZero(n_);
  u_.setZero(n_ + 1);
  cx_.setZero(m_);
  set_up_ = true;
  summary_.message = "set up";
  return true;
}

void QpSolver::ClearWarmStart() { warm_.clear(); }

void QpSolver::Normal(int k, Eigen::VectorXd& out) const {
  if (k < 2 * m_) {
    out = C_.row(k / 2).transpose();
    if (k % 2) out = -out;
  } else {
    out.setZero();
    out((k - 2 * m_) / 2) = (k % 2) ? -1.0 : 1.0;
  }
}

double QpSolver::NormalDot(int k, const Eigen::VectorXd& v) const {
  if (k < 2 * m_) {
    const double c = C_.row(k / 2).dot(v);
    return (k % 2) ? -c : c;
  }
  const double c = v((k - 2 * m_) / 2);
  return (k % 2) ? -c : c;
}

double QpSolver::Rhs(int k) const {
  if (k < 2 * m_) return (k % 2) ? -ub_(k / 2) : lb_(k / 2);
  const int j = (k - 2 * m_) / 2;
  return (k % 2) ? -ubx_(j) : lbx_(j);
}

bool QpSolver::IsEquality(int k) const {
  // The lower side of a row with lb == ub carries the equality; its upper
  // side is never used.
  if (k % 2) return false;
  if (k < 2 * m_) return lb_(k / 2) == ub_(k / 2);
  const int j = (k - 2 * m_) / 2;
  return lbx_(j) == ubx_(j);
}

// Appends constraint k (whose d_ = J' n_k was computed with the current J):
// Givens rotations zero d_(q+1..n-1), the same rotations act on the columns of
// J, and d_(0..q) becomes column q of R.
void QpSolver::AddToActive(int k, double multiplier) {
  for (int i = n_ - 1; i > q_; --i) {
    const double a = d_(i - 1), b = d_(i);
    if (b == 0.0) continue;
    const double h = std::hypot(a, b);
    const double c = a / h, s = b / h;
    d_(i - 1) = h;
    d_(i) = 0.0;
    for (int row = 0; row < n_; ++row) {
      const double j1 = J_(row, i - 1), j2 = J_(row, i);
      J_(row, i - 1) = c * j1 + s * j2;
      J_(row, i) = -s * j1 + c * j2;
    }
  }
  for (int i = 0; i <= q_; ++i) R_(i, q_) = d_(i);
  for (int i = q_ + 1; i < n_; ++i) R_(i, q_) = 0.0;
  active_[q_] = k;
  u_(q_) = multiplier;
  is_active_[k] = 1;
  ++q_;
}

// Removes the active constraint at `position`: its column leaves R, and
// rotations of rows (j, j+1) restore the triangular form, mirrored on the
// columns of J.
void QpSolver::DropFromActive(int position) {
  is_active_[active_[position]] = 0;
  for (int j = position; j < q_ - 1; ++j) {
    active_[j] = active_[j + 1];
    u_(j) = u_(j + 1);
    for (int i = 0; i <= j + 1; ++i) R_(i, j) = R_(i, j + 1);
  }
  --q_;
  for (int j = position; j < q_; ++j) {
    const double a = R_(j, j), b = R_(j + 1, j);
    if (b == 0.0) continue;
    const double h = std::hypot(a, b);
    const double c = a / h, s = b / h;
    for (int col = j; col < q_; ++col) {
      const double r1 = R_(j, col), r2 = R_(j + 1, col);
      R_(j, col) = c * r1 + s * r2;
      R_(j + 1, col) = -s * r1 + c * r2;
    }
    R_(j + 1, j) = 0.0;
    for (int row = 0; row < n_; ++row) {
      const double j1 = J_(row, j), j2 = J_(row, j + 1);
      J_(row, j) = c * j1 + s * j2;
      J_(row, j + 1) = -s * j1 + c * j2;
    }
  }
}

void QpSolver::Finish(QpStatus status) {
  summary_.status = status;
  switch (status) {
    case QpStatus::kSolved:
      summary_.message = "all constraints satisfied, multipliers nonnegative";
      break;
    case QpStatus::kInfeasible:
      summary_.message = "a violated constraint cannot be satisfied with the active ones";
      break;
    case QpStatus::kMaxIterations:
      summary_.message = "iteration cap reached";
      break;
    default:
      break;
  }
  summary_.num_active = q_;
  // Multipliers in the two-sided convention.
  y_c_.setZero();
  y_x_.setZero();
  for (int j = 0; j < q_; ++j) {
    const int k = active_[j];
    const double v = (k % 2) ? -u_(j) : u_(j);
    if (k < 2 * m_) {
      y_c_(k / 2) += v;
    } else {
      y_x_((k - 2 * m_) / 2) += v;
    }
  }
  // Remember the inequality active set for the next warm start.
  warm_.clear();
  if (status == QpStatus::kSolved) {
    for (int j = 0; j < q_; ++j) {
      if (!IsEquality(active_[j])) warm_.push_back(active_[j]);
    }
  }
  // objective = 1/2 x'Hx + g'x = g'x + 1/2 x'(Hx); d_ is free scratch here.
  d_.noalias() = H_ * x_;
  summary_.objective = 0.5 * x_.dot(d_) + g_.dot(x_);
}

namespace {

// The sizes and values Solve() accepts: PNEUMID_CHECK throws on a mismatch,
// a NaN, or a lower bound above its upper bound.
void CheckSolveData(int n, int m, const Eigen::Ref<const Eigen::VectorXd>& g,
                    const Eigen::Ref<const Eigen::VectorXd>& lb,
                    const Eigen::Ref<const Eigen::VectorXd>& ub,
                    const Eigen::Ref<const Eigen::VectorXd>& lbx,
                    const Eigen::Ref<const Eigen::VectorXd>& ubx) {
  PNEUMID_CHECK(g.size() == n, "g must have {} entries, got {}", n, g.size());
  PNEUMID_CHECK(lb.size() == m && ub.size() == m, "lb and ub must have {} entries, got {} and {}",
                m, lb.size(), ub.size());
  PNEUMID_CHECK(lbx.size() == n && ubx.size() == n,
                "lbx and ubx must have {} entries, got {} and {}", n, lbx.size(), ubx.size());
  PNEUMID_CHECK(g.allFinite(), "g has a non-finite entry");
  for (int i = 0; i < m; ++i) {
    PNEUMID_CHECK(!std::isnan(lb(i)) && !std::isnan(ub(i)) && lb(i) <= ub(i),
                  "constraint row {}: need lb <= ub, got lb = {}, ub = {}", i, lb(i), ub(i));
  }
  for (int j = 0; j < n; ++j) {
    PNEUMID_CHECK(!std::isnan(lbx(j)) && !std::isnan(ubx(j)) && lbx(j) <= ubx(j),
                  "bound {}: need lbx <= ubx, got lbx = {}, ubx = {}", j, lbx(j), ubx(j));
  }
}

}  // namespace

const QpSummary& QpSolver::Solve(const Eigen::Ref<const Eigen::VectorXd>& g,
                                 const Eigen::Ref<const Eigen::VectorXd>& lb,
                                 const Eigen::Ref<const Eigen::VectorXd>& ub,
                                 const Eigen::Ref<const Eigen::VectorXd>& lbx,
                                 const Eigen::Ref<const Eigen::VectorXd>& ubx) {
  summary_.iterations = 0;
  if (!set_up_) {
    if (summary_.status != QpStatus::kNotConvex) {
      summary_.status = QpStatus::kNotSetUp;
      summary_.message = "Solve() called before a successful Setup()";
    }
    return summary_;
  }
  CheckSolveData(n_, m_, g, lb, ub, lbx, ubx);
  g_ = g;
  lb_ = lb;
  ub_ = ub;
  lbx_ = lbx;
  ubx_ = ubx;

  const int num_constraints = 2 * (m_ + n_);
  int finite_sides = 0;
  for (int k = 0; k < num_constraints; ++k) finite_sides += std::isfinite(Rhs(k)) ? 1 : 0;
  const int max_iter =
      options_.max_iterations > 0 ? options_.max_iterations : 10 * (n_ + finite_sides) + 10;

  // Unconstrained minimum, empty active set.
  J_ = J0_;
  q_ = 0;
  std::fill(is_active_.begin(), is_active_.end(), 0);
  x_ = -g_;
  llt_.solveInPlace(x_);

  if (!AddEqualityConstraints()) return summary_;
  RunDualIterations(max_iter);
  return summary_;
}

// d_ = J' n_p, the primal direction z_ = J2 J2' n_p and the dual direction
// r_ = R^-1 J1' n_p for the normal np_ and the current active set.
void QpSolver::ComputeStepDirections() {
  d_.noalias() = J_.transpose() * np_;
  z_.noalias() = J_.rightCols(n_ - q_) * d_.tail(n_ - q_);
  r_.head(q_) = d_.head(q_);
  R_.topLeftCorner(q_, q_).triangularView<Eigen::Upper>().solveInPlace(r_.head(q_));
}

// Equality constraints first; they are never dropped. Returns false (the
// summary set to infeasible) for inconsistent equalities.
bool QpSolver::AddEqualityConstraints() {
  const int num_constraints = 2 * (m_ + n_);
  const double tol = options_.feasibility_tolerance;
  for (int k = 0; k < num_constraints; k += 2) {
    if (!IsEquality(k) || !std::isfinite(Rhs(k))) continue;
    Normal(k, np_);
    ComputeStepDirections();
    const double slack = NormalDot(k, x_) - Rhs(k);
    const double z_normal = z_.dot(np_);  // z' n_k
    if (std::abs(z_normal) <= 1e3 * kEps * np_.squaredNorm() || q_ == n_) {
      // Linearly dependent on the equalities already active.
      if (std::abs(slack) > tol * row_norm_(k)) {
        Finish(QpStatus::kInfeasible);
        summary_.message = "inconsistent equality constraints";
        return false;
      }
      continue;
    }
    const double t = -slack / z_normal;
    x_ += t * z_;
    u_.head(q_) -= t * r_.head(q_);
    AddToActive(k, t);
    ++summary_.iterations;
  }
  return true;
}

// Repeats step 1 (choose a violated constraint) and step 2 (move towards
// satisfying it) until every constraint holds, or the method stops; Finish()
// sets the summary either way.
void QpSolver::RunDualIterations(int max_iter) {
  std::size_t warm_next = 0;
  while (true) {
    // Step 1: choose a violated constraint p (previously active ones first).
    int p = -1;
    if (options_.warm_start) p = NextViolatedWarmConstraint(&warm_next);
    if (p < 0) p = MostViolatedConstraint();
    if (p < 0) {
      Finish(QpStatus::kSolved);
      return;
    }
    // Step 2: move towards satisfying p.
    if (!MakeActive(p, max_iter)) return;
  }
}

// The next constraint of the warm-start list, from *warm_next on, that is
// inactive and violated; -1 when there is none.
int QpSolver::NextViolatedWarmConstraint(std::size_t* warm_next) const {
  const double tol = options_.feasibility_tolerance;
  int p = -1;
  while (*warm_next < warm_.size() && p < 0) {
    const int k = warm_[(*warm_next)++];
    if (is_active_[k] || !std::isfinite(Rhs(k))) continue;
    if ((NormalDot(k, x_) - Rhs(k)) / row_norm_(k) < -tol) p = k;
  }
  return p;
}

// The inactive constraint with the most negative scaled slack below
// -tolerance; -1 when every constraint holds.
int QpSolver::MostViolatedConstraint() {
  const int num_constraints = 2 * (m_ + n_);
  int p = -1;
  cx_.noalias() = C_ * x_;
  double worst = -options_.feasibility_tolerance;
  for (int k = 0; k < num_constraints; ++k) {
    if (is_active_[k]) continue;
    const double rhs = Rhs(k);
    if (!std::isfinite(rhs)) continue;
    if (k % 2 == 1 && IsEquality(k - 1)) continue;
    double normal_dot_x;  // n_k' x
    if (k < 2 * m_) {
      normal_dot_x = (k % 2) ? -cx_(k / 2) : cx_(k / 2);
    } else {
      normal_dot_x = (k % 2) ? -x_((k - 2 * m_) / 2) : x_((k - 2 * m_) / 2);
    }
    const double scaled_slack = (normal_dot_x - rhs) / row_norm_(k);
    if (scaled_slack < worst) {
      worst = scaled_slack;
      p = k;
    }
  }
  return p;
}

// Partial step length t1: the largest dual step keeping the multipliers of
// the active inequalities >= 0 (infinite when none limits it); *drop is the
// position of the one that reaches zero first.
double QpSolver::PartialStepLength(int* drop) const {
  double t1 = kInf;
  *drop = -1;
  for (int j = 0; j < q_; ++j) {
    if (IsEquality(active_[j])) continue;
    if (r_(j) > 0.0) {
      const double ratio = u_(j) / r_(j);
      if (ratio < t1) {
        t1 = ratio;
        *drop = j;
      }
    }
  }
  return t1;
}

// Step 2 for the violated constraint p: full steps make p active, partial
// steps drop the active constraint whose multiplier reaches zero. Returns
// true once p is active, false when the method stopped (Finish() called:
// iteration cap or infeasible).
bool QpSolver::MakeActive(int p, int max_iter) {
  Normal(p, np_);
  double u_plus = 0.0;
  while (true) {
    if (summary_.iterations >= max_iter) {
      Finish(QpStatus::kMaxIterations);
      return false;
    }
    ComputeStepDirections();
    int drop = -1;
    const double t1 = PartialStepLength(&drop);
    // Full step length t2: makes p active.
    const double z_normal = z_.dot(np_);  // z' n_p
    const double slack = NormalDot(p, x_) - Rhs(p);
    double t2 = kInf;
    if (q_ < n_ && std::abs(z_normal) > 1e3 * kEps * np_.squaredNorm()) t2 = -slack / z_normal;
    if (t2 < 0.0) t2 = 0.0;  // roundoff: p is (just) satisfied already
    if (!std::isfinite(t1) && !std::isfinite(t2)) {
      Finish(QpStatus::kInfeasible);
      return false;
    }
    if (!std::isfinite(t2)) {
      // Step in dual space only, then drop.
      u_.head(q_) -= t1 * r_.head(q_);
      u_plus += t1;
      DropFromActive(drop);
      ++summary_.iterations;
      continue;
    }
    const double t = std::min(t1, t2);
    x_ += t * z_;
    u_.head(q_) -= t * r_.head(q_);
    u_plus += t;
    ++summary_.iterations;
    if (t2 <= t1) {
      AddToActive(p, u_plus);
      return true;
    }
    DropFromActive(drop);
  }
}

}  // namespace pneumid
