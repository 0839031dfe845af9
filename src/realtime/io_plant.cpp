#include "pneumid/realtime/io_plant.hpp"

#include <cmath>
#include <limits>
#include <thread>

#include "pneumid/common/check.hpp"

namespace pneumid {

IoPlant::IoPlant(std::unique_ptr<IoBackend> backend, double Ts, bool realtime)
    : backend_(std::move(backend)), Ts_(Ts), realtime_(realtime) {
  PNEUMID_CHECK(backend_ != nullptr, "IoPlant: the backend is null");
  PNEUMID_CHECK(Ts > 0.0 && std::isfinite(Ts), "IoPlant: Ts must be positive, got {}", Ts);
  backend_->Open(Ts);
  if (std::isfinite(backend_->adopted_period())) Ts_ = backend_->adopted_period();
  start_ = std::chrono::steady_clock::now();
}

IoPlant::~IoPlant() {
  backend_->EnterSafeState(SafeState::kRelease);
  try {
    backend_->Close();
  } catch (...) {  // a destructor does not throw; the outputs are already safe
  }
}

void IoPlant::Reset() {
  k_ = 0;
  load_disturbance_ = 0.0;
  start_ = std::chrono::steady_clock::now();
}

double IoPlant::Measure() {
  Measurement m;
  status_ = backend_->Read(&m);
  if (status_ == IoStatus::kError || status_ == IoStatus::kTimeout)
    return std::numeric_limits<double>::quiet_NaN();
  return m.y + load_disturbance_;
}

void IoPlant::Advance(double u) {
  const IoStatus s = backend_->Write(u);
  if (s != IoStatus::kOk) status_ = s;
  ++k_;
  if (realtime_) {
    const auto next = start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                   std::chrono::duration<double>(static_cast<double>(k_) * Ts_));
    std::this_thread::sleep_until(next);
  }
}

std::string IoPlant::Describe() const { return "io: " + backend_->Describe(); }

void IoPlant::EnterSafeState(SafeState state) { backend_->EnterSafeState(state); }

}  // namespace pneumid
