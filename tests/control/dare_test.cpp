// DARE solver (structure-preserving doubling): the scalar closed form, a
// 4 x 4 two-input case with an unstable A against
// scipy.linalg.solve_discrete_are (tests/control/gen_mpc_reference.py), a
// plant with an uncontrollable unstable mode, and bad input.
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/control/dare.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

Eigen::MatrixXd Mat(int rows, int cols, std::initializer_list<double> values) {
  Eigen::MatrixXd M(rows, cols);
  auto it = values.begin();
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) M(i, j) = *it++;
  return M;
}

TEST(DareTest, ScalarMatchesClosedForm) {
  // X = a^2 X - a^2 b^2 X^2 / (r + b^2 X) + q  <=>  b^2 X^2 + (r (1 - a^2) - q b^2) X - q r = 0
  // (positive root); unstable a.
  const double a = 1.2, b = 0.5, q = 2.0, r = 0.3;
  const double p = r * (1.0 - a * a) - q * b * b;
  const double X = (-p + std::sqrt(p * p + 4.0 * b * b * q * r)) / (2.0 * b * b);
  const DareResult res = SolveDare(Mat(1, 1, {a}), Mat(1, 1, {b}), Mat(1, 1, {q}), Mat(1, 1, {r}));
  EXPECT_EQ(res.summary.status, DareStatus::kConverged) << res.summary.BriefReport();
  EXPECT_NEAR(res.X(0, 0), X, 1e-12 * X);
  EXPECT_NEAR(res.K(0, 0), b * X * a / (r + b * b * X), 1e-12);
  EXPECT_LT(res.summary.closed_loop_spectral_radius, 1.0);
  EXPECT_LT(res.summary.residual, 1e-13);
}

TEST(DareTest, MatchesScipyOnUnstableTwoInputCase) {
  const Eigen::MatrixXd A =
      Mat(4, 4, {1.1, 0.2, 0, 0, 0, 0.9, 0.3, 0, 0.1, 0, 0.8, 0.2, 0, 0, -0.3, 1.05});
  const Eigen::MatrixXd B = Mat(4, 2, {1, 0, 0, 0, 0, 1, 0.5, 0.2});
  const Eigen::MatrixXd Q = Eigen::Vector4d(1.0, 2.0, 0.5, 1.0).asDiagonal();
  const Eigen::MatrixXd R = Mat(2, 2, {1.0, 0.2, 0.2, 0.5});
  // scipy.linalg.solve_discrete_are, gen_mpc_reference.py
  const Eigen::MatrixXd expected =
      Mat(4, 4,
          {4.5539897973820338, -0.2434524202762588, 2.1597054863669731, -4.6398976694680716,
           -0.2434524202762588, 5.9295930527310086, 1.1877966097872426, 0.93771993372687767,
           2.1597054863669731, 1.1877966097872426, 2.7889667104921032, -3.3532693372731934,
           -4.6398976694680716, 0.93771993372687767, -3.3532693372731934, 9.1584755150347394});
  const DareResult res = SolveDare(A, B, Q, R);
  ASSERT_EQ(res.summary.status, DareStatus::kConverged) << res.summary.BriefReport();
  EXPECT_LT((res.X - expected).norm(), 1e-11 * expected.norm());
  EXPECT_LT(res.summary.iterations, 20);
  EXPECT_LT(res.summary.residual, 1e-13);
  EXPECT_LT(res.summary.closed_loop_spectral_radius, 1.0);
}

TEST(DareTest, ZeroWeightOnStablePlantGivesZero) {
  const DareResult res = SolveDare(Mat(2, 2, {0.5, 0.1, 0, 0.3}), Mat(2, 1, {1, 0}),
                                   Eigen::MatrixXd::Zero(2, 2), Mat(1, 1, {1.0}));
  EXPECT_EQ(res.summary.status, DareStatus::kConverged);
  EXPECT_EQ(res.X.norm(), 0.0);
}

TEST(DareTest, UncontrollableUnstableModeIsReported) {
  // Mode 1.2 is not reached by B: no stabilizing solution exists.
  const DareResult res = SolveDare(Mat(2, 2, {1.2, 0, 0, 0.5}), Mat(2, 1, {0, 1}),
                                   Eigen::MatrixXd::Identity(2, 2), Mat(1, 1, {1.0}));
  EXPECT_NE(res.summary.status, DareStatus::kConverged) << res.summary.BriefReport();
}

TEST(DareTest, StatusNamesRoundTrip) {
  for (DareStatus s : {DareStatus::kConverged, DareStatus::kMaxIterations,
                       DareStatus::kNotStabilizing, DareStatus::kNumericalFailure})
    EXPECT_EQ(DareStatusFromString(ToString(s)), s);
  EXPECT_THROW(DareStatusFromString("done"), InvalidArgument);
}

TEST(DareTest, BadInputThrows) {
  const Eigen::MatrixXd A = Mat(1, 1, {0.5}), B = Mat(1, 1, {1}), Q = Mat(1, 1, {1});
  EXPECT_THAT([&] { SolveDare(A, B, Q, Mat(1, 1, {0.0})); },
              ThrowsMessage<InvalidArgument>(HasSubstr("R must be positive definite")));
  EXPECT_THAT([&] { SolveDare(A, B, Mat(1, 1, {-1.0}), Mat(1, 1, {1.0})); },
              ThrowsMessage<InvalidArgument>(HasSubstr("positive semidefinite")));
  EXPECT_THAT(
      [&] {
        SolveDare(Mat(1, 2, {1, 2}), B, Q, Q);
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("square")));
  EXPECT_THAT(
      [&] {
        SolveDare(A, Mat(2, 1, {1, 1}), Q, Q);
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("B must be")));
  EXPECT_THAT(
      [&] {
        SolveDare(A, B, Mat(2, 2, {1, 2, 2, 1}), Q);
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("Q must be 1 x 1")));
  EXPECT_THAT([&] { SolveDare(Mat(1, 1, {NAN}), B, Q, Q); },
              ThrowsMessage<InvalidArgument>(HasSubstr("finite")));
  DareOptions o;
  o.max_iterations = 0;
  EXPECT_THAT([&] { SolveDare(A, B, Q, Q, o); },
              ThrowsMessage<InvalidArgument>(HasSubstr("max_iterations")));
}

}  // namespace
}  // namespace pneumid
