// Parameter table, names, TOML writer and SetState of the IPA simulator
// (include/pneumid/plant/ipa_simulator.hpp).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/plant/ipa_simulator.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;

TEST(IpaParameterTable, EveryEntryHasARangeThatHoldsTheDefault) {
  const IpaParameters p;
  for (const auto& info : IpaParameterTable()) {
    EXPECT_LT(info.lower, info.upper) << info.key;
    const double v = GetIpaParameter(p, info.key);
    EXPECT_GE(v, info.lower) << info.key;
    EXPECT_LE(v, info.upper) << info.key;
  }
}

TEST(IpaParameterTable, NamesResolveByKeyOrUniqueLastPart) {
  EXPECT_EQ(FindIpaParameter("bore").key, "cylinder.bore");
  EXPECT_EQ(FindIpaParameter("valves.open_delay").key, "valves.open_delay");
  EXPECT_EQ(FindIpaParameter("frequency").key, "pwm.frequency");
  try {
    FindIpaParameter("diameter");
    FAIL() << "no error";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown IPA parameter 'diameter'"));
    EXPECT_THAT(e.what(), HasSubstr("cylinder.bore"));
  }
  IpaParameters p;
  SetIpaParameter(p, "exhaust_conductance", 3e-9);
  EXPECT_EQ(p.exhaust_conductance, 3e-9);
}

TEST(IpaParameterTable, TomlRoundTripIsExact) {
  IpaParameters p;
  p.mode = IpaMode::kPosition;
  p.pwm_mode = PwmMode::kAveraged;
  p.bore = 0.0213456789012345;
  p.inlet_conductance = 4.4309061254694033e-10;
  p.pwm_frequency = 100.0;  // integral value: must still be written as a float
  p.transport_delay_samples = 0;
  p.adc_bits = 12;
  p.force_offset = -1.5;
  const std::string path = testing::TempDir() + "/ipa_roundtrip.toml";
  {
    std::ofstream out(path);
    out << IpaParametersToToml(p, "calibrated\nfrom two files");
  }
  const IpaParameters q = LoadIpaParameters(path);
  for (const auto& info : IpaParameterTable())
    EXPECT_EQ(GetIpaParameter(q, info.key), GetIpaParameter(p, info.key)) << info.key;
  EXPECT_EQ(q.mode, p.mode);
  EXPECT_EQ(q.pwm_mode, p.pwm_mode);
  EXPECT_EQ(q.adc_bits, 12);
  EXPECT_EQ(q.transport_delay_samples, 0);
  std::remove(path.c_str());
}

TEST(IpaSimulator, SetStateIsMeasuredAtOnce) {
  IpaParameters p;
  p.pressure_noise = 0.0;
  p.adc_bits = 0;
  IpaSimulator sim(p, 0.01);
  const double pa = p.atmospheric_pressure + 3e5;
  sim.SetState(pa, sim.pressure_b(), sim.position());
  EXPECT_NEAR(sim.Measure(), p.AreaA() * 3e5, 1e-9);
  EXPECT_NEAR(sim.force(), p.AreaA() * 3e5, 1e-9);
  EXPECT_THROW(sim.SetState(-1.0, sim.pressure_b(), 0.0), InvalidArgument);
  EXPECT_THROW(sim.SetState(pa, sim.pressure_b(), 2.0 * p.stroke), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
