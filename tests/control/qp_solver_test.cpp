// Tests of the Goldfarb-Idnani QP solver: KKT conditions on every returned
// solution, agreement with exhaustive enumeration of active sets on small
// random problems, infeasibility detection, warm start and argument checks.
#include "pneumid/control/qp_solver.hpp"

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Problem {
  Eigen::MatrixXd H, C;
  Eigen::VectorXd g, lb, ub, lbx, ubx;
};

// Checks the KKT conditions of (x, yc, yx) for the problem, with tolerance tol:
// stationarity H x + g = C' yc + yx, primal feasibility, dual sign and
// complementarity (a nonzero multiplier only on an active side).
void ExpectKkt(const Problem& p, const Eigen::VectorXd& x, const Eigen::VectorXd& yc,
               const Eigen::VectorXd& yx, double tol) {
  const Eigen::VectorXd stat = p.H * x + p.g - p.C.transpose() * yc - yx;
  EXPECT_LT(stat.norm(), tol * (1.0 + p.g.norm())) << "stationarity residual " << stat.norm();
  const Eigen::VectorXd cx = p.C * x;
  for (int i = 0; i < cx.size(); ++i) {
    EXPECT_GE(cx(i), p.lb(i) - tol) << "row " << i;
    EXPECT_LE(cx(i), p.ub(i) + tol) << "row " << i;
    if (yc(i) > tol) EXPECT_NEAR(cx(i), p.lb(i), tol) << "row " << i << " y " << yc(i);
    if (yc(i) < -tol) EXPECT_NEAR(cx(i), p.ub(i), tol) << "row " << i << " y " << yc(i);
  }
  for (int j = 0; j < x.size(); ++j) {
    EXPECT_GE(x(j), p.lbx(j) - tol) << "x " << j;
    EXPECT_LE(x(j), p.ubx(j) + tol) << "x " << j;
    if (yx(j) > tol) EXPECT_NEAR(x(j), p.lbx(j), tol) << "x " << j;
    if (yx(j) < -tol) EXPECT_NEAR(x(j), p.ubx(j), tol) << "x " << j;
  }
}

// Reference solution by enumeration of every set of one-sided constraints
// taken as equalities: the KKT point is the one whose equality-constrained
// minimizer is feasible with nonnegative multipliers. Returns false when no
// subset qualifies (infeasible problem).
bool SolveByEnumeration(const Problem& p, Eigen::VectorXd* x_out) {
  const int n = static_cast<int>(p.H.rows());
  std::vector<Eigen::VectorXd> normals;
  std::vector<double> rhs;
  for (int i = 0; i < p.C.rows(); ++i) {
    if (std::isfinite(p.lb(i))) {
      normals.push_back(p.C.row(i).transpose());
      rhs.push_back(p.lb(i));
    }
    if (std::isfinite(p.ub(i))) {
      normals.push_back(-p.C.row(i).transpose());
      rhs.push_back(-p.ub(i));
    }
  }
  for (int j = 0; j < n; ++j) {
    if (std::isfinite(p.lbx(j))) {
      normals.push_back(Eigen::VectorXd::Unit(n, j));
      rhs.push_back(p.lbx(j));
    }
    if (std::isfinite(p.ubx(j))) {
      normals.push_back(-Eigen::VectorXd::Unit(n, j));
      rhs.push_back(-p.ubx(j));
    }
  }
  const int k = static_cast<int>(normals.size());
  bool found = false;
  double best = kInf;
  for (long mask = 0; mask < (1L << k); ++mask) {
    std::vector<int> set;
    for (int i = 0; i < k; ++i)
      if (mask & (1L << i)) set.push_back(i);
    const int q = static_cast<int>(set.size());
    if (q > n) continue;
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + q, n + q);
    Eigen::VectorXd b(n + q);
    K.topLeftCorner(n, n) = p.H;
    b.head(n) = -p.g;
    for (int a = 0; a < q; ++a) {
      K.block(0, n + a, n, 1) = -normals[set[a]];
      K.block(n + a, 0, 1, n) = normals[set[a]].transpose();
      b(n + a) = rhs[set[a]];
    }
    Eigen::FullPivLU<Eigen::MatrixXd> lu(K);
    if (lu.rank() < n + q) continue;
    const Eigen::VectorXd sol = lu.solve(b);
    const Eigen::VectorXd x = sol.head(n);
    bool ok = (sol.tail(q).array() >= -1e-9).all();
    for (int i = 0; i < k && ok; ++i) ok = normals[i].dot(x) >= rhs[i] - 1e-9;
    if (!ok) continue;
    const double f = 0.5 * x.dot(p.H * x) + p.g.dot(x);
    if (f < best) {
      best = f;
      *x_out = x;
      found = true;
    }
  }
  return found;
}

