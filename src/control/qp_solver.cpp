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
  PNEUMID_CHECK(g.size() == n_, "g must have {} entries, got {}", n_, g.size());
  PNEUMID_CHECK(lb.size() == m_ && ub.size() == m_, "lb and ub must have {} entries, got {} and {}",
                m_, lb.size(), ub.size());
  PNEUMID_CHECK(lbx.size() == n_ && ubx.size() == n_,
                "lbx and ubx must have {} entries, got {} and {}", n_, lbx.size(), ubx.size());
  PNEUMID_CHECK(g.allFinite(), "g has a non-finite entry");
  for (int i = 0; i < m_; ++i) {
    PNEUMID_CHECK(!std::isnan(lb(i)) && !std::isnan(ub(i)) && lb(i) <= ub(i),
                  "constraint row {}: need lb <= ub, got lb = {}, ub = {}", i, lb(i), ub(i));
  }
  for (int j = 0; j < n_; ++j) {
    PNEUMID_CHECK(!std::isnan(lbx(j)) && !std::isnan(ubx(j)) && lbx(j) <= ubx(j),
                  "bound {}: need lbx <= ubx, got lbx = {}, ubx = {}", j, lbx(j), ubx(j));
  }
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
  const double tol = options_.feasibility_tolerance;
  constexpr double kEps = std::numeric_limits<double>::epsilon();

  // Unconstrained minimum, empty active set.
  J_ = J0_;
  q_ = 0;
  std::fill(is_active_.begin(), is_active_.end(), 0);
  x_ = -g_;
  llt_.solveInPlace(x_);

  // Equality constraints first; they are never dropped.
  for (int k = 0; k < num_constraints; k += 2) {
    if (!IsEquality(k) || !std::isfinite(Rhs(k))) continue;
    Normal(k, np_);
    d_.noalias() = J_.transpose() * np_;
    z_.noalias() = J_.rightCols(n_ - q_) * d_.tail(n_ - q_);
    r_.head(q_) = d_.head(q_);
    R_.topLeftCorner(q_, q_).triangularView<Eigen::Upper>().solveInPlace(r_.head(q_));
    const double s = NormalDot(k, x_) - Rhs(k);
    const double zn = z_.dot(np_);
    if (std::abs(zn) <= 1e3 * kEps * np_.squaredNorm() || q_ == n_) {
      // Linearly dependent on the equalities already active.
      if (std::abs(s) > tol * row_norm_(k)) {
        Finish(QpStatus::kInfeasible);
        summary_.message = "inconsistent equality constraints";
        return summary_;
      }
      continue;
    }
    const double t = -s / zn;
    x_ += t * z_;
    u_.head(q_) -= t * r_.head(q_);
    AddToActive(k, t);
    ++summary_.iterations;
  }

  std::size_t warm_next = 0;
  while (true) {
    // Step 1: choose a violated constraint p (previously active ones first).
    int p = -1;
    if (options_.warm_start) {
      while (warm_next < warm_.size() && p < 0) {
        const int k = warm_[warm_next++];
        if (is_active_[k] || !std::isfinite(Rhs(k))) continue;
        if ((NormalDot(k, x_) - Rhs(k)) / row_norm_(k) < -tol) p = k;
      }
    }
    if (p < 0) {
      cx_.noalias() = C_ * x_;
      double worst = -tol;
      for (int k = 0; k < num_constraints; ++k) {
        if (is_active_[k]) continue;
        const double b = Rhs(k);
        if (!std::isfinite(b)) continue;
        if (k % 2 == 1 && IsEquality(k - 1)) continue;
        double v;
        if (k < 2 * m_) {
          v = (k % 2) ? -cx_(k / 2) : cx_(k / 2);
        } else {
          v = (k % 2) ? -x_((k - 2 * m_) / 2) : x_((k - 2 * m_) / 2);
        }
        const double s = (v - b) / row_norm_(k);
        if (s < worst) {
          worst = s;
          p = k;
        }
      }
    }
    if (p < 0) {
      Finish(QpStatus::kSolved);
      return summary_;
    }

    // Step 2: move towards satisfying p.
    Normal(p, np_);
    double u_plus = 0.0;
    while (true) {
      if (summary_.iterations >= max_iter) {
        Finish(QpStatus::kMaxIterations);
        return summary_;
      }
      d_.noalias() = J_.transpose() * np_;
      z_.noalias() = J_.rightCols(n_ - q_) * d_.tail(n_ - q_);
      r_.head(q_) = d_.head(q_);
      R_.topLeftCorner(q_, q_).triangularView<Eigen::Upper>().solveInPlace(r_.head(q_));
      // Partial step length t1: largest dual step keeping multipliers >= 0.
      double t1 = kInf;
      int drop = -1;
      for (int j = 0; j < q_; ++j) {
        if (IsEquality(active_[j])) continue;
        if (r_(j) > 0.0) {
          const double ratio = u_(j) / r_(j);
          if (ratio < t1) {
            t1 = ratio;
            drop = j;
          }
        }
      }
      // Full step length t2: makes p active.
      const double zn = z_.dot(np_);
      const double s = NormalDot(p, x_) - Rhs(p);
      double t2 = kInf;
      if (q_ < n_ && std::abs(zn) > 1e3 * kEps * np_.squaredNorm()) t2 = -s / zn;
      if (t2 < 0.0) t2 = 0.0;  // roundoff: p is (just) satisfied already
      if (!std::isfinite(t1) && !std::isfinite(t2)) {
        Finish(QpStatus::kInfeasible);
        return summary_;
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
        break;
      }
      DropFromActive(drop);
    }
  }
}

}  // namespace pneumid
