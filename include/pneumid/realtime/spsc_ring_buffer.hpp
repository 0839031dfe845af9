// Lock-free single-producer single-consumer ring buffer.
//
// The real-time loop pushes one record per sample; a writer thread pops them
// and does the file I/O. Storage is allocated once in the constructor; Push and
// Pop never allocate, lock or block, so they are safe on the loop thread.
//
// Algorithm: the classic Lamport queue with acquire/release indices [1]; the
// capacity is rounded up to a power of two and the indices run freely (wrap at
// 2^64), so "full" is head - tail == capacity and no slot is wasted. Each
// index sits on its own cache line to avoid false sharing.
//
// [1] L. Lamport, Specifying Concurrent Program Modules, ACM TOPLAS 5(2), 1983.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>

#include "pneumid/common/check.hpp"

namespace pneumid {

/// Lock-free ring buffer of trivially copyable records for one producer thread and one
/// consumer thread (see above).
template <typename T>
class SpscRingBuffer {
  static_assert(std::is_trivially_copyable_v<T>, "SpscRingBuffer holds trivially copyable records");

 public:
  /// Allocates room for at least `min_capacity` records (rounded up to a power of two).
  /// @throws InvalidArgument when min_capacity is 0 or above 2^30.
  explicit SpscRingBuffer(std::size_t min_capacity) {
    PNEUMID_CHECK(min_capacity > 0 && min_capacity <= (std::size_t{1} << 30),
                  "ring buffer capacity must be in [1, 2^30], got {}", min_capacity);
    capacity_ = 1;
    while (capacity_ < min_capacity) capacity_ <<= 1;
    mask_ = capacity_ - 1;
    slots_ = std::make_unique<T[]>(capacity_);
  }

  SpscRingBuffer(const SpscRingBuffer&) = delete;  ///< not copyable (shared by two threads)
  SpscRingBuffer& operator=(const SpscRingBuffer&) = delete;

  /// Producer side: copies `value` in; returns false (and drops it) when full.
  bool TryPush(const T& value) noexcept {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (head - cached_tail_ >= capacity_) {
      cached_tail_ = tail_.load(std::memory_order_acquire);
      if (head - cached_tail_ >= capacity_) return false;
    }
    slots_[head & mask_] = value;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  /// Consumer side: moves the oldest record to `*out`; returns false when empty.
  bool TryPop(T* out) noexcept {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (cached_head_ == tail) {
      cached_head_ = head_.load(std::memory_order_acquire);
      if (cached_head_ == tail) return false;
    }
    *out = slots_[tail & mask_];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  /// Number of records that fit.
  std::size_t capacity() const noexcept { return capacity_; }
  /// Records currently queued (exact when called from either side while the other is idle).
  std::size_t size() const noexcept {
    return static_cast<std::size_t>(head_.load(std::memory_order_acquire) -
                                    tail_.load(std::memory_order_acquire));
  }
  bool empty() const noexcept { return size() == 0; }  ///< size() == 0, same caveat

 private:
  std::size_t capacity_ = 0;
  std::size_t mask_ = 0;
  std::unique_ptr<T[]> slots_;
  alignas(64) std::atomic<std::uint64_t> head_{0};  // written by the producer
  std::uint64_t cached_tail_ = 0;                   // producer's view of tail_
  alignas(64) std::atomic<std::uint64_t> tail_{0};  // written by the consumer
  std::uint64_t cached_head_ = 0;                   // consumer's view of head_
};

}  // namespace pneumid
