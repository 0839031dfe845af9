// Skogestad's half rule, closed forms from the rule itself [Skogestad 2003,
// J. Process Control 13, sec. 2.2] and the paper's continuous ARX model.
#include "pneumid/identify/step/half_rule.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/models/model_file.hpp"

namespace pneumid {
namespace {

Eigen::VectorXd Lag(double T) {
  Eigen::VectorXd v(2);
  v << T, 1.0;
  return v;
}

TEST(HalfRuleTest, FiveLags) {
  // 1 / ((s+1)(0.2s+1)(0.04s+1)(0.008s+1)(0.001s+1)):
  // FOPDT tau = 1 + 0.1, theta = 0.1 + 0.04 + 0.008 + 0.001;
  // SOPDT tau1 = 1, tau2 = 0.2 + 0.02, theta = 0.02 + 0.008 + 0.001.
  Eigen::VectorXd den = Lag(1.0);
  for (double T : {0.2, 0.04, 0.008, 0.001}) den = poly::Multiply(den, Lag(T));
  Eigen::VectorXd num(1);
  num << 1.0;
  const HalfRuleResult r = HalfRule(TransferFunction(num, den));
  EXPECT_NEAR(r.fopdt.K, 1.0, 1e-9);
  EXPECT_NEAR(r.fopdt.tau, 1.1, 1e-9);
  EXPECT_NEAR(r.fopdt.theta, 0.149, 1e-9);
  EXPECT_NEAR(r.sopdt.tau1, 1.0, 1e-9);
  EXPECT_NEAR(r.sopdt.tau2, 0.22, 1e-9);
  EXPECT_NEAR(r.sopdt.theta, 0.029, 1e-9);
  // Sample time h adds h/2 to the delay.
  EXPECT_NEAR(HalfRule(TransferFunction(num, den), 0.1).fopdt.theta, 0.199, 1e-9);
}

TEST(HalfRuleTest, ZerosAndDelay) {
  // (-0.3s+1)(0.08s+1) / ((2s+1)(s+1)(0.4s+1)(0.2s+1)(0.05s+1)^3):
  // the RHP zero adds 0.3 to the delay; the LHP zero 0.08 meets the lag 0.2
  // (tau~0 = min(0.2, 5 theta) = 0.2, theta = 1.55 without the zero), leaving
  // a lag of 0.12 and the gain 1. Then FOPDT tau = 2.5, theta = 1.47 and SOPDT
  // tau1 = 2, tau2 = 1.2, theta = 0.77.
  Eigen::VectorXd den = Lag(2.0);
  for (double T : {1.0, 0.4, 0.2, 0.05, 0.05, 0.05}) den = poly::Multiply(den, Lag(T));
  const Eigen::VectorXd num = poly::Multiply(Lag(-0.3), Lag(0.08));
  const HalfRuleResult r = HalfRule(TransferFunction(num, den));
  EXPECT_NEAR(r.fopdt.K, 1.0, 1e-9);
  EXPECT_NEAR(r.fopdt.tau, 2.5, 1e-6);
  EXPECT_NEAR(r.fopdt.theta, 1.47, 1e-6);
  EXPECT_NEAR(r.sopdt.tau1, 2.0, 1e-6);
  EXPECT_NEAR(r.sopdt.tau2, 1.2, 1e-6);
  EXPECT_NEAR(r.sopdt.theta, 0.77, 1e-6);
  // A pure delay passes through.
  const HalfRuleResult d = HalfRule(TransferFunction(num, den, 0.0, 0.5));
  EXPECT_NEAR(d.fopdt.theta, 1.97, 1e-6);
}

TEST(HalfRuleTest, PaperArxModel) {
  // docs/paper.md, reference value 3: continuous poles -4.41102, -138.290 +- 233.774j,
  // numerator 6.10237 s^2 - 91.9458 s + 520011.9. The complex pole pair becomes
  // a lag 2 zeta / w = 2 * 138.290 / |p|^2, the complex zero pair (negative s
  // coefficient) a delay 91.9458 / 520011.9.
  const double tau1 = 1.0 / 4.41102;
  const double tau_pair = 2.0 * 138.290 / (138.290 * 138.290 + 233.774 * 233.774);
  const double inverse = 91.9458 / 520011.9;
  const HalfRuleResult r = HalfRule(PaperArxModel());  // discrete: converted by zoh d2c
  EXPECT_NEAR(r.fopdt.K, 1.59796, 1e-4);
  EXPECT_NEAR(r.fopdt.tau, tau1 + tau_pair / 2, 1e-5);
  EXPECT_NEAR(r.fopdt.theta, tau_pair / 2 + inverse, 1e-6);
  EXPECT_NEAR(r.sopdt.tau1, tau1, 1e-5);
  EXPECT_NEAR(r.sopdt.tau2, tau_pair, 1e-6);
  EXPECT_NEAR(r.sopdt.theta, inverse, 1e-6);
  EXPECT_FALSE(r.notes.empty());
}

TEST(HalfRuleTest, Refusals) {
  Eigen::VectorXd num(1), unstable(2), integ(2);
  num << 1.0;
  unstable << 1.0, -1.0;
  integ << 1.0, 0.0;
  EXPECT_THAT([&] { HalfRule(TransferFunction(num, unstable)); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("stable")));
  EXPECT_THROW(HalfRule(TransferFunction(num, integ)), InvalidArgument);
  EXPECT_THROW(HalfRule(TransferFunction(num, Lag(1.0)), -1.0), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