Problem RandomProblem(std::mt19937& rng, int n, int m, bool feasible) {
  std::normal_distribution<double> N(0.0, 1.0);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  Problem p;
  const Eigen::MatrixXd A = Eigen::MatrixXd::NullaryExpr(n, n, [&] { return N(rng); });
  p.H = A * A.transpose() + 0.1 * Eigen::MatrixXd::Identity(n, n);
  p.g = Eigen::VectorXd::NullaryExpr(n, [&] { return 3.0 * N(rng); });
  p.C = Eigen::MatrixXd::NullaryExpr(m, n, [&] { return N(rng); });
  const Eigen::VectorXd x0 = Eigen::VectorXd::NullaryExpr(n, [&] { return N(rng); });
  const Eigen::VectorXd cx0 = p.C * x0;
  p.lb.resize(m);
  p.ub.resize(m);
  for (int i = 0; i < m; ++i) {
    const double r = U(rng);
    p.lb(i) = r < 0.3 ? -kInf : cx0(i) - U(rng);
    p.ub(i) = r > 0.7 ? kInf : cx0(i) + U(rng);
    if (r > 0.3 && r < 0.4) p.lb(i) = p.ub(i) = cx0(i);  // equality
  }
  p.lbx.resize(n);
  p.ubx.resize(n);
  for (int j = 0; j < n; ++j) {
    const double r = U(rng);
    p.lbx(j) = r < 0.5 ? -kInf : x0(j) - 0.5 * U(rng);
    p.ubx(j) = r > 0.8 ? kInf : x0(j) + 0.5 * U(rng);
  }
  if (!feasible) {
    // Contradictory pair: c'x >= 1 and c'x <= 0 for a random direction c.
    p.C.conservativeResize(m + 2, n);
    p.lb.conservativeResize(m + 2);
    p.ub.conservativeResize(m + 2);
    const Eigen::VectorXd c = Eigen::VectorXd::NullaryExpr(n, [&] { return N(rng); });
    p.C.row(m) = c.transpose();
    p.C.row(m + 1) = 2.0 * c.transpose();
    p.lb(m) = 1.0;
    p.ub(m) = kInf;
    p.lb(m + 1) = -kInf;
    p.ub(m + 1) = 0.0;
  }
  return p;
}

TEST(QpSolverTest, UnconstrainedMinimumIsNewtonPoint) {
  Eigen::MatrixXd H(2, 2);
  H << 4, 1, 1, 3;
  Eigen::VectorXd g(2);
  g << 1, 2;
  QpSolver solver;
  ASSERT_TRUE(solver.Setup(H, Eigen::MatrixXd(0, 2)));
  const Eigen::VectorXd inf = Eigen::VectorXd::Constant(2, kInf);
  const auto& s = solver.Solve(g, Eigen::VectorXd(0), Eigen::VectorXd(0), -inf, inf);
  EXPECT_EQ(s.status, QpStatus::kSolved);
  const Eigen::VectorXd expected = -H.ldlt().solve(g);  // closed form
  EXPECT_LT((solver.x() - expected).norm(), 1e-12);
  EXPECT_EQ(s.num_active, 0);
  EXPECT_NEAR(s.objective, 0.5 * expected.dot(H * expected) + g.dot(expected), 1e-12);
}

