#include "pneumid/identify/identified_model.hpp"

#include "pneumid/common/enum_names.hpp"

#include <fmt/format.h>

#include "pneumid/common/check.hpp"

namespace pneumid {

namespace {
inline constexpr EnumName<ModelFlag> kModelFlagNames[] = {
    {ModelFlag::kNotFinite, "not_finite"},
    {ModelFlag::kUnstable, "unstable"},
    {ModelFlag::kNyquistPole, "nyquist_pole"},
    {ModelFlag::kNoConvergence, "no_convergence"},
    {ModelFlag::kResidualsNotWhite, "residuals_not_white"}};
}  // namespace

std::string ToString(ModelFlag f) { return std::string(EnumToString(kModelFlagNames, f)); }

ModelFlag ModelFlagFromString(const std::string& name) {
  return EnumFromString(kModelFlagNames, name, "model flag");
}

namespace {
inline constexpr EnumName<ContinuousForm> kContinuousFormNames[] = {
    {ContinuousForm::kZoh, "zoh"}, {ContinuousForm::kTustin, "tustin"}, {ContinuousForm::kNone, "none"}};
}  // namespace

std::string ToString(ContinuousForm form) {
  return std::string(EnumToString(kContinuousFormNames, form));
}

ContinuousForm ContinuousFormFromString(const std::string& name) {
  return EnumFromString(kContinuousFormNames, name, "continuous form");
}

namespace {
inline constexpr EnumName<OperatingPointKind> kOperatingPointKindNames[] = {
    {OperatingPointKind::kAuto, "auto"},
    {OperatingPointKind::kZero, "zero"},
    {OperatingPointKind::kMean, "mean"},
    {OperatingPointKind::kInitial, "initial"}};
}  // namespace

std::string ToString(OperatingPointKind k) {
  return std::string(EnumToString(kOperatingPointKindNames, k));
}

OperatingPointKind OperatingPointKindFromString(const std::string& name) {
  return EnumFromString(kOperatingPointKindNames, name, "operating point");
}

namespace {

std::string Names(const ModelParams& p) {
  std::string names;
  for (const auto& [name, value] : p) names += (names.empty() ? "" : ", ") + name;
  return names.empty() ? "none" : names;
}

}  // namespace

const ParamValue& ModelParams::at(const std::string& name) const {
  const auto it = values_.find(name);
  PNEUMID_CHECK(it != values_.end(), "no parameter '{}' (parameters: {})", name, Names(*this));
  return it->second;
}

std::optional<double> ModelParams::FindScalar(const std::string& name) const {
  const auto it = values_.find(name);
  if (it == values_.end()) return std::nullopt;
  if (const double* d = std::get_if<double>(&it->second)) return *d;
  if (const int* i = std::get_if<int>(&it->second)) return *i;
  return std::nullopt;
}

double ModelParams::Scalar(const std::string& name) const {
  at(name);  // names the available parameters when missing
  const std::optional<double> v = FindScalar(name);
  PNEUMID_CHECK(v.has_value(), "parameter '{}' is not a number", name);
  return *v;
}

const std::vector<double>& ModelParams::Vector(const std::string& name) const {
  const auto* v = std::get_if<std::vector<double>>(&at(name));
  PNEUMID_CHECK(v != nullptr, "parameter '{}' is not a coefficient vector", name);
  return *v;
}

bool IdentifyRequest::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (input < 0) return fail(fmt::format("input column must be >= 0, got {}", input));
  if (output < 0) return fail(fmt::format("output column must be >= 0, got {}", output));
  if (order < 1 || order > 20) return fail(fmt::format("order must be in 1..20, got {}", order));
  if (na < 0 || na > 50) return fail(fmt::format("na must be in 0..50, got {}", na));
  if (nb < 1 || nb > 50) return fail(fmt::format("nb must be in 1..50, got {}", nb));
  if (nk < 0 || nk > 1000) return fail(fmt::format("nk must be in 0..1000, got {}", nk));
  if (nc < 0 || nc > 50) return fail(fmt::format("nc must be in 0..50, got {}", nc));
  if (nd < 0 || nd > 50) return fail(fmt::format("nd must be in 0..50, got {}", nd));
  if (nf < 0 || nf > 50) return fail(fmt::format("nf must be in 0..50, got {}", nf));
  return true;
}

}  // namespace pneumid
