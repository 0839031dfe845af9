// Dense strictly convex quadratic programming by the dual active-set method of
// Goldfarb and Idnani, the solver under the constrained predictive controllers.
//
//   minimize    1/2 x' H x + g' x                      x in R^n
//   subject to  lb  <= C x <= ub                       C is m x n
//               lbx <=  x  <= ubx                      simple bounds
//
// H must be symmetric positive definite (it is factorized once, at Setup()).
// Infinite bounds (+-inf) switch a side off; lb_i == ub_i makes row i an
// equality. Each call to Solve() changes only the data that move from one
// control step to the next (g and the bounds), as in OSQP's update/solve
// interface, and allocates nothing: all work arrays are sized at Setup().
//
// Method [1]: start from the unconstrained minimum x = -H^-1 g (dual
// feasible), then repeatedly pick a violated constraint p and move along the
// primal direction z = J2 J2' n_p and the dual direction r = R^-1 J1' n_p
// (with the factors J = L^-T Q, H = L L', J' N = [R; 0] of the active normals
// N), taking either a full step (p becomes active) or a partial step (an active
// constraint whose multiplier reaches zero is dropped). J and R are updated by
// Givens rotations [1, sec. 4], [2, ch. 16.8]. The objective increases
// monotonically, so the method terminates; it detects infeasibility when a
// violated constraint can neither be reached in the primal nor the dual space.
// Warm start: the constraints active at the previous solution are tried first
// when they are violated, which for receding-horizon problems usually yields
// the solution in as many iterations as there are active constraints.
//
// [1] D. Goldfarb, A. Idnani, "A numerically stable dual method for solving
//     strictly convex quadratic programs", Math. Programming 27 (1983) 1-33.
// [2] J. Nocedal, S. J. Wright, Numerical Optimization, 2nd ed., 2006, ch. 16.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

namespace pneumid {

/// Outcome of QpSolver::Solve().
enum class QpStatus {
  kSolved,         ///< KKT point found (the unique minimizer)
  kInfeasible,     ///< the constraints have no common point
  kMaxIterations,  ///< iteration cap reached; x is the last (dual-feasible) iterate
  kNotConvex,      ///< H is not positive definite (Setup failed)
  kNotSetUp,       ///< Solve() called before a successful Setup()
};

/// "solved", "infeasible", "max_iterations", "not_convex", "not_set_up".
std::string ToString(QpStatus status);
/// Inverse of ToString; throws InvalidArgument listing the valid names.
QpStatus QpStatusFromString(const std::string& name);

/// Iteration cap, feasibility tolerance and warm start of the Goldfarb-Idnani solver.
struct QpSolverOptions {
  /// Cap on active-set changes per Solve(); 0 chooses 10 (n + number of
  /// finite one-sided constraints) + 10.
  int max_iterations = 0;
  /// A constraint counts as violated when its slack, divided by the norm of
  /// its row, is below -feasibility_tolerance (units of x).
  double feasibility_tolerance = 1e-9;
  /// Try the previously active constraints first (see the file comment).
  bool warm_start = true;
  /// True when the options are usable (max_iterations >= 0, feasibility_tolerance finite
  /// and > 0); otherwise false and *error says why (when error is not null).
  bool IsValid(std::string* error) const;
};

/// Outcome of the last Setup() or Solve().
struct QpSummary {
  QpStatus status = QpStatus::kNotSetUp;  ///< see QpStatus
  /// Static text describing the status (no allocation in Solve()).
  std::string_view message = "not set up";
  int iterations = 0;    ///< constraint additions plus removals
  int num_active = 0;    ///< active constraints at the returned point
  double objective = 0;  ///< 1/2 x'Hx + g'x at the returned point
  /// One line, e.g. "QP solved: 3 iterations, 2 active, objective -1.25".
  std::string BriefReport() const;
};

/// Dense strictly convex QP solver (dual active set, Goldfarb-Idnani) set up once and
/// solved repeatedly with new g and bounds (file comment).
class QpSolver {
 public:
  /// A solver with `options`, not yet set up (status kNotSetUp until Setup()).
  explicit QpSolver(const QpSolverOptions& options = {});

  /// Sets the Hessian H (n x n, symmetric positive definite; only the lower
  /// triangle is read) and the constraint matrix C (m x n, m may be 0), and
  /// allocates all work arrays. Returns false (and summary().status ==
  /// kNotConvex) when the Cholesky factorization of H fails.
  /// @throws InvalidArgument when the sizes disagree, n == 0, an entry is not
  /// finite, or the options are invalid.
  bool Setup(const Eigen::MatrixXd& H, const Eigen::MatrixXd& C);

