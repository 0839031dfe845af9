#include "pneumid/realtime/sim_backend.hpp"

#include <cmath>

#include "pneumid/common/check.hpp"

namespace pneumid {

SimBackend::SimBackend(std::unique_ptr<Plant> plant) : plant_(std::move(plant)) {
  PNEUMID_CHECK(plant_ != nullptr, "SimBackend needs a plant, got null");
  ipa_ = dynamic_cast<IpaSimulator*>(plant_.get());
}

void SimBackend::Open(double period) {
  PNEUMID_CHECK(std::abs(period - plant_->Ts()) <= 1e-9,
                "loop period {} s differs from the plant's sample time {} s", period, plant_->Ts());
  plant_->Reset();
  plant_->SetLoadDisturbance(LoadAt(load_steps_, plant_->time(), plant_->Ts()));
  in_safe_state_ = false;
}

IoStatus SimBackend::Read(Measurement* m) noexcept {
  try {
    m->y = plant_->Measure();
    if (ipa_) m->aux = ipa_->pressure_a();
  } catch (...) {
    return IoStatus::kError;
  }
  return IoStatus::kOk;
}

IoStatus SimBackend::Write(double u) noexcept {
  if (in_safe_state_) return IoStatus::kOk;
  try {
    plant_->Advance(u);
    if (!load_steps_.empty())
      plant_->SetLoadDisturbance(LoadAt(load_steps_, plant_->time(), plant_->Ts()));
  } catch (...) {
    return IoStatus::kError;
  }
  return IoStatus::kOk;
}

IoStatus SimBackend::EnterSafeState(SafeState state) noexcept {
  IoStatus status = IoStatus::kOk;
  if (!in_safe_state_ && (ipa_ || state == SafeState::kRelease)) {
    try {
      if (ipa_)
        ipa_->AdvanceValves(false, state == SafeState::kRelease);
      else
        plant_->Advance(0.0);
    } catch (...) {
      status = IoStatus::kError;
    }
  }
  in_safe_state_ = true;
  safe_state_ = state;
  return status;
}

void SimBackend::SetLoadSteps(std::vector<LoadStep> steps) {
  load_steps_ = std::move(steps);
  plant_->SetLoadDisturbance(LoadAt(load_steps_, plant_->time(), plant_->Ts()));
}

std::string SimBackend::Describe() const { return "sim (" + plant_->Describe() + ")"; }

}  // namespace pneumid
