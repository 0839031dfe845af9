// The IPA simulator's sample loop (Measure, Advance, AdvanceValves) does not
// allocate after construction or Reset, so that it can run on the real-time
// loop thread; and its fixed-storage sensor delay line delays by exactly
// transport_delay_samples.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <vector>

#include <gtest/gtest.h>

#include "pneumid/plant/ipa_simulator.hpp"

// Counting allocator for this test program: operator new counts on the calling
// thread only while that thread has armed the counter, so the other tests of the
// program are unaffected.
namespace {
thread_local bool t_armed = false;
thread_local std::int64_t t_allocations = 0;

void* CountedAlloc(std::size_t n) {
  if (t_armed) ++t_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t n) { return CountedAlloc(n); }
void* operator new[](std::size_t n) { return CountedAlloc(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace pneumid {
namespace {

// Allocations made by this thread while `f` runs.
template <typename F>
std::int64_t AllocationsDuring(F&& f) {
  t_allocations = 0;
  t_armed = true;
  f();
  t_armed = false;
  return t_allocations;
}

TEST(IpaAllocationTest, CounterSeesAllocations) {
  // The counter itself works (otherwise the zero counts below prove nothing).
  const std::int64_t n = AllocationsDuring([] {
    std::vector<double> v(100);
    v.push_back(1.0);
  });
  EXPECT_GE(n, 2);
}

// 200 samples of a step-and-ramp duty sequence that crosses the dead bands
// (0 %, 100 %) and switches the valves at every PWM edge.
void RunSamples(IpaSimulator& sim, double* sink) {
  for (int k = 0; k < 200; ++k) {
    *sink += sim.Measure();
    const double u = k < 20 ? 0.0 : (k < 60 ? 82.0 : (k < 80 ? 100.0 : 0.5 * (k % 100)));
    sim.Advance(u);
  }
}

void ExpectNoAllocation(IpaParameters p, double Ts) {
  IpaSimulator sim(p, Ts, 5);
  double sink = 0.0;
  for (int run = 0; run < 2; ++run) {
    sim.Reset();
    EXPECT_EQ(AllocationsDuring([&] { RunSamples(sim, &sink); }), 0)
        << ToString(p.mode) << " mode, " << ToString(p.pwm_mode) << " PWM, run " << run;
  }
  // Manual valve commands (the safe states of the real-time loop), then PWM again.
  EXPECT_EQ(AllocationsDuring([&] {
              for (int k = 0; k < 20; ++k) {
                sink += sim.Measure();
                sim.AdvanceValves(k % 3 == 0, k % 2 == 0);
              }
              RunSamples(sim, &sink);
            }),
            0)
      << ToString(p.mode) << " mode, " << ToString(p.pwm_mode) << " PWM, AdvanceValves";
  EXPECT_TRUE(std::isfinite(sink));
}

TEST(IpaAllocationTest, SampleLoopDoesNotAllocateInEitherPwmMode) {
  for (PwmMode pwm : {PwmMode::kSwitching, PwmMode::kAveraged}) {
    IpaParameters p;
    p.pwm_mode = pwm;
    ExpectNoAllocation(p, 0.01);
  }
}

TEST(IpaAllocationTest, PositionModeLongDelaysAndFastPwmDoNotAllocate) {
  for (PwmMode pwm : {PwmMode::kSwitching, PwmMode::kAveraged}) {
    IpaParameters p;
    p.pwm_mode = pwm;
    p.mode = IpaMode::kPosition;
    p.transport_delay_samples = 7;
    // Many valve events pending at once: delays of several PWM periods and samples.
    p.pwm_frequency = 400.0;
    p.open_delay = 0.013;
    p.close_delay = 0.004;
    p.min_pulse_width = 0.0005;
    ExpectNoAllocation(p, 0.002);
  }
}

TEST(IpaAllocationTest, DelayLineDelaysByTransportDelaySamples) {
  IpaParameters p;
  p.pressure_noise = 0.0;
  p.adc_bits = 0;
  p.pressure_filter_time_constant = 0.0;  // the sensed force is the chamber's
  p.transport_delay_samples = 3;
  IpaSimulator sim(p, 0.01);
  for (int run = 0; run < 2; ++run) {
    sim.Reset();
    std::vector<double> truth{sim.force()};  // true force at samples 0, 1, ...
    for (int k = 0; k < 40; ++k) {
      const double expected = truth[static_cast<std::size_t>(std::max(0, k - 3))];
      EXPECT_NEAR(sim.Measure(), expected, 1e-9 * (1.0 + std::abs(expected))) << "k = " << k;
      sim.Advance(k < 5 ? 0.0 : 70.0);
      truth.push_back(sim.force());
    }
    EXPECT_GT(truth.back(), 50.0);  // the step reached the output
  }
}

}  // namespace
}  // namespace pneumid
