#include "pneumid/identify/step/reaction_curve.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"

namespace pneumid {

FopdtParams ReactionCurve(const StepAnalysis& step) {
  const double t63 = step.CrossingTime(1.0 - std::exp(-1.0));
  FopdtParams p;
  p.K = step.gain;
  p.theta = std::min(step.departure_time, t63);
  p.tau = t63 - p.theta;
  if (!(p.tau > 0.0)) {
    throw DataError(
        fmt::format("reaction curve: the response reaches 63.2 % at {} s, no later "
                    "than its departure from the baseline at {} s",
                    t63, step.departure_time));
  }
  return p;
}

}  // namespace pneumid
