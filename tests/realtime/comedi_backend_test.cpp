// The comedi backend without a card: configuration, conversion math and the
// error for a missing device. Reads and writes on a card are not exercised here.
#include "pneumid/realtime/comedi_backend.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"

#ifdef PNEUMID_HAVE_COMEDI
#include <comedilib.h>
#endif

namespace pneumid {
namespace {

using ::testing::HasSubstr;

TEST(ComediConfig, PressureAndForceCalibration) {
  ComediConfig c;
  // 0-10 V transducer for 0-1 MPa; F = p_s A_a - p A_b with A_a = A_b = 4.9e-4 m^2.
  c.pressure_gain = 1e5;
  c.pressure_offset = 0.0;
  c.force_gain = -4.9e-4;
  c.force_offset = 6e5 * 4.9e-4;
  double p = 0.0;
  EXPECT_NEAR(c.VoltsToForce(6.0, &p), 0.0, 1e-9);  // both chambers at 0.6 MPa
  EXPECT_NEAR(p, 6e5, 1e-6);
  EXPECT_NEAR(c.VoltsToForce(0.0), 294.0, 1e-9);
  EXPECT_TRUE(c.VoltsOutOfRange(10.5));
  EXPECT_TRUE(c.VoltsOutOfRange(std::nan("")));
  EXPECT_FALSE(c.VoltsOutOfRange(5.0));
}

TEST(ComediConfig, DutyToValveLevelsAndSafeStates) {
  ComediConfig c;
  c.v_closed = 0.0;
  c.v_open = 5.0;
  double vi = 0.0, ve = 0.0;
  c.DutyToVolts(20.0, &vi, &ve);
  EXPECT_DOUBLE_EQ(vi, 1.0);
  EXPECT_DOUBLE_EQ(ve, 4.0);  // complementary exhaust
  c.DutyToVolts(150.0, &vi, &ve);
  EXPECT_DOUBLE_EQ(vi, 5.0);
  EXPECT_DOUBLE_EQ(ve, 0.0);
  c.exhaust_complementary = false;
  c.DutyToVolts(20.0, &vi, &ve);
  EXPECT_DOUBLE_EQ(ve, 0.0);
  c.SafeStateVolts(SafeState::kHold, &vi, &ve);
  EXPECT_DOUBLE_EQ(vi, 0.0);
  EXPECT_DOUBLE_EQ(ve, 0.0);
  c.SafeStateVolts(SafeState::kRelease, &vi, &ve);
  EXPECT_DOUBLE_EQ(vi, 0.0);
  EXPECT_DOUBLE_EQ(ve, 5.0);
}

TEST(ComediConfig, InvalidConfigurationsAreRejected) {
  ComediConfig c;
  std::string error;
  EXPECT_TRUE(c.IsValid(&error)) << error;
  c.exhaust_channel = c.inlet_channel;
  EXPECT_FALSE(c.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("different channels"));
  c = ComediConfig{};
  c.device = "comedi0";
  EXPECT_FALSE(c.IsValid(&error));
  c = ComediConfig{};
  c.v_min = 5;
  c.v_max = 1;
  EXPECT_FALSE(c.IsValid(&error));
  EXPECT_THROW(ComediBackend{c}, InvalidArgument);
  EXPECT_EQ(AnalogReferenceFromString("diff"), AnalogReference::kDiff);
  EXPECT_THROW(AnalogReferenceFromString("x"), InvalidArgument);
}

TEST(ComediBackend, MissingDeviceIsADataErrorNamingIt) {
  ComediConfig c;
  c.device = "/dev/comedi_pneumid_missing";
  ComediBackend io(c);
  try {
    io.Open(0.01);
    FAIL() << "opened a missing device";
  } catch (const DataError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/dev/comedi_pneumid_missing"));
  }
  Measurement m;
  EXPECT_EQ(io.Read(&m), IoStatus::kError);  // not open: an error status, no crash
  EXPECT_EQ(io.Write(10.0), IoStatus::kError);
}

#ifdef PNEUMID_HAVE_COMEDI
// comedi_to_phys / comedi_from_phys on the PCI-6221's 16-bit +-10 V range, as the
// backend uses them when no calibration polynomial is available.
TEST(ComediConversion, NominalRangeOfA16BitConverter) {
  EXPECT_TRUE(ComediAvailable());
  comedi_range r{-10.0, 10.0, UNIT_volt};
  const lsampl_t maxdata = 65535;
  comedi_set_global_oor_behavior(COMEDI_OOR_NUMBER);  // rails as numbers for this check
  EXPECT_NEAR(comedi_to_phys(0, &r, maxdata), -10.0, 1e-12);
  EXPECT_NEAR(comedi_to_phys(65535, &r, maxdata), 10.0, 1e-12);
  EXPECT_NEAR(comedi_to_phys(49151, &r, maxdata), -10.0 + 20.0 * 49151 / 65535, 1e-12);
  EXPECT_EQ(comedi_from_phys(0.0, &r, maxdata), 32768u);  // rounds to the nearest code
  EXPECT_EQ(comedi_from_phys(5.0, &r, maxdata), 49151u);
  EXPECT_EQ(comedi_from_phys(12.0, &r, maxdata), 65535u);  // saturates
  comedi_set_global_oor_behavior(COMEDI_OOR_NAN);
  EXPECT_TRUE(std::isnan(comedi_to_phys(65535, &r, maxdata)));  // rail reads as NaN
  comedi_set_global_oor_behavior(COMEDI_OOR_NUMBER);
}
#endif

}  // namespace
}  // namespace pneumid