TEST(QpSolverTest, TextbookExample) {
  // Nocedal & Wright, Numerical Optimization 2nd ed., Example 16.4:
  // min (x1-1)^2 + (x2-2.5)^2 s.t. x1 - 2x2 + 2 >= 0, -x1 - 2x2 + 6 >= 0,
  // -x1 + 2x2 + 2 >= 0, x >= 0; solution (1.4, 1.7).
  Eigen::MatrixXd H = 2.0 * Eigen::MatrixXd::Identity(2, 2);
  Eigen::VectorXd g(2);
  g << -2, -5;
  Eigen::MatrixXd C(3, 2);
  C << 1, -2, -1, -2, -1, 2;
  Eigen::VectorXd lb(3), ub = Eigen::VectorXd::Constant(3, kInf);
  lb << -2, -6, -2;
  QpSolver solver;
  ASSERT_TRUE(solver.Setup(H, C));
  const auto& s =
      solver.Solve(g, lb, ub, Eigen::VectorXd::Zero(2), Eigen::VectorXd::Constant(2, kInf));
  ASSERT_EQ(s.status, QpStatus::kSolved) << s.BriefReport();
  EXPECT_NEAR(solver.x()(0), 1.4, 1e-12);
  EXPECT_NEAR(solver.x()(1), 1.7, 1e-12);
  EXPECT_EQ(s.num_active, 1);
  EXPECT_NEAR(solver.y_constraints()(0), 0.8, 1e-12);  // multiplier of row 0
}

TEST(QpSolverTest, RandomProblemsMatchEnumerationAndSatisfyKkt) {
  std::mt19937 rng(12345);
  int solved = 0, with_active = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const int n = 1 + trial % 4;
    const int m = trial % 5;
    Problem p = RandomProblem(rng, n, m, true);
    QpSolver solver;
    ASSERT_TRUE(solver.Setup(p.H, p.C));
    const auto& s = solver.Solve(p.g, p.lb, p.ub, p.lbx, p.ubx);
    Eigen::VectorXd x_ref;
    const bool feasible = SolveByEnumeration(p, &x_ref);
    ASSERT_TRUE(feasible) << "trial " << trial;  // built around a feasible x0
    ASSERT_EQ(s.status, QpStatus::kSolved) << "trial " << trial << ": " << s.BriefReport();
    EXPECT_LT((solver.x() - x_ref).norm(), 1e-7 * (1.0 + x_ref.norm())) << "trial " << trial;
    ExpectKkt(p, solver.x(), solver.y_constraints(), solver.y_bounds(), 1e-8);
    ++solved;
    with_active += s.num_active > 0 ? 1 : 0;
  }
  EXPECT_EQ(solved, 150);
  EXPECT_GT(with_active, 75);  // the constraints bind in most trials
}

TEST(QpSolverTest, DetectsInfeasibleProblems) {
  std::mt19937 rng(777);
  for (int trial = 0; trial < 40; ++trial) {
    const int n = 1 + trial % 4;
    Problem p = RandomProblem(rng, n, trial % 3, false);
    QpSolver solver;
    ASSERT_TRUE(solver.Setup(p.H, p.C));
    const auto& s = solver.Solve(p.g, p.lb, p.ub, p.lbx, p.ubx);
    Eigen::VectorXd x_ref;
    EXPECT_FALSE(SolveByEnumeration(p, &x_ref));
    EXPECT_EQ(s.status, QpStatus::kInfeasible) << "trial " << trial << ": " << s.BriefReport();
  }
  // Three constraints, pairwise compatible, jointly infeasible:
  // x1 >= 1, x2 >= 1, x1 + x2 <= 1.
  Eigen::MatrixXd C(1, 2);
  C << 1, 1;
  QpSolver solver;
  ASSERT_TRUE(solver.Setup(Eigen::MatrixXd::Identity(2, 2), C));
  const auto& s = solver.Solve(Eigen::VectorXd::Zero(2), Eigen::VectorXd::Constant(1, -kInf),
                               Eigen::VectorXd::Ones(1), Eigen::VectorXd::Ones(2),
                               Eigen::VectorXd::Constant(2, kInf));
  EXPECT_EQ(s.status, QpStatus::kInfeasible);
}

