// ARX(3,3,1) and its continuous (d2c) form from the IPA simulator's PRBS data,
// the way the paper obtains its Eq. 5-6 from the measured actuator.
#include <gtest/gtest.h>

#include "pneumid/identify/parametric/parametric.hpp"
#include "pneumid/identify/evaluation/residual_analysis.hpp"
#include "pneumid/plant/experiment.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/plant/signal.hpp"

namespace pneumid {
namespace {

TEST(ParametricPlant, ArxAndD2cFromSimulatedIpaPrbsData) {
  auto plant = MakePlant("ipa", 0.01);
  const auto input = ParseSignal("prbs:low=20,high=80,order=7,clock=0.05,seed=3");
  const Experiment e = RunExperiment(*plant, *input, 20.0);
  ASSERT_GE(e.data.size(), 2000);
  const IdentifiedModel m = IdentifyParametric("arx", e.data, IdentifyRequest{});
  EXPECT_EQ(m.structure, "ARX");
  EXPECT_EQ(m.params.Vector("a").size(), 4u);
  EXPECT_EQ(m.params.Vector("b").size(), 4u);
  EXPECT_EQ(std::get<int>(m.params.at("nk")), 1);
  ASSERT_TRUE(m.discrete.has_value());
  EXPECT_TRUE(m.discrete->IsStable());
  EXPECT_GT(m.discrete->DcGain(), 0.0);  // more duty, more force
  // The continuous form of Eq. 6: a third-order model with a proper numerator,
  // whose DC gain equals the discrete one (zoh and tustin both preserve it).
  // A discrete pole on the negative real axis (PWM ripple aliased to the
  // Nyquist frequency) has no zoh equivalent: tustin is used and noted.
  ASSERT_TRUE(m.tf.IsContinuous());
  EXPECT_EQ(m.tf.Order(), 3);
  EXPECT_NEAR(m.tf.DcGain(), m.discrete->DcGain(), 1e-6 * std::abs(m.discrete->DcGain()));
  bool negative_real_pole = false;
  for (const auto& p : m.discrete->Poles())
    negative_real_pole |= std::abs(p.imag()) < 1e-12 && p.real() < 0.0;
  if (negative_real_pole) {
    ASSERT_FALSE(m.notes.empty());
    EXPECT_NE(m.notes[0].find("tustin"), std::string::npos);
  }
  // A linear ARX model of the nonlinear, PWM-driven actuator explains only part
  // of the PRBS response variation (simulation fit about 50-75 %, depending on
  // the twin's parameters).
  EXPECT_GT(m.fit_percent, 40.0);
}

}  // namespace
}  // namespace pneumid
