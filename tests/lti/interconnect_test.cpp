// Series, parallel, feedback and minimal realization.
#include "pneumid/lti/interconnect.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/models/model_file.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

Eigen::VectorXd V(std::initializer_list<double> v) {
  Eigen::VectorXd out(v.size());
  int i = 0;
  for (double x : v) out[i++] = x;
  return out;
}

TEST(InterconnectTest, SeriesMultipliesAndAddsDelays) {
  const TransferFunction g1 = TransferFunction::Continuous({1}, {1, 1}, 0.1);
  const TransferFunction g2 = TransferFunction::Continuous({2, 1}, {1, 3}, 0.2);
  const TransferFunction s = Series(g1, g2);
  EXPECT_EQ(s.num(), V({2, 1}));
  EXPECT_EQ(s.den(), V({1, 4, 3}));
  EXPECT_NEAR(s.delay(), 0.3, 1e-15);
  const std::complex<double> w = s.FrequencyResponse(2.0);
  EXPECT_NEAR(std::abs(w - g1.FrequencyResponse(2.0) * g2.FrequencyResponse(2.0)), 0.0, 1e-14);
}

TEST(InterconnectTest, ParallelAddsResponses) {
  const TransferFunction g1 = TransferFunction::Continuous({1}, {1, 1});
  const TransferFunction g2 = TransferFunction::Continuous({2}, {1, 3});
  const TransferFunction p = Parallel(g1, g2);
  EXPECT_EQ(p.num(), V({3, 5}));  // (s + 3) + 2 (s + 1)
  EXPECT_EQ(p.den(), V({1, 4, 3}));
  // Discrete models with different delays are still rational.
  const TransferFunction d1 = TransferFunction::Discrete({0, 1}, {1, -0.5}, 0.1, 1);
  const TransferFunction d2 = TransferFunction::Discrete({0, 2}, {1, -0.2}, 0.1);
  const TransferFunction dp = Parallel(d1, d2);
  for (double w : {0.3, 3.0, 20.0}) {
    EXPECT_NEAR(
        std::abs(dp.FrequencyResponse(w) - d1.FrequencyResponse(w) - d2.FrequencyResponse(w)), 0.0,
        1e-13);
  }
  EXPECT_THAT([&] { Parallel(g1.WithDelay(0.1), g2); },
              ThrowsMessage<InvalidArgument>(HasSubstr("delays differ")));
  EXPECT_THAT([&] { Parallel(g1, d2); },
              ThrowsMessage<InvalidArgument>(HasSubstr("continuous or both discrete")));
  EXPECT_THAT([&] { Series(d1, TransferFunction::Discrete({1}, {1}, 0.2)); },
              ThrowsMessage<InvalidArgument>(HasSubstr("sample times differ")));
}

TEST(InterconnectTest, FeedbackClosedForms) {
  // K / (s + 1) with unity negative feedback: K / (s + 1 + K).
  const TransferFunction g = TransferFunction::Continuous({4}, {1, 1});
  const TransferFunction t = Feedback(g);
  EXPECT_EQ(t.num(), V({4}));
  EXPECT_EQ(t.den(), V({1, 5}));
  // Positive feedback: K / (s + 1 - K).
  EXPECT_EQ(Feedback(g, TransferFunction(), +1).den(), V({1, -3}));
  // Discrete with delay in the loop: the delay is absorbed.
  const TransferFunction gd = TransferFunction::Discrete({0, 0.5}, {1, -0.5}, 0.1, 2);
  const TransferFunction td = Feedback(gd);
  for (double w : {0.5, 5.0, 25.0}) {
    const std::complex<double> gw = gd.FrequencyResponse(w);
    EXPECT_NEAR(std::abs(td.FrequencyResponse(w) - gw / (1.0 + gw)), 0.0, 1e-13);
  }
  EXPECT_NEAR(td.DcGain(), 0.5, 1e-14);
  EXPECT_THAT([&] { Feedback(g.WithDelay(0.1)); },
              ThrowsMessage<InvalidArgument>(HasSubstr("non-rational")));
  EXPECT_THAT([&] { Feedback(g, TransferFunction(), 2); },
              ThrowsMessage<InvalidArgument>(HasSubstr("sign must be")));
  // 1 + g h = 0 identically at high frequency: ill-posed.
  const TransferFunction one = TransferFunction::Continuous({-1}, {1});
  EXPECT_THAT([&] { Feedback(one); }, ThrowsMessage<InvalidArgument>(HasSubstr("ill-posed")));
}

TEST(InterconnectTest, MinimalRealizationCancelsPairs) {
  // (s + 1)(s + 2) / ((s + 1)(s + 3)(s + 4)) -> (s + 2) / ((s + 3)(s + 4)).
  const TransferFunction g = TransferFunction::Continuous({2, 6, 4}, {1, 8, 19, 12}, 0.2);
  const TransferFunction m = MinimalRealization(g).Normalized();
  EXPECT_EQ(m.Order(), 2);
  EXPECT_LT((m.num() - V({2, 4})).norm(), 1e-12);
  EXPECT_LT((m.den() - V({1, 7, 12})).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(m.delay(), 0.2);
  // Nothing to cancel: unchanged.
  EXPECT_EQ(MinimalRealization(PaperFopdtModel()).Order(), 1);
  // Discrete: (z - 0.5) / ((z - 0.5)(z - 0.8)) -> 1 / (z - 0.8) = z^-1 / (1 - 0.8 z^-1).
  const TransferFunction d = TransferFunction::Discrete({0, 1, -0.5}, {1, -1.3, 0.4}, 0.1);
  const TransferFunction md = MinimalRealization(d).Normalized();
  EXPECT_EQ(md.Order(), 1);
  EXPECT_LT((md.num() - V({0, 1})).norm(), 1e-12);
  EXPECT_LT((md.den() - V({1, -0.8})).norm(), 1e-12);
  EXPECT_THAT([&] { MinimalRealization(g, -1); },
              ThrowsMessage<InvalidArgument>(HasSubstr("tol must be >= 0")));
}

}  // namespace
}  // namespace pneumid
