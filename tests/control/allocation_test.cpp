// The controllers allocate only at construction: Update() (including the
// QDMC's QP solve) must not touch the heap. Counted by replacing the global
// operator new for this test program.
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <vector>

#include <gtest/gtest.h>

#include "pneumid/control/dmc.hpp"
#include "pneumid/control/gpc.hpp"
#include "pneumid/control/mpc.hpp"
#include "pneumid/control/pid.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/models/static_map.hpp"

namespace {
std::atomic<long> g_allocations{0};
std::atomic<bool> g_counting{false};
}  // namespace

void* operator new(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace pneumid {
namespace {

// Runs 600 steps of a closed loop against a first-order lag and returns the
// number of heap allocations made by Update().
long AllocationsDuringUpdates(Controller& c) {
  c.Reset(0.0, 0.0);
  double y = 0.0;
  g_allocations = 0;
  g_counting = true;
  for (int k = 0; k < 600; ++k) {
    const double r = (k / 100) % 2 ? 1.3 : 0.2;
    const double u = c.Update(r, y);
    y = 0.96 * y + 0.064 * u;
  }
  g_counting = false;
  return g_allocations.load();
}

TEST(AllocationTest, CountingWorks) {
  g_allocations = 0;
  g_counting = true;
  auto* p = new std::vector<double>(10);
  g_counting = false;
  delete p;
  EXPECT_GE(g_allocations.load(), 2);
}

TEST(AllocationTest, DmcAndQdmcStepsDoNotAllocate) {
  DmcOptions o;
  o.P = 126;
  o.M = 10;
  o.lambda = 1.92;
  o.limits.u_min = 0.0;
  o.limits.u_max = 0.9;
  o.limits.du_max = 0.15;
  DmcController clipped(PaperFopdtModel(), 0.01, o);
  EXPECT_EQ(AllocationsDuringUpdates(clipped), 0);
  o.constrained = true;
  o.y_max = 1.25;
  DmcController qdmc(PaperFopdtModel(), 0.01, o);
  EXPECT_EQ(AllocationsDuringUpdates(qdmc), 0);
  EXPECT_EQ(qdmc.qp_failures(), 0);
}

TEST(AllocationTest, MpcStepsDoNotAllocate) {
  MpcOptions o;
  o.P = 150;
  o.M = 10;
  MpcController unconstrained(PaperFopdtModel(), 0.01, o);
  EXPECT_EQ(AllocationsDuringUpdates(unconstrained), 0);
  o.limits.u_min = 0.0;
  o.limits.u_max = 0.9;
  o.limits.du_max = 0.15;
  o.y_max = 1.25;
  o.disturbance = DisturbanceModel::kInput;
  MpcController constrained(PaperFopdtModel(), 0.01, o);
  EXPECT_EQ(AllocationsDuringUpdates(constrained), 0);
  EXPECT_EQ(constrained.qp_failures(), 0);
  g_allocations = 0;
  g_counting = true;
  constrained.Applied(0.5);
  g_counting = false;
  EXPECT_EQ(g_allocations.load(), 0);
}

TEST(AllocationTest, GpcAndPidStepsDoNotAllocate) {
  GpcOptions g;
  g.N2 = 126;
  g.Nu = 10;
  g.lambda = 1.92;
  g.t_equals_a = true;
  GpcController gpc(PaperArxModel(), 0.01, g);
  EXPECT_EQ(AllocationsDuringUpdates(gpc), 0);
  PidOptions p;
  p.gains = TunePid(1.6, 0.245, 0.001, 0.01, PidTuningRule::kImc);
  p.limits.u_max = 1.0;
  PidController pid(0.01, p);
  EXPECT_EQ(AllocationsDuringUpdates(pid), 0);
}

// A compensator calls the actuator map's inverse every sample (in front of a
// linear controller): Evaluate and Inverse are binary searches without heap use.
TEST(AllocationTest, StaticMapEvaluateAndInverseDoNotAllocate) {
  const StaticMap f({0, 10, 20, 40, 60, 82, 88, 100}, {0, 0, 18.7, 39, 79.8, 130, 193.2, 193.2});
  double acc = 0.0;
  g_allocations = 0;
  g_counting = true;
  for (int k = 0; k < 1000; ++k) {
    acc += f.Inverse(-10.0 + 0.21 * k);  // below, inside and above the output range
    acc += f.Evaluate(-5.0 + 0.11 * k);
  }
  g_counting = false;
  EXPECT_EQ(g_allocations.load(), 0);
  EXPECT_TRUE(std::isfinite(acc));
}

}  // namespace
}  // namespace pneumid
