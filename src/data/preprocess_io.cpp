#include "pneumid/data/preprocess_io.hpp"

#include <string>
#include <vector>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

nlohmann::json Array(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

/// The value of `key`, checked to be of the type that `read` expects.
template <typename T, typename Read>
void Get(const nlohmann::json& j, const char* key, T* out, Read read) {
  if (!j.contains(key)) return;
  try {
    *out = read(j.at(key));
  } catch (const nlohmann::json::exception& e) {
    throw InvalidArgument(fmt::format("preprocessing: key '{}': {}", key, e.what()));
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(fmt::format("preprocessing: key '{}': {}", key, e.what()));
  }
}

Eigen::VectorXd Vector(const nlohmann::json& j) {
  const auto v = j.get<std::vector<double>>();
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

}  // namespace

nlohmann::json ToJson(const PreprocessRecord& r) {
  nlohmann::json j;
  if (r.window.IsSet()) j["window"] = r.window.ToString();
  if (r.resample_ts > 0) j["resample_ts"] = r.resample_ts;
  j["offsets"] = r.offsets;
  j["channels"] = ToString(r.channels);
  j["u0"] = Array(r.level.u0);
  j["y0"] = Array(r.level.y0);
  if (r.offsets == ToString(DetrendKind::kLinear)) {
    j["u_slope"] = Array(r.slope.u0);
    j["y_slope"] = Array(r.slope.y0);
    j["trend_time"] = r.trend_time;
  }
  if (r.filter) j["filter"] = r.filter->ToString();
  if (r.decimate > 1) {
    j["decimate"] = r.decimate;
    j["decimate_order"] = r.decimate_options.order;
    j["decimate_cutoff"] = r.decimate_options.cutoff;
  }
  j["steps"] = r.steps;
  return j;
}

PreprocessRecord PreprocessRecordFromJson(const nlohmann::json& j) {
  PNEUMID_CHECK(j.is_object(), "preprocessing: expected a JSON object, got {}", j.type_name());
  PreprocessRecord r;
  auto text = [](const nlohmann::json& v) { return v.get<std::string>(); };
  auto number = [](const nlohmann::json& v) { return v.get<double>(); };
  Get(j, "window", &r.window, [&](const auto& v) { return TimeWindow::Parse(text(v)); });
  Get(j, "resample_ts", &r.resample_ts, number);
  Get(j, "offsets", &r.offsets, [&](const auto& v) {
    std::string s = text(v);
    PNEUMID_CHECK(s == "none" || s == "initial" || s == "constant" || s == "linear",
                  "expected none, initial, constant or linear, got '{}'", s);
    return s;
  });
  Get(j, "channels", &r.channels, [&](const auto& v) { return ChannelSetFromString(text(v)); });
  Get(j, "u0", &r.level.u0, Vector);
  Get(j, "y0", &r.level.y0, Vector);
  r.slope.u0 = Eigen::VectorXd::Zero(r.level.u0.size());
  r.slope.y0 = Eigen::VectorXd::Zero(r.level.y0.size());
  Get(j, "u_slope", &r.slope.u0, Vector);
  Get(j, "y_slope", &r.slope.y0, Vector);
  Get(j, "trend_time", &r.trend_time, number);
  Get(j, "filter", &r.filter,
      [&](const auto& v) { return std::optional<FilterSpec>(FilterSpec::Parse(text(v))); });
  Get(j, "decimate", &r.decimate, [](const auto& v) { return v.template get<int>(); });
  Get(j, "decimate_order", &r.decimate_options.order,
      [](const auto& v) { return v.template get<int>(); });
  Get(j, "decimate_cutoff", &r.decimate_options.cutoff, number);
  Get(j, "steps", &r.steps,
      [](const auto& v) { return v.template get<std::vector<std::string>>(); });
  PNEUMID_CHECK(r.slope.u0.size() == r.level.u0.size() && r.slope.y0.size() == r.level.y0.size(),
                "preprocessing: u_slope/y_slope have {}/{} values, u0/y0 have {}/{}",
                r.slope.u0.size(), r.slope.y0.size(), r.level.u0.size(), r.level.y0.size());
  PNEUMID_CHECK(r.resample_ts >= 0, "preprocessing: key 'resample_ts': must be >= 0, got {}",
                r.resample_ts);
  PNEUMID_CHECK(r.decimate >= 1, "preprocessing: key 'decimate': must be >= 1, got {}", r.decimate);
  std::string error;
  PNEUMID_CHECK(r.decimate == 1 || r.decimate_options.IsValid(&error), "preprocessing: {}", error);
  return r;
}

}  // namespace pneumid
