// The multi-level pseudo-random signal prbs-levels: values against an
// independent Python computation (gen_prbs_levels.py beside this file),
// clock-period hold, shaping, round trip of the spec and errors.
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/plant/signal.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

struct LevelsCase {
  double low, high;
  int levels;
  std::uint64_t seed;
  std::vector<double> values;
};

TEST(PrbsLevelsTest, MatchesTheReferenceSequence) {
  const std::vector<LevelsCase> cases = {
#include "prbs_levels_cases.inc"
  };
  for (const LevelsCase& c : cases) {
    const std::string spec = fmt::format("prbs-levels:low={},high={},levels={},clock=0.2,seed={}",
                                         c.low, c.high, c.levels, c.seed);
    SCOPED_TRACE(spec);
    const auto s = ParseSignal(spec);
    for (std::size_t k = 0; k < c.values.size(); ++k) {
      const double t = 0.2 * static_cast<double>(k);
      EXPECT_DOUBLE_EQ((*s)(t), c.values[k]) << k;
      EXPECT_DOUBLE_EQ((*s)(t + 0.199), c.values[k]) << k;  // held for the clock period
    }
  }
}

TEST(PrbsLevelsTest, UsesEveryLevelAndStartsAtLow) {
  const auto s = ParseSignal("prbs-levels:low=20,high=80,levels=5,clock=0.2,seed=1,at=0.5");
  EXPECT_DOUBLE_EQ((*s)(0.49), 20.0);
  const Eigen::VectorXd v = s->Sample(0.01, 6000);
  std::set<double> seen(v.data(), v.data() + v.size());
  EXPECT_EQ(seen, (std::set<double>{20, 35, 50, 65, 80}));
  // The spec written back reads as the same signal.
  EXPECT_EQ(s->ToString(), "prbs-levels:low=20,high=80,levels=5,clock=0.2,seed=1,at=0.5");
  const auto again = ParseSignal(s->ToString());
  EXPECT_EQ(again->Sample(0.01, 6000), v);
  // Another seed gives another sequence; shaping applies.
  EXPECT_NE(ParseSignal("prbs-levels:low=20,high=80,levels=5,clock=0.2,seed=2")->Sample(0.01, 600),
            ParseSignal("prbs-levels:low=20,high=80,levels=5,clock=0.2,seed=1")->Sample(0.01, 600));
  const auto shaped = ParseSignal("prbs-levels:low=0,high=10,levels=2,clock=1,max=5");
  const Eigen::VectorXd w = shaped->Sample(1.0, 50);
  EXPECT_LE(w.maxCoeff(), 5.0);
}

TEST(PrbsLevelsTest, RejectsBadSpecs) {
  EXPECT_THAT(
      [] { ParseSignal("prbs-levels:levels=1,clock=0.1"); },
      ThrowsMessage<InvalidArgument>(HasSubstr("levels must be an integer in 2..1000, got 1")));
  EXPECT_THAT([] { ParseSignal("prbs-levels:levels=2.5,clock=0.1"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("got 2.5")));
  EXPECT_THAT([] { ParseSignal("prbs-levels:clock=0"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("clock must be positive, got 0")));
  EXPECT_THAT(
      [] { ParseSignal("prbs-levels:clock=0.1,seed=-1"); },
      ThrowsMessage<InvalidArgument>(HasSubstr("seed must be an integer in 0..2^53, got -1")));
  EXPECT_THAT([] { ParseSignal("prbs-levels:clock=0.1,order=7"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("order")));
}

}  // namespace
}  // namespace pneumid
