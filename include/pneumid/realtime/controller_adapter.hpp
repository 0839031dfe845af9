// Runs any pneumid::Controller (DMC, GPC, PID of the control area) in the
// real-time loop. The controllers allocate only at construction (their Update()
// is allocation-free); an exception escaping Update() is turned into a NaN
// output, which the loop reports as a controller-error fault.
#pragma once

#include <memory>
#include <string>

#include "pneumid/control/controller.hpp"
#include "pneumid/realtime/realtime_loop.hpp"

namespace pneumid {

/// A pneumid::Controller as the real-time loop's LoopController (see above).
class ControllerAdapter : public LoopController {
 public:
  /// `u0` and `y0` are the operating point the controller is reset to before the run.
  /// @throws InvalidArgument when controller is null.
  explicit ControllerAdapter(std::unique_ptr<Controller> controller, double u0 = 0.0,
                             double y0 = 0.0);
  void Reset() override;
  /// The controller reset at (u0, y): its observer starts at the measured
  /// output, as SimulateClosedLoop starts it (an MPC on a rig resting at
  /// 50 N sees no 50 N error in its first period; with measurement noise
  /// `run` reproduces its --offline simulation sample for sample).
  void Start(double y) noexcept override;
  double Update(std::int64_t k, double r, double y) noexcept override;
  void Applied(double u) noexcept override;
  std::string Describe() const override { return controller_->Describe(); }
  Controller& controller() { return *controller_; }  ///< the wrapped controller

 private:
  std::unique_ptr<Controller> controller_;
  double u0_, y0_;
};

}  // namespace pneumid
