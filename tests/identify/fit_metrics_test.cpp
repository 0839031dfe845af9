#include "pneumid/identify/evaluation/fit_metrics.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;

// Closed forms: y = [0 1 2 3], mean 1.5, ||y - mean|| = sqrt(5);
// yhat = y + [0 0 0 1] -> ||e|| = 1 -> fit = 100 (1 - 1/sqrt(5)).
TEST(FitMetricsTest, NrmseFitClosedForm) {
  Eigen::VectorXd y(4), yhat(4);
  y << 0, 1, 2, 3;
  yhat << 0, 1, 2, 4;
  EXPECT_NEAR(NrmseFit(y, yhat), 100.0 * (1.0 - 1.0 / std::sqrt(5.0)), 1e-12);
  EXPECT_DOUBLE_EQ(NrmseFit(y, y), 100.0);
  // The mean as a model scores exactly 0.
  EXPECT_NEAR(NrmseFit(y, Eigen::VectorXd::Constant(4, 1.5)), 0.0, 1e-12);
}

TEST(FitMetricsTest, IaeTrapezoidal) {
  Eigen::VectorXd t(3), y(3), yhat(3);
  t << 0.0, 0.5, 1.5;
  y << 1.0, 2.0, 3.0;
  yhat << 0.0, 2.0, 1.0;  // |e| = 1, 0, 2
  // 0.5 * 0.5 * (1 + 0) + 0.5 * 1.0 * (0 + 2) = 0.25 + 1.0
  EXPECT_NEAR(Iae(t, y, yhat), 1.25, 1e-14);
  Eigen::VectorXd tu(3);
  tu << 0.0, 0.1, 0.2;
  EXPECT_NEAR(Iae(y, yhat, 0.1), Iae(tu, y, yhat), 1e-14);
  EXPECT_NEAR(Rmse(y, yhat), std::sqrt(5.0 / 3.0), 1e-14);
  FitMetrics m = ComputeFitMetrics(t, y, yhat);
  EXPECT_DOUBLE_EQ(m.max_abs_error, 2.0);
  EXPECT_NEAR(m.iae, 1.25, 1e-14);
}

TEST(FitMetricsTest, BadInputThrows) {
  Eigen::VectorXd y(3), yhat(2);
  y << 1, 2, 3;
  yhat << 1, 2;
  EXPECT_THAT([&] { NrmseFit(y, yhat); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("3 samples")));
  Eigen::VectorXd c = Eigen::VectorXd::Constant(3, 2.0);
  EXPECT_THAT([&] { NrmseFit(c, y); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("constant")));
  Eigen::VectorXd n = y;
  n[1] = std::nan("");
  EXPECT_THAT([&] { NrmseFit(n, y); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("not finite")));
  Eigen::VectorXd t(3);
  t << 0.0, 0.0, 1.0;
  EXPECT_THAT([&] { Iae(t, y, y); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("strictly increasing")));
  EXPECT_THROW(Iae(y, y, 0.0), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