  /// Solves with linear term g (n) and bounds lb, ub (m) and lbx, ubx (n);
  /// use -inf/+inf for absent sides. Returns the summary; the solution is in
  /// x() and the multipliers in y_constraints() and y_bounds().
  /// Allocates no memory.
  /// @throws InvalidArgument on a size mismatch, NaN, or a lower bound above
  /// its upper bound.
  const QpSummary& Solve(const Eigen::Ref<const Eigen::VectorXd>& g,
                         const Eigen::Ref<const Eigen::VectorXd>& lb,
                         const Eigen::Ref<const Eigen::VectorXd>& ub,
                         const Eigen::Ref<const Eigen::VectorXd>& lbx,
                         const Eigen::Ref<const Eigen::VectorXd>& ubx);

  /// Forgets the active set remembered for warm starting.
  void ClearWarmStart();

  /// Solution (n) of the last Solve(): the minimizer when solved, else the last iterate.
  const Eigen::VectorXd& x() const { return x_; }
  /// Multipliers of C x: positive when the lower side is active, negative
  /// when the upper side is, zero when inactive. With them the KKT
  /// stationarity reads H x + g = C' y_constraints + y_bounds.
  const Eigen::VectorXd& y_constraints() const { return y_c_; }
  /// Multipliers of the simple bounds, same sign convention.
  const Eigen::VectorXd& y_bounds() const { return y_x_; }
  const QpSummary& summary() const { return summary_; }        ///< Summary of the last call.
  int num_variables() const { return n_; }                     ///< n, set by Setup() (0 before).
  const QpSolverOptions& options() const { return options_; }  ///< The options in use.
  /// The data fixed at Setup(): H, C, the Cholesky factor L of H = L L'
  /// (lower triangle, zeros above), J0 = L^-T, and the norms of the rows of
  /// C (0 replaced by 1) used to scale violations.
  const Eigen::MatrixXd& hessian() const { return H_; }
  const Eigen::MatrixXd& constraint_matrix() const { return C_; }  ///< C (m x n).
  /// L (n x n) with H = L L', lower triangular; allocates (not for the control loop).
  Eigen::MatrixXd cholesky_factor() const { return llt_.matrixL().toDenseMatrix(); }
  const Eigen::MatrixXd& initial_basis() const { return J0_; }  ///< J0 = L^-T (n x n).
  /// Row norms of C (m); the bounds' normals have norm 1.
  Eigen::VectorXd row_norms() const {
    Eigen::VectorXd r(m_);
    for (int i = 0; i < m_; ++i) r(i) = row_norm_(2 * i);
    return r;
  }
  int num_constraints() const { return m_; }  ///< m, rows of C (0 before Setup()).

 private:
  // One-sided constraint k: n_k' x >= b_k. k < 2m: row k/2 of C (side k%2:
  // 0 lower, 1 upper, normal -C_i); k >= 2m: bound (k-2m)/2.
  void Normal(int k, Eigen::VectorXd& out) const;
  double NormalDot(int k, const Eigen::VectorXd& v) const;
  double Rhs(int k) const;
  bool IsEquality(int k) const;
  void AddToActive(int k, double multiplier);
  void DropFromActive(int position);
  void Finish(QpStatus status);
  // The stages of Solve() (qp_solver.cpp).
  void ComputeStepDirections();
  bool AddEqualityConstraints();
  void RunDualIterations(int max_iter);
  int NextViolatedWarmConstraint(std::size_t* warm_next) const;
  int MostViolatedConstraint();
  double PartialStepLength(int* drop) const;
  bool MakeActive(int p, int max_iter);

  QpSolverOptions options_;
  int n_ = 0, m_ = 0;
  bool set_up_ = false;
  Eigen::MatrixXd H_, C_, J0_, J_, R_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
  Eigen::VectorXd row_norm_;
  // Per-solve data (copies of the caller's vectors, preallocated).
  Eigen::VectorXd g_, lb_, ub_, lbx_, ubx_;
  Eigen::VectorXd x_, y_c_, y_x_, np_, d_, z_, r_, u_, cx_;
  std::vector<int> active_;      // constraint ids, size q (capacity n)
  std::vector<char> is_active_;  // per constraint id
  std::vector<int> warm_;        // previous active inequality ids
  int q_ = 0;
  QpSummary summary_;
};

}  // namespace pneumid
