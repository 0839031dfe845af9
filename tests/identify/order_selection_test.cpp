#include "pneumid/identify/parametric/order_selection.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "parametric_test_util.hpp"
#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

Dataset DelayedPaperData(int extra_delay, Eigen::Index n = 4000) {
  PolynomialModel truth = testing::PaperArx();
  Eigen::VectorXd b = Eigen::VectorXd::Zero(truth.b[0].size() + extra_delay);
  b.tail(truth.b[0].size()) = truth.b[0];
  truth.b = {b};
  truth.nk = {1 + extra_delay};
  const Eigen::VectorXd u = testing::Prbs(n, 10.0, 90.0, 2, 5);
  const Eigen::VectorXd y = testing::SimulateArx(truth, u, testing::WhiteNoise(n, 0.5, 6));
  return Dataset::FromUniform(0.01, u, y);
}

TEST(OrderSelection, CriteriaPickThePaperStructure) {
  // Data from the paper's ARX(3,3,1): AIC, MDL and FPE select na = nb = 3, nk = 1.
  const Dataset d = DelayedPaperData(0);
  OrderSelectionOptions o;
  o.na = {1, 5};
  o.nb = {1, 5};
  o.nk = {0, 3};
  const OrderSelection s = SelectArxOrders(d, o);
  EXPECT_EQ(s.candidates.size(), 5u * 5u * 4u);
  for (auto c : {OrderCriterion::kMdl, OrderCriterion::kAicc}) {
    const OrderCandidate& b = s.candidates[s.Best(c)];
    EXPECT_EQ(b.na, 3) << ToString(c);
    EXPECT_EQ(b.nb, 3) << ToString(c);
    EXPECT_EQ(b.nk, 1) << ToString(c);
  }
  // The loss alone never penalises: it picks the largest model.
  const OrderCandidate& bl = s.candidates[s.Best(OrderCriterion::kLoss)];
  EXPECT_EQ(bl.na, 5);
  // Definitions (order_selection.hpp): AIC - MDL = d (2 - ln N), FPE from V.
  const OrderCandidate& c = s.candidates[0];
  const double N = static_cast<double>(s.num_rows);
  EXPECT_NEAR(c.aic - c.mdl, c.num_parameters * (2 - std::log(N)), 1e-9);
  EXPECT_NEAR(c.fpe, c.loss * (1 + c.num_parameters / N) / (1 - c.num_parameters / N), 1e-12);
  const auto j = s.ToJson();
  EXPECT_EQ(j["best"]["mdl"]["na"], 3);
  EXPECT_EQ(j["candidates"].size(), 100u);
}

// Offsets on the same record (u + 50, y + 100): the ARX models are fitted
// about the means (operating point auto), and the criteria pick the same
// structure as without them. Fitted to the raw signals, an ARX without an
// intercept spends its orders on the offset: every criterion picked 5, 5, 3
// on a helper's ARX(2,2,3) record.
TEST(OrderSelection, OffsetsDoNotChangeTheChoice) {
  const Dataset d = DelayedPaperData(0);
  const Dataset shifted = Dataset::FromUniform(0.01, (d.u(0).array() + 50.0).matrix(),
                                               (d.y(0).array() + 100.0).matrix());
  OrderSelectionOptions o;
  const OrderSelection a = SelectArxOrders(d, o), b = SelectArxOrders(shifted, o);
  EXPECT_NEAR(b.u0 - a.u0, 50.0, 1e-9);
  EXPECT_NEAR(b.y0 - a.y0, 100.0, 1e-9);
  for (auto c : {OrderCriterion::kMdl, OrderCriterion::kAicc}) {
    const OrderCandidate &x = a.candidates[a.Best(c)], &y = b.candidates[b.Best(c)];
    EXPECT_EQ(y.na, 3) << ToString(c);
    EXPECT_EQ(y.nb, 3) << ToString(c);
    EXPECT_EQ(y.nk, 1) << ToString(c);
    EXPECT_NEAR(y.loss, x.loss, 1e-6 * x.loss) << ToString(c);
  }
  // The raw signals (operating point zero) are what went wrong.
  o.operating_point = OperatingPointKind::kZero;
  const OrderSelection raw = SelectArxOrders(shifted, o);
  EXPECT_EQ(raw.u0, 0.0);
  EXPECT_GT(raw.candidates[raw.Best(OrderCriterion::kMdl)].loss,
            b.candidates[b.Best(OrderCriterion::kMdl)].loss);
}

TEST(OrderSelection, DelayEstimation) {
  EXPECT_EQ(EstimateDelay(DelayedPaperData(0), 2, 2, 0, 8), 1);
  EXPECT_EQ(EstimateDelay(DelayedPaperData(4), 2, 2, 0, 8), 5);
}

TEST(OrderSelection, ValidationDataLoss) {
  const Dataset est = DelayedPaperData(0, 3000);
  const Dataset val = DelayedPaperData(0, 2000);
  OrderSelectionOptions o;
  o.na = {3, 3};
  o.nb = {3, 3};
  o.nk = {1, 1};
  const OrderSelection s = SelectArxOrders(est, o, &val);
  ASSERT_EQ(s.candidates.size(), 1u);
  EXPECT_TRUE(s.validation);
  EXPECT_NEAR(s.candidates[0].loss, 0.25, 0.03);  // white noise variance 0.5^2
}

TEST(OrderSelection, RangeParsingAndErrors) {
  const OrderRange r = OrderRange::Parse("1:5");
  EXPECT_EQ(r.min, 1);
  EXPECT_EQ(r.max, 5);
  EXPECT_EQ(OrderRange::Parse("3").max, 3);
  EXPECT_THROW(OrderRange::Parse("5:1"), InvalidArgument);
  EXPECT_THROW(OrderRange::Parse("a:3"), InvalidArgument);
  EXPECT_THROW(OrderRange::Parse(""), InvalidArgument);
  OrderSelectionOptions o;
  o.nb = {0, 2};
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("nb range 0:2"));
  EXPECT_THROW(OrderCriterionFromString("bic"), InvalidArgument);
  EXPECT_THROW(SelectArxOrders(DelayedPaperData(0, 20), OrderSelectionOptions{}), DataError);
}

}  // namespace
}  // namespace pneumid
