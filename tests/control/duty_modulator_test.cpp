// DutyModulator and ModulatedController against the definition of a
// first-order sigma-delta modulator (duty_modulator.hpp): the applied input
// never lies inside a gap, its running sum follows the requests' within the
// widest gap, and inputs outside the gaps pass unchanged.
#include "pneumid/control/duty_modulator.hpp"

#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

const std::vector<InputGap> kIpaGaps = {{0.0, 15.0}, {85.0, 100.0}};

TEST(DutyModulator, InputsOutsideTheGapsPassUnchanged) {
  DutyModulator m(kIpaGaps);
  for (double v : {0.0, 15.0, 20.0, 50.0, 84.9, 85.0, 100.0}) EXPECT_DOUBLE_EQ(m.Next(v), v);
  EXPECT_DOUBLE_EQ(m.error(), 0.0);
}

TEST(DutyModulator, TheMeanOfTheAppliedInputsFollowsTheRequests) {
  for (double v : {0.61, 5.0, 14.0, 86.0, 88.0, 92.5, 99.0}) {
    DutyModulator m(kIpaGaps);
    double sum_applied = 0.0;
    const int n = 1000;
    for (int k = 0; k < n; ++k) {
      const double a = m.Next(v);
      for (const InputGap& g : kIpaGaps) EXPECT_FALSE(a > g.lo && a < g.hi) << a;
      sum_applied += a;
      // Error feedback: sum of requests - sum of applied = the carried error.
      EXPECT_NEAR((k + 1) * v - sum_applied, m.error(), 1e-9 * n * 100);
      EXPECT_LE(std::abs(m.error()), 15.0);
    }
    EXPECT_NEAR(sum_applied / n, v, 15.0 / n) << "request " << v;
  }
}

TEST(DutyModulator, ARequestBeyondTheRangeDoesNotWindUpTheError) {
  DutyModulator m(kIpaGaps);
  for (int k = 0; k < 100; ++k) m.Next(150.0);  // beyond 100 %: applied as is, error bounded
  EXPECT_LE(std::abs(m.error()), 15.0);
  // Back inside: the modulator answers within one gap's width at once.
  EXPECT_NEAR(m.Next(50.0), 50.0, 15.0);
}

TEST(DutyModulator, TheAppliedInputStaysWithinTheLimits) {
  DutyModulator m(kIpaGaps, 0.0, 100.0);
  // A request that alternates near the top: w = v + e would pass 100 %.
  for (int k = 0; k < 200; ++k) {
    const double a = m.Next(k % 2 == 0 ? 99.0 : 100.0);
    EXPECT_GE(a, 0.0);
    EXPECT_LE(a, 100.0);
  }
  // Beyond the range nothing is carried: back inside, the request passes.
  for (int k = 0; k < 50; ++k) EXPECT_DOUBLE_EQ(m.Next(120.0), 100.0);
  EXPECT_DOUBLE_EQ(m.error(), 0.0);
  EXPECT_DOUBLE_EQ(m.Next(50.0), 50.0);
  EXPECT_THROW(DutyModulator(kIpaGaps, 10.0, 0.0), InvalidArgument);
}

TEST(DutyModulator, ParsesAndPrintsGaps) {
  EXPECT_EQ(ParseInputGaps("0:15,85:100"), kIpaGaps);
  EXPECT_EQ(InputGapsToString(kIpaGaps), "0:15,85:100");
  EXPECT_TRUE(ParseInputGaps("").empty());
  EXPECT_TRUE(ParseInputGaps("none").empty());
  EXPECT_THROW(ParseInputGaps("15:0"), InvalidArgument);
  EXPECT_THROW(ParseInputGaps("0:15,10:20"), InvalidArgument);
  EXPECT_THROW(ParseInputGaps("0-15"), InvalidArgument);
  EXPECT_THROW(ParseInputGaps("a:b"), InvalidArgument);
  try {
    ParseInputGaps("0:15,x:3");
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("'x:3'"), std::string::npos) << e.what();
  }
}

// A controller that asks for a fixed input.
class Constant : public Controller {
 public:
  explicit Constant(double v) : v_(v) {}
  double Ts() const override { return 0.01; }
  std::string Describe() const override { return "constant"; }
  int applied_calls = 0;

 protected:
  void DoReset(double, double) override {}
  double DoUpdate(double, double) override { return v_; }
  void DoApplied(double) override { ++applied_calls; }

 private:
  double v_;
};

TEST(ModulatedController, ModulatesTheInnerControllersRequest) {
  auto inner = std::make_unique<Constant>(90.0);
  Constant* raw = inner.get();
  ModulatedController c(std::move(inner), kIpaGaps);
  EXPECT_NE(c.Describe().find("sigma-delta modulation over the input gaps 0:15,85:100"),
            std::string::npos);
  c.Reset(0.0, 0.0);
  double sum = 0.0;
  for (int k = 0; k < 300; ++k) {
    const double u = c.Update(100.0, 0.0);
    EXPECT_TRUE(u == 85.0 || u == 100.0) << u;
    EXPECT_DOUBLE_EQ(c.last_request(), 90.0);
    c.Applied(u);  // the applied input is the modulated one: not a limit
    sum += u;
  }
  EXPECT_NEAR(sum / 300, 90.0, 15.0 / 300);
  EXPECT_EQ(raw->applied_calls, 0);
  c.Applied(40.0);  // a limit that cut the request: passed on
  EXPECT_EQ(raw->applied_calls, 1);
  EXPECT_THROW(ModulatedController(nullptr, kIpaGaps), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
