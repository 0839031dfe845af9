// The position twin (IpaSimulator in position mode, docs/position.md) against
// closed forms: pressure balance at rest, end pressures at full command,
// breakaway at the static friction force, the dead band of the minimum pulse.
#include <cmath>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/plant/actuator.hpp"
#include "pneumid/plant/ipa_simulator.hpp"
#include "pneumid/plant/plant_factory.hpp"

namespace pneumid {
namespace {

IpaParameters QuietRig() {
  IpaParameters p = DefaultIpaParameters(IpaMode::kPosition);
  p.position_noise = 0.0;
  p.adc_bits = 0;
  return p;
}

TEST(IpaPositionTest, StartsBalancedAndStaysWithTheValvesClosed) {
  // Reset: p_b = p_atm + p_s/2 and A_a (p_a - p_atm) = A_b (p_b - p_atm): no
  // net force, the piston stays where it is.
  const IpaParameters p = QuietRig();
  IpaSimulator sim(p, 0.01);
  const double patm = p.atmospheric_pressure;
  EXPECT_NEAR(sim.pressure_b(), patm + 0.5 * p.supply_pressure, 1e-6);
  EXPECT_NEAR(sim.rod_force(), 0.0, 1e-9);
  for (int k = 0; k < 100; ++k) sim.Advance(0.0);
  EXPECT_NEAR(sim.position(), p.piston_position, 1e-9);
  EXPECT_NEAR(sim.pressure_a(), patm + p.AreaB() / p.AreaA() * 0.5 * p.supply_pressure, 1e-6);
  EXPECT_NEAR(sim.Measure(), p.piston_position, 1e-12);
}

TEST(IpaPositionTest, FullCommandDrivesToTheEndStopsWithSupplyAndAtmosphere) {
  // +100 %: A's inlet and B's exhaust stay open, so p_a -> p_s (absolute),
  // p_b -> p_atm and the piston rests on the far end stop, x = stroke plus the
  // stop spring's give, (A_a p_s,gauge) / k_stop. -100 %: the reverse.
  const IpaParameters p = QuietRig();
  const double ps = p.supply_pressure + p.atmospheric_pressure;
  IpaSimulator sim(p, 0.01);
  for (int k = 0; k < 300; ++k) sim.Advance(100.0);
  EXPECT_NEAR(sim.pressure_a(), ps, 1e-3 * p.supply_pressure);
  EXPECT_NEAR(sim.pressure_b(), p.atmospheric_pressure, 1e-3 * p.supply_pressure);
  const double push = p.AreaA() * p.supply_pressure;
  EXPECT_NEAR(sim.position(), p.stroke + push / p.end_stop_stiffness, 2e-6);
  for (int k = 0; k < 300; ++k) sim.Advance(-100.0);
  EXPECT_NEAR(sim.pressure_b(), ps, 1e-3 * p.supply_pressure);
  EXPECT_NEAR(sim.pressure_a(), p.atmospheric_pressure, 1e-3 * p.supply_pressure);
  EXPECT_NEAR(sim.position(), -p.AreaB() * p.supply_pressure / p.end_stop_stiffness, 2e-6);
  // Above +-100 % the command is clipped.
  IpaSimulator clipped(p, 0.01);
  for (int k = 0; k < 30; ++k) clipped.Advance(250.0);
  IpaSimulator full(p, 0.01);
  for (int k = 0; k < 30; ++k) full.Advance(100.0);
  EXPECT_EQ(clipped.position(), full.position());
}

TEST(IpaPositionTest, SignOfTheCommandSetsTheDirection) {
  const IpaParameters p = QuietRig();
  IpaSimulator out(p, 0.01), in(p, 0.01);
  for (int k = 0; k < 10; ++k) {
    out.Advance(30.0);
    in.Advance(-30.0);
  }
  EXPECT_GT(out.position() - p.piston_position, 1e-3);
  EXPECT_LT(in.position() - p.piston_position, -1e-3);
}

TEST(IpaPositionTest, PulsesShorterThanTheMinimumWidthDoNotOpenTheValves) {
  // Dead band: |u| < 100 w_min f_pwm gives pulses shorter than w_min.
  const IpaParameters p = QuietRig();
  const double band = 100.0 * p.min_pulse_width * p.pwm_frequency;
  ASSERT_GT(band, 1.0);
  IpaSimulator sim(p, 0.01);
  const double pa = sim.pressure_a(), pb = sim.pressure_b();
  for (int k = 0; k < 50; ++k) sim.Advance(k % 2 ? 0.95 * band : -0.95 * band);
  EXPECT_EQ(sim.pressure_a(), pa);
  EXPECT_EQ(sim.pressure_b(), pb);
  EXPECT_EQ(sim.position(), p.piston_position);
  IpaSimulator moved(p, 0.01);
  moved.Advance(1.05 * band);
  EXPECT_GT(moved.pressure_a(), pa);
  EXPECT_LT(moved.pressure_b(), pb);
  // The actuator lists the gaps on both sides of 0 and below +-100 %.
  const Actuator a = PlantActuator(sim);
  EXPECT_EQ(a.u_min, -100.0);
  EXPECT_EQ(a.u_max, 100.0);
  ASSERT_EQ(a.input_gaps.size(), 4u);
  EXPECT_NEAR(a.input_gaps[1].lo, -band, 1e-9);
  EXPECT_NEAR(a.input_gaps[2].hi, band, 1e-9);
  EXPECT_EQ(a.input_label, "command");
}

TEST(IpaPositionTest, LuGrePistonSticksBelowCoulombAndBreaksAwayAboveStaticFriction) {
  // LuGre [4]: a force below F_c is taken by the bristles (deflection z = F /
  // sigma0) and the piston sticks; above F_s it slides. (Between the two, a
  // suddenly applied force may slip: the Stribeck drop of the model.) The
  // chambers are set so that the pressure force is the given share; the
  // valves stay closed.
  IpaParameters p = QuietRig();
  p.lugre_stiffness = 1e6;
  p.lugre_damping = 1000.0;
  p.static_friction = 20.0;
  p.coulomb_friction = 15.0;
  const double patm = p.atmospheric_pressure;
  const double pb = patm + 0.3e6;
  auto pressure_a_for = [&](double force) {
    return patm + (force + p.AreaB() * (pb - patm)) / p.AreaA();
  };
  for (double F : {0.9 * p.coulomb_friction, -0.9 * p.coulomb_friction}) {
    IpaSimulator sim(p, 0.01);
    sim.SetState(pressure_a_for(F), pb, 0.05);
    EXPECT_NEAR(sim.rod_force(), F, 1e-9);
    for (int k = 0; k < 50; ++k) sim.Advance(0.0);
    // Pre-sliding: on loading dz/dx = 1 - sigma0 z / g, so x runs ahead of z,
    // x = -(g / sigma0) ln(1 - F / g) ~ 1.1 F_s / sigma0 here (plus the
    // overshoot of the bristle spring); it stays within a few F_s / sigma0.
    EXPECT_LT(std::abs(sim.position() - 0.05), 5.0 * p.static_friction / p.lugre_stiffness)
        << "F " << F;
    EXPECT_NEAR(sim.bristle_deflection(), F / p.lugre_stiffness,
                0.02 * std::abs(F) / p.lugre_stiffness);
    EXPECT_NEAR(sim.velocity(), 0.0, 1e-6);
  }
  for (double F : {1.1 * p.static_friction, -1.1 * p.static_friction}) {
    IpaSimulator sim(p, 0.01);
    sim.SetState(pressure_a_for(F), pb, 0.05);
    for (int k = 0; k < 50; ++k) sim.Advance(0.0);
    EXPECT_GT(std::copysign(1.0, F) * (sim.position() - 0.05), 3e-4) << "F " << F;
  }
}

TEST(IpaPositionTest, StribeckPistonCreepsBelowBreakawayAtTheSmoothedSignsSpeed) {
  // Static map: at a net force F < g(0) = F_s the smoothed sign balances it at
  // v = v_eps atanh(F / F_s) (viscous term negligible): a creep, no sticking.
  IpaParameters p = QuietRig();
  p.static_friction = p.coulomb_friction = 10.0;  // flat g(v): a closed form for v
  p.viscous_friction = 0.0;
  p.mass = 0.1;
  const double patm = p.atmospheric_pressure;
  const double pb = patm + 0.3e6;
  const double F = 5.0;
  IpaSimulator sim(p, 0.001);
  sim.SetState(patm + (F + p.AreaB() * (pb - patm)) / p.AreaA(), pb, 0.05);
  for (int k = 0; k < 20; ++k) sim.Advance(0.0);
  // The air springs lower the force as the piston creeps; take the force now.
  const double v_expected =
      p.friction_smoothing_velocity * std::atanh(sim.rod_force() / p.static_friction);
  EXPECT_NEAR(sim.velocity(), v_expected, 0.02 * v_expected);
}

TEST(IpaPositionTest, PositionSensorRoundsToItsResolution) {
  IpaParameters p = QuietRig();
  p.position_resolution = 1e-4;
  p.piston_position = 0.05004;
  IpaSimulator sim(p, 0.01);
  EXPECT_NEAR(sim.Measure(), 0.0500, 1e-12);
  p.position_noise = 2e-5;
  p.adc_bits = 16;
  IpaSimulator noisy(p, 0.01);
  for (int k = 0; k < 20; ++k) {
    noisy.Advance(0.0);
    const double m = noisy.Measure();
    EXPECT_NEAR(m / p.position_resolution, std::round(m / p.position_resolution), 0.02) << m;
  }
}

TEST(IpaPositionTest, HoldAndReleaseActOnBothChambers) {
  // AdvanceValves(false, true) vents both chambers (release); (false, false)
  // holds both.
  const IpaParameters p = QuietRig();
  IpaSimulator sim(p, 0.01);
  const double pa = sim.pressure_a(), pb = sim.pressure_b();
  for (int k = 0; k < 10; ++k) sim.AdvanceValves(false, false);
  EXPECT_EQ(sim.pressure_a(), pa);
  EXPECT_EQ(sim.pressure_b(), pb);
  for (int k = 0; k < 200; ++k) sim.AdvanceValves(false, true);
  EXPECT_NEAR(sim.pressure_a(), p.atmospheric_pressure, 1e-3 * p.supply_pressure);
  EXPECT_NEAR(sim.pressure_b(), p.atmospheric_pressure, 1e-3 * p.supply_pressure);
}

TEST(IpaPositionTest, PositionModeTakesTheRigsDefaultsFromSpecsAndFiles) {
  const IpaParameters rig = DefaultIpaParameters(IpaMode::kPosition);
  EXPECT_EQ(rig.mode, IpaMode::kPosition);
  EXPECT_LT(rig.inlet_conductance, IpaParameters{}.inlet_conductance);
  auto plant = MakePlant("ipa-position", 0.01);
  const auto* sim = dynamic_cast<const IpaSimulator*>(plant.get());
  ASSERT_NE(sim, nullptr);
  EXPECT_EQ(sim->parameters().inlet_conductance, rig.inlet_conductance);
  // A file that names the position mode starts from the rig; keys it gives win.
  const std::string path = testing::TempDir() + "/ipa_position_rig.toml";
  {
    std::ofstream out(path);
    out << "[simulation]\nmode = \"position\"\n[mechanics]\nmass = 2.0\n";
  }
  const IpaParameters f = LoadIpaParameters(path);
  EXPECT_EQ(f.exhaust_conductance, rig.exhaust_conductance);
  EXPECT_EQ(f.mass, 2.0);
  // A file without a mode, read for ipa-position, too.
  {
    std::ofstream out(path);
    out << "[mechanics]\nmass = 3.0\n";
  }
  auto from_file = MakePlant("ipa-position:config=" + path, 0.01);
  const auto* g = dynamic_cast<const IpaSimulator*>(from_file.get());
  EXPECT_EQ(g->parameters().open_delay, rig.open_delay);
  EXPECT_EQ(g->parameters().mass, 3.0);
  // Force mode is unchanged.
  EXPECT_EQ(LoadIpaParameters(path).inlet_conductance, IpaParameters{}.inlet_conductance);
}

}  // namespace
}  // namespace pneumid
