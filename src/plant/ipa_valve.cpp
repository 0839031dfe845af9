#include "ipa_valve.hpp"

#include <algorithm>
#include <utility>

namespace pneumid::ipa_detail {

void EventQueue::Reserve(std::size_t capacity) {
  ring_.assign(std::max<std::size_t>(capacity, 1), ValveEvent{});
  head_ = size_ = 0;
}

void EventQueue::push_back(ValveEvent e) {
  if (size_ == ring_.size()) {  // beyond EventCapacity(): grow, keeping the order
    std::vector<ValveEvent> grown(2 * ring_.size());
    for (std::size_t i = 0; i < size_; ++i) grown[i] = ring_[(head_ + i) % ring_.size()];
    ring_ = std::move(grown);
    head_ = 0;
  }
  ring_[(head_ + size_) % ring_.size()] = e;
  ++size_;
}

void EventQueue::pop_front() {
  head_ = (head_ + 1) % ring_.size();
  --size_;
}

}  // namespace pneumid::ipa_detail
