#include "pneumid/realtime/controller_adapter.hpp"

#include <limits>

#include "pneumid/common/check.hpp"

namespace pneumid {

ControllerAdapter::ControllerAdapter(std::unique_ptr<Controller> controller, double u0, double y0)
    : controller_(std::move(controller)), u0_(u0), y0_(y0) {
  PNEUMID_CHECK(controller_ != nullptr, "ControllerAdapter needs a controller, got null");
}

void ControllerAdapter::Reset() { controller_->Reset(u0_, y0_); }

void ControllerAdapter::Start(double y) noexcept {
  try {
    controller_->Reset(u0_, y);
  } catch (...) {
    // Kept at Reset()'s operating point; the next Update() reports a failure.
  }
}

double ControllerAdapter::Update(std::int64_t, double r, double y) noexcept {
  try {
    return controller_->Update(r, y);
  } catch (...) {
    return std::numeric_limits<double>::quiet_NaN();
  }
}

void ControllerAdapter::Applied(double u) noexcept {
  try {
    controller_->Applied(u);
  } catch (...) {
    // The next Update() reports a failing controller.
  }
}

}  // namespace pneumid
