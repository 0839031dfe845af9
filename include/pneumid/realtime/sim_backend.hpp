// Simulation backend: any Plant (the nonlinear IPA simulator, a linear digital
// twin) behind the IoBackend interface. Read() is Plant::Measure(), Write(u) is
// Plant::Advance(u). Paced in real time by the loop, or as fast as possible
// (LoopOptions::fast) since the plant keeps its own time.
//
// Safe state in simulation: with the IPA simulator the valves are commanded
// directly for one period (IpaSimulator::AdvanceValves: hold = both closed,
// release = inlet closed and exhaust open) and the plant is not advanced any
// further; with another plant (single input) release applies u = 0 for one
// period and hold stops advancing it. With the IPA simulator, Read() also
// returns the chamber-A pressure (Pa, absolute) as the auxiliary measurement.
// The actuator is the plant's (PlantActuator).
#pragma once

#include <memory>
#include <string>

#include <vector>

#include "pneumid/control/closed_loop.hpp"
#include "pneumid/plant/actuator.hpp"
#include "pneumid/plant/ipa_simulator.hpp"
#include "pneumid/plant/plant.hpp"
#include "pneumid/realtime/io_backend.hpp"

namespace pneumid {

/// A Plant behind the IoBackend interface (see above); may run faster than real time.
class SimBackend : public IoBackend {
 public:
  /// Takes ownership of the plant. @throws InvalidArgument when plant is null.
  explicit SimBackend(std::unique_ptr<Plant> plant);
  /// Resets the plant. @throws InvalidArgument when `period` differs from the plant's
  /// Ts by more than 1e-9 s.
  void Open(double period) override;
  IoStatus Read(Measurement* m) noexcept override;
  IoStatus Write(double u) noexcept override;
  IoStatus EnterSafeState(SafeState state) noexcept override;
  void Close() override {}
  bool CanRunFast() const override { return true; }
  std::string Describe() const override;
  Actuator actuator() const override { return PlantActuator(*plant_); }

  Plant& plant() { return *plant_; }  ///< the simulated plant (owned by the backend)
  /// Load disturbances on the plant's output (closed_loop.hpp) by plant time
  /// since Open(), applied after every Write().
  void SetLoadSteps(std::vector<LoadStep> steps);
  /// True once EnterSafeState was called; which state.
  bool in_safe_state() const { return in_safe_state_; }
  SafeState safe_state() const { return safe_state_; }  ///< the last state entered

 private:
  std::unique_ptr<Plant> plant_;
  IpaSimulator* ipa_ = nullptr;  // plant_ when it is the IPA simulator
  bool in_safe_state_ = false;
  SafeState safe_state_ = SafeState::kHold;
  std::vector<LoadStep> load_steps_;
};

}  // namespace pneumid
