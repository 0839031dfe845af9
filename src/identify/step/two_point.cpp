#include "pneumid/identify/step/two_point.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"

namespace pneumid {

namespace {
constexpr EnumName<TwoPointMethod> kTwoPointMethodNames[] = {
    {TwoPointMethod::kSmith, "smith"},
    {TwoPointMethod::kSundaresanKrishnaswamy, "sundaresan"},
    {TwoPointMethod::kBroida, "broida"},
};
}  // namespace

std::string ToString(TwoPointMethod v) {
  return std::string(EnumToString(kTwoPointMethodNames, v));
}

TwoPointMethod TwoPointMethodFromString(const std::string& name) {
  return EnumFromString(kTwoPointMethodNames, name, "two-point method");
}

std::pair<double, double> TwoPointLevels(TwoPointMethod method) {
  switch (method) {
    case TwoPointMethod::kSmith:
      return {kSmithLevel1, kSmithLevel2};
    case TwoPointMethod::kSundaresanKrishnaswamy:
      return {0.353, 0.853};
    case TwoPointMethod::kBroida:
      return {0.28, 0.40};
  }
  return {0.0, 0.0};
}

FopdtParams TwoPoint(const StepAnalysis& step, TwoPointMethod method) {
  const auto [p1, p2] = TwoPointLevels(method);
  const double t1 = step.CrossingTime(p1);
  const double t2 = step.CrossingTime(p2);
  FopdtParams p;
  p.K = step.gain;
  switch (method) {
    case TwoPointMethod::kSmith:
      p = SmithTwoPoint(step.gain, t1, t2);
      break;
    case TwoPointMethod::kSundaresanKrishnaswamy:
      p.tau = 0.67 * (t2 - t1);
      p.theta = 1.3 * t1 - 0.29 * t2;
      break;
    case TwoPointMethod::kBroida:
      p.tau = 5.5 * (t2 - t1);
      p.theta = 2.8 * t1 - 1.8 * t2;
      break;
  }
  if (!(p.tau > 0.0)) {
    throw DataError(
        fmt::format("{}: the response reaches {} % at {} s and {} % at {} s; no "
                    "positive time constant",
                    ToString(method), 100 * p1, t1, 100 * p2, t2));
  }
  p.theta = std::max(p.theta, 0.0);
  return p;
}

}  // namespace pneumid