TEST(QpSolverTest, WarmStartGivesSameSolutionInFewerIterations) {
  // A box-constrained sequence resembling receding-horizon steps: the linear
  // term drifts slowly, the active set hardly changes.
  const int n = 10;
  std::mt19937 rng(4);
  std::normal_distribution<double> N(0.0, 1.0);
  const Eigen::MatrixXd A = Eigen::MatrixXd::NullaryExpr(n, n, [&] { return N(rng); });
  const Eigen::MatrixXd H = A * A.transpose() + Eigen::MatrixXd::Identity(n, n);
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) C.row(i).head(i + 1).setOnes();  // cumulative sums
  const Eigen::VectorXd lb = Eigen::VectorXd::Constant(n, -1.0), ub = -lb;
  const Eigen::VectorXd lbx = Eigen::VectorXd::Constant(n, -0.3), ubx = -lbx;
  QpSolverOptions cold_options;
  cold_options.warm_start = false;
  QpSolver warm, cold(cold_options);
  ASSERT_TRUE(warm.Setup(H, C));
  ASSERT_TRUE(cold.Setup(H, C));
  const Eigen::VectorXd g0 = Eigen::VectorXd::NullaryExpr(n, [&] { return 20.0 * N(rng); });
  int warm_iters = 0, cold_iters = 0;
  for (int k = 0; k < 50; ++k) {
    const Eigen::VectorXd g = g0 * (1.0 + 0.01 * k);
    const auto& sw = warm.Solve(g, lb, ub, lbx, ubx);
    const auto& sc = cold.Solve(g, lb, ub, lbx, ubx);
    ASSERT_EQ(sw.status, QpStatus::kSolved);
    ASSERT_EQ(sc.status, QpStatus::kSolved);
    EXPECT_LT((warm.x() - cold.x()).norm(), 1e-9);
    Problem p{H, C, g, lb, ub, lbx, ubx};
    ExpectKkt(p, warm.x(), warm.y_constraints(), warm.y_bounds(), 1e-8);
    if (k > 0) {
      warm_iters += sw.iterations;
      cold_iters += sc.iterations;
    }
  }
  EXPECT_GT(cold_iters, 0);
  EXPECT_LE(warm_iters, cold_iters);
}

TEST(QpSolverTest, IterationCapIsReported) {
  QpSolverOptions options;
  options.max_iterations = 1;
  QpSolver solver(options);
  ASSERT_TRUE(solver.Setup(Eigen::MatrixXd::Identity(3, 3), Eigen::MatrixXd(0, 3)));
  const auto& s =
      solver.Solve(Eigen::VectorXd::Constant(3, -10.0), Eigen::VectorXd(0), Eigen::VectorXd(0),
                   Eigen::VectorXd::Constant(3, -kInf), Eigen::VectorXd::Ones(3));
  EXPECT_EQ(s.status, QpStatus::kMaxIterations);
  EXPECT_EQ(s.iterations, 1);
}

TEST(QpSolverTest, RejectsBadInput) {
  QpSolver solver;
  Eigen::MatrixXd H(2, 2);
  H << 1, 2, 2, 1;  // indefinite
  EXPECT_FALSE(solver.Setup(H, Eigen::MatrixXd(0, 2)));
  EXPECT_EQ(solver.summary().status, QpStatus::kNotConvex);
  const Eigen::VectorXd inf = Eigen::VectorXd::Constant(2, kInf);
  EXPECT_EQ(
      solver.Solve(Eigen::VectorXd::Zero(2), Eigen::VectorXd(0), Eigen::VectorXd(0), -inf, inf)
          .status,
      QpStatus::kNotConvex);
  EXPECT_THROW(solver.Setup(Eigen::MatrixXd::Identity(2, 3), Eigen::MatrixXd(0, 3)),
               InvalidArgument);
  ASSERT_TRUE(solver.Setup(Eigen::MatrixXd::Identity(2, 2), Eigen::MatrixXd::Ones(1, 2)));
  EXPECT_THAT(
      [&] {
        solver.Solve(Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(1), Eigen::VectorXd::Zero(1),
                     -inf, inf);
      },
      testing::ThrowsMessage<InvalidArgument>(testing::HasSubstr("g must have 2")));
  EXPECT_THAT(
      [&] {
        solver.Solve(Eigen::VectorXd::Zero(2), Eigen::VectorXd::Ones(1), Eigen::VectorXd::Zero(1),
                     -inf, inf);
      },
      testing::ThrowsMessage<InvalidArgument>(testing::HasSubstr("lb <= ub")));
  QpSolverOptions bad;
  bad.feasibility_tolerance = -1;
  std::string error;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_THROW(QpSolver{bad}, InvalidArgument);
  EXPECT_EQ(QpStatusFromString("infeasible"), QpStatus::kInfeasible);
  EXPECT_THROW(QpStatusFromString("nope"), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
