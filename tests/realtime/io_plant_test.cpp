// IoPlant: a Plant over an IoBackend. Measure() is the backend's reading plus
// the load disturbance (an output disturbance, as the simulated plants apply
// it), NaN when the read fails; Reset() clears the load; the destructor leaves
// the actuator in its release state.
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "pneumid/realtime/io_plant.hpp"
#include "test_support.hpp"

namespace pneumid {
namespace {

using testing::FaultyBackend;
using testing::FirstOrderPlant;
using testing::Injected;

TEST(IoPlant, MeasureIsTheBackendReadingPlusTheLoadDisturbance) {
  const double Ts = 0.01;
  IoPlant plant(std::make_unique<FaultyBackend>(Ts, Injected::kNone, 0), Ts, false);
  FirstOrderPlant reference(Ts, 0.9, 0.1);  // the backend's plant, driven alike
  for (int k = 0; k < 5; ++k) {
    EXPECT_DOUBLE_EQ(plant.Measure(), reference.Measure()) << "sample " << k;
    plant.Advance(1.0);
    reference.Advance(1.0);
  }
  // y_5 = 1 - 0.9^5 for a unit step through y+ = 0.9 y + 0.1 u.
  EXPECT_NEAR(plant.Measure(), 1.0 - std::pow(0.9, 5), 1e-12);
  plant.SetLoadDisturbance(-0.25);
  EXPECT_NEAR(plant.Measure(), 1.0 - std::pow(0.9, 5) - 0.25, 1e-12);
  EXPECT_DOUBLE_EQ(plant.time(), 5 * Ts);
  EXPECT_FALSE(plant.can_reset());
  EXPECT_TRUE(reference.can_reset());
  plant.Reset();  // the clock and the load restart; the plant keeps its state
  EXPECT_DOUBLE_EQ(plant.time(), 0.0);
  EXPECT_NEAR(plant.Measure(), 1.0 - std::pow(0.9, 5), 1e-12);
}

TEST(IoPlant, AFailedReadIsNaNWhateverTheLoad) {
  const double Ts = 0.01;
  IoPlant plant(std::make_unique<FaultyBackend>(Ts, Injected::kReadError, 2), Ts, false);
  plant.SetLoadDisturbance(3.0);
  EXPECT_DOUBLE_EQ(plant.Measure(), 3.0);
  plant.Advance(0.0);
  plant.Advance(0.0);
  EXPECT_TRUE(std::isnan(plant.Measure()));
  EXPECT_EQ(plant.last_status(), IoStatus::kError);
}

}  // namespace
}  // namespace pneumid
