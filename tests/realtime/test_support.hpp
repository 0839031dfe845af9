// Test doubles for the real-time tests: an allocation-free first-order plant, a
// PI controller that checks it is never called with allocations in between,
// and a backend that injects faults.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "pneumid/plant/plant.hpp"
#include "pneumid/realtime/io_backend.hpp"
#include "pneumid/realtime/realtime_loop.hpp"

namespace pneumid::testing {

/// Allocations made by the calling thread so far (counted by the replaced global
/// operator new in realtime_loop_test.cpp).
std::int64_t ThreadAllocations();

/// y_(k+1) = a y_k + b u_k: a discretized first-order lag (gain b / (1 - a)).
class FirstOrderPlant : public Plant {
 public:
  FirstOrderPlant(double Ts, double a, double b) : Ts_(Ts), a_(a), b_(b) {}
  void Reset() override {
    y_ = 0.0;
    k_ = 0;
  }
  double Measure() override { return y_ + load_disturbance_; }
  void Advance(double u) override {
    y_ = a_ * y_ + b_ * u;
    ++k_;
  }
  double Ts() const override { return Ts_; }
  double time() const override { return static_cast<double>(k_) * Ts_; }
  std::string Describe() const override { return "first-order test plant"; }

 private:
  double Ts_, a_, b_;
  double y_ = 0.0;
  std::int64_t k_ = 0;
};

/// Velocity-form PI controller; records the thread's allocation count between calls.
class CountingPi : public LoopController {
 public:
  CountingPi(double kp, double ki, double Ts) : kp_(kp), ki_(ki), Ts_(Ts) {}
  void Reset() override {
    u_ = 0.0;
    e_prev_ = 0.0;
    first_allocs_ = -1;
    calls_ = 0;
  }
  double Update(std::int64_t, double r, double y) noexcept override {
    const std::int64_t a = ThreadAllocations();
    if (first_allocs_ < 0) first_allocs_ = a;
    last_allocs_ = a;
    ++calls_;
    const double e = r - y;
    u_ += kp_ * (e - e_prev_) + ki_ * Ts_ * e;
    e_prev_ = e;
    return u_;
  }
  std::string Describe() const override { return "test pi"; }
  /// Allocations on the loop thread between the first and the last call.
  std::int64_t allocations_during_run() const { return last_allocs_ - first_allocs_; }
  std::int64_t calls() const { return calls_; }

 private:
  double kp_, ki_, Ts_;
  double u_ = 0.0, e_prev_ = 0.0;
  std::int64_t first_allocs_ = -1, last_allocs_ = 0, calls_ = 0;
};

enum class Injected { kNone, kNaN, kOutOfRange, kFrozen, kReadError, kWriteError, kRail };

/// Runs a FirstOrderPlant and injects a fault from sample `at` on.
class FaultyBackend : public IoBackend {
 public:
  FaultyBackend(double Ts, Injected what, std::int64_t at)
      : plant_(Ts, 0.9, 0.1), what_(what), at_(at) {}
  void Open(double) override {
    plant_.Reset();
    k_ = 0;
  }
  IoStatus Read(Measurement* m) noexcept override {
    m->y = plant_.Measure();
    const bool on = what_ != Injected::kNone && k_ >= at_;
    if (on) {
      switch (what_) {
        case Injected::kNaN:
          m->y = std::numeric_limits<double>::quiet_NaN();
          break;
        case Injected::kOutOfRange:
          m->y = 1e6;
          break;
        case Injected::kFrozen:
          m->y = 0.5;
          break;
        case Injected::kReadError:
          return IoStatus::kError;
        case Injected::kRail:
          return IoStatus::kOutOfRange;
        default:
          break;
      }
    }
    return IoStatus::kOk;
  }
  IoStatus Write(double u) noexcept override {
    if (what_ == Injected::kWriteError && k_ >= at_) return IoStatus::kError;
    plant_.Advance(u);
    last_u_ = u;
    ++k_;
    return IoStatus::kOk;
  }
  IoStatus EnterSafeState(SafeState s) noexcept override {
    safe_calls_++;
    safe_ = s;
    return IoStatus::kOk;
  }
  void Close() override { closed_ = true; }
  bool CanRunFast() const override { return true; }
  std::string Describe() const override { return "faulty test backend"; }

  int safe_calls_ = 0;
  SafeState safe_ = SafeState::kHold;
  bool closed_ = false;
  double last_u_ = 0.0;

 private:
  FirstOrderPlant plant_;
  Injected what_;
  std::int64_t at_;
  std::int64_t k_ = 0;
};

}  // namespace pneumid::testing

namespace pneumid::testing {

/// Delegates to another LoopController and records the loop thread's allocations.
class CountingWrapper : public LoopController {
 public:
  explicit CountingWrapper(LoopController& inner) : inner_(inner) {}
  void Reset() override {
    inner_.Reset();
    first_ = -1;
  }
  double Update(std::int64_t k, double r, double y) noexcept override {
    const std::int64_t a = ThreadAllocations();
    if (first_ < 0) first_ = a;
    last_ = a;
    return inner_.Update(k, r, y);
  }
  std::string Describe() const override { return inner_.Describe(); }
  std::int64_t allocations_during_run() const { return last_ - first_; }

 private:
  LoopController& inner_;
  std::int64_t first_ = -1, last_ = 0;
};

}  // namespace pneumid::testing
