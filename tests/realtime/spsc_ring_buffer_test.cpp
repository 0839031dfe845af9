#include "pneumid/realtime/spsc_ring_buffer.hpp"

#include <cstdint>
#include <thread>

#include <gtest/gtest.h>

namespace pneumid {
namespace {

TEST(SpscRingBuffer, CapacityIsRoundedUpToAPowerOfTwo) {
  EXPECT_EQ(SpscRingBuffer<int>(1).capacity(), 1u);
  EXPECT_EQ(SpscRingBuffer<int>(5).capacity(), 8u);
  EXPECT_EQ(SpscRingBuffer<int>(64).capacity(), 64u);
  EXPECT_THROW(SpscRingBuffer<int>(0), InvalidArgument);
}

TEST(SpscRingBuffer, FifoOrderAndFullAndEmpty) {
  SpscRingBuffer<int> rb(4);
  int v = 0;
  EXPECT_FALSE(rb.TryPop(&v));
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(rb.TryPush(i));
  EXPECT_FALSE(rb.TryPush(99));  // full: dropped, not overwritten
  EXPECT_EQ(rb.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(rb.TryPop(&v));
    EXPECT_EQ(v, i);
  }
  EXPECT_TRUE(rb.empty());
  // Wrap around many times.
  for (int i = 0; i < 1000; ++i) {
    ASSERT_TRUE(rb.TryPush(i));
    ASSERT_TRUE(rb.TryPop(&v));
    ASSERT_EQ(v, i);
  }
}

TEST(SpscRingBuffer, ConcurrentProducerAndConsumerLoseNothing) {
  struct Rec {
    std::uint64_t seq;
    double payload[6];
  };
  SpscRingBuffer<Rec> rb(256);
  constexpr std::uint64_t kN = 200000;
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kN;) {
      Rec r{i, {static_cast<double>(i), 0, 0, 0, 0, -static_cast<double>(i)}};
      if (rb.TryPush(r)) ++i;
    }
  });
  std::uint64_t expected = 0;
  bool ordered = true;
  Rec r{};
  while (expected < kN) {
    if (rb.TryPop(&r)) {
      ordered = ordered && r.seq == expected && r.payload[0] == static_cast<double>(expected) &&
                r.payload[5] == -static_cast<double>(expected);
      ++expected;
    }
  }
  producer.join();
  EXPECT_TRUE(ordered);
  EXPECT_TRUE(rb.empty());
}

}  // namespace
}  // namespace pneumid
