// Private helper of the Ceres-based estimators: keeps the glog messages of
// Ceres (e.g. "Error in evaluating the ResidualBlock ...", printed with
// "Logging before InitGoogleLogging()" when a trial step gives a non-finite
// cost) off stderr. The estimators report why a solve failed in their summary
// message and notes instead.
#pragma once

namespace pneumid::internal {

/// Raises glog's minimum log level to FATAL once per process. Thread-safe:
/// the first call does the work inside a function-local static initializer,
/// which C++ guarantees to run exactly once, before any other caller returns;
/// call it before every ceres::Solve / ceres::Covariance use.
void SilenceCeresLogging();

}  // namespace pneumid::internal
