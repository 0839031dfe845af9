#include "ceres_logging.hpp"

#include <glog/logging.h>

namespace pneumid::internal {

void SilenceCeresLogging() {
  static const bool silenced = [] {
    // Only FATAL (which aborts anyway) still reaches stderr; an application
    // that initialises glog itself may lower the level again afterwards.
    FLAGS_minloglevel = google::GLOG_FATAL;
    return true;
  }();
  (void)silenced;
}

}  // namespace pneumid::internal
