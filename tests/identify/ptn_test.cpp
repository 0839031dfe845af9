// Equivalent PTn by the tangent-line method, paper Eq. 3 and
// docs/paper.md, reference value 5.
#include "pneumid/identify/step/ptn.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

TEST(PtnTest, PaperSecondOrder) {
  // td ~ 0.001 s, tTL ~ 0.2377 s give the paper's a1 = 0.2387 and a2 = 2.39e-4
  // (printed with 3-4 significant digits).
  const std::vector<double> a = PtnCoefficients(0.001, 0.2377, 2);
  ASSERT_EQ(a.size(), 3u);
  EXPECT_DOUBLE_EQ(a[0], 1.0);
  EXPECT_NEAR(a[1], 0.2387, 1e-12);
  EXPECT_NEAR(a[2], (0.001 / 2 + 0.2377) * 0.001, 1e-15);
  EXPECT_NEAR(a[2], 2.39e-4, 0.01 * 2.39e-4);
  const TransferFunction g = PtnModel(1.6, 0.001, 0.2377, 2);
  EXPECT_NEAR(g.DcGain(), 1.6, 1e-12);
  EXPECT_EQ(g.Order(), 2);
  EXPECT_TRUE(g.IsStable());
}

TEST(PtnTest, ThirdOrderIsTheTaylorExpansion) {
  // a3 = (td/6 + tTL/2) td^2 (the paper's print lacks one factor td).
  const double td = 0.3, tTL = 1.7;
  const std::vector<double> a = PtnCoefficients(td, tTL, 4);
  EXPECT_NEAR(a[1], td + tTL, 1e-15);
  EXPECT_NEAR(a[2], (td / 2 + tTL) * td, 1e-15);
  EXPECT_NEAR(a[3], (td / 6 + tTL / 2) * td * td, 1e-15);
  EXPECT_NEAR(a[4], std::pow(td, 4) / 24 + tTL * std::pow(td, 3) / 6, 1e-15);
  // Closed form: the series of (1 + tTL s) exp(td s) at s = 0.1 converges to it.
  const std::vector<double> b = PtnCoefficients(td, tTL, 12);
  double sum = 0.0, s = 0.1;
  for (std::size_t i = 0; i < b.size(); ++i) sum += b[i] * std::pow(s, i);
  EXPECT_NEAR(sum, (1 + tTL * s) * std::exp(td * s), 1e-14);
}

TEST(PtnTest, BadArguments) {
  EXPECT_THAT([] { PtnCoefficients(-0.1, 1.0, 2); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("td")));
  EXPECT_THROW(PtnCoefficients(0.1, 0.0, 2), InvalidArgument);
  EXPECT_THROW(PtnCoefficients(0.1, 1.0, 0), InvalidArgument);
  EXPECT_THROW(PtnModel(std::nan(""), 0.1, 1.0, 2), InvalidArgument);
  // td = 0: the expansion is 1 + tTL s for any n.
  EXPECT_EQ(PtnModel(2.0, 0.0, 1.0, 3).Order(), 1);
}

}  // namespace
}  // namespace pneumid
