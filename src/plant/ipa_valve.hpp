// Valve state of the IPA simulator (ipa_simulator.hpp), private to the plant
// area: each solenoid valve keeps its physical and commanded state and the
// state changes still to take effect after the valve delays [3 of
// ipa_simulator.hpp], in a FIFO sized once so that the sample loop does not
// allocate.
#pragma once

#include <cstddef>
#include <vector>

namespace pneumid::ipa_detail {

/// A valve state change taking effect at `time` (s).
struct ValveEvent {
  double time = 0.0;
  bool open = false;
};

/// FIFO of pending valve events in increasing time, in a ring buffer whose
/// capacity is set once (Reserve); it only grows (allocates) if a push exceeds
/// that capacity, which IpaSimulator::EventCapacity() rules out below its cap.
class EventQueue {
 public:
  void Reserve(std::size_t capacity);
  bool empty() const { return size_ == 0; }
  const ValveEvent& front() const { return ring_[head_]; }
  const ValveEvent& back() const { return ring_[(head_ + size_ - 1) % ring_.size()]; }
  void push_back(ValveEvent e);
  void pop_front();
  void pop_back() { --size_; }
  void clear() { head_ = size_ = 0; }

 private:
  std::vector<ValveEvent> ring_;
  std::size_t head_ = 0, size_ = 0;
};

struct Valve {
  bool open = false;     ///< physical state
  bool command = false;  ///< command state
  EventQueue pending;    ///< (time, new physical state)
};

}  // namespace pneumid::ipa_detail
