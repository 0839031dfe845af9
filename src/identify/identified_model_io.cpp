#include "pneumid/identify/identified_model_io.hpp"

#include <fstream>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/data/preprocess_io.hpp"
#include "pneumid/models/model_file.hpp"

namespace pneumid {

namespace {

std::vector<double> Numbers(const nlohmann::json& a, const std::string& key) {
  std::vector<double> v;
  v.reserve(a.size());
  for (const auto& x : a) {
    PNEUMID_CHECK(x.is_number(), "parameter '{}': expected numbers, got a JSON {}", key,
                  x.type_name());
    v.push_back(x.get<double>());
  }
  return v;
}

ParamValue ParamFromJson(const nlohmann::json& v, const std::string& key) {
  if (v.is_number_integer()) return v.get<int>();
  if (v.is_number()) return v.get<double>();
  PNEUMID_CHECK(v.is_array(), "parameter '{}': expected a number or an array, got a JSON {}", key,
                v.type_name());
  if (!v.empty() && v[0].is_array()) {
    std::vector<std::vector<double>> rows;
    for (const auto& row : v) {
      PNEUMID_CHECK(row.is_array(), "parameter '{}': expected an array of arrays", key);
      rows.push_back(Numbers(row, key));
    }
    return rows;
  }
  bool integers = !v.empty();
  for (const auto& x : v) integers = integers && x.is_number_integer();
  if (integers) return v.get<std::vector<int>>();
  return Numbers(v, key);
}

// {"names": [n strings], "matrix": [n rows of n numbers]}.
ParameterCovariance CovarianceFromJson(const nlohmann::json& c) {
  PNEUMID_CHECK(c.is_object() && c.contains("names") && c.contains("matrix"),
                "'covariance' must be an object with 'names' and 'matrix', got {}",
                Excerpt(c.dump()));
  const nlohmann::json& names = c.at("names");
  const nlohmann::json& rows = c.at("matrix");
  PNEUMID_CHECK(names.is_array(), "'covariance.names' must be an array of strings, got {}",
                Excerpt(names.dump()));
  ParameterCovariance cov;
  for (const auto& name : names) {
    PNEUMID_CHECK(name.is_string(), "'covariance.names' must hold strings, got {}",
                  Excerpt(name.dump()));
    cov.names.push_back(name.get<std::string>());
  }
  const auto n = static_cast<Eigen::Index>(cov.names.size());
  PNEUMID_CHECK(rows.is_array() && static_cast<Eigen::Index>(rows.size()) == n,
                "'covariance.matrix' must be {} rows for the {} names, got {}", n, n,
                Excerpt(rows.dump()));
  cov.matrix.resize(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const nlohmann::json& row = rows.at(static_cast<std::size_t>(i));
    PNEUMID_CHECK(row.is_array() && static_cast<Eigen::Index>(row.size()) == n,
                  "'covariance.matrix' row {} must hold {} numbers, got {}", i + 1, n,
                  Excerpt(row.dump()));
    const std::vector<double> v = Numbers(row, "covariance.matrix");
    for (Eigen::Index k = 0; k < n; ++k) cov.matrix(i, k) = v[static_cast<std::size_t>(k)];
  }
  return cov;
}

}  // namespace

nlohmann::json ToJson(const ModelParams& params) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [name, value] : params) {
    std::visit([&j, &name = name](const auto& x) { j[name] = x; }, value);
  }
  return j;
}

ModelParams ModelParamsFromJson(const nlohmann::json& j) {
  PNEUMID_CHECK(j.is_object(), "model parameters must be a JSON object, got a JSON {}",
                j.type_name());
  ModelParams p;
  for (const auto& [key, value] : j.items()) p[key] = ParamFromJson(value, key);
  return p;
}

nlohmann::json ToJson(const IdentifiedModel& model) {
  nlohmann::json j;
  j["method"] = model.method;
  j["structure"] = model.structure;
  j["params"] = ToJson(model.params);
  if (!model.param_std.empty()) j["param_std"] = ToJson(model.param_std);
  j["tf"] = ToJson(model.tf);
  if (model.discrete) j["discrete"] = ToJson(*model.discrete);
  if (model.continuous_form) j["continuous_form"] = ToString(*model.continuous_form);
  j["fit_percent"] = model.fit_percent;
  j["iae"] = model.iae;
  j["notes"] = model.notes;  // always present (an empty list when there are none)
  j["operating_point"] = {{"u0", model.u0}, {"y0", model.y0}};
  j["termination"] = ToString(model.termination);
  if (std::isfinite(model.validation_fit_percent))
    j["validation_fit_percent"] = model.validation_fit_percent;
  j["flags"] = nlohmann::json::array();
  for (const ModelFlagNote& f : model.flags)
    j["flags"].push_back({{"flag", ToString(f.flag)}, {"reason", f.reason}});
  if (model.preprocessing) j["preprocessing"] = ToJson(*model.preprocessing);
  if (model.covariance) {
    nlohmann::json rows = nlohmann::json::array();
    for (Eigen::Index i = 0; i < model.covariance->matrix.rows(); ++i) {
      nlohmann::json row = nlohmann::json::array();
      for (Eigen::Index k = 0; k < model.covariance->matrix.cols(); ++k)
        row.push_back(model.covariance->matrix(i, k));
      rows.push_back(std::move(row));
    }
    j["covariance"] = {{"names", model.covariance->names}, {"matrix", std::move(rows)}};
  }
  if (model.input_map) j["input_map"] = ToJson(*model.input_map);
  if (model.output_map) j["output_map"] = ToJson(*model.output_map);
  if (model.narx) j["narx"] = ToJson(*model.narx);
  if (!model.input_map_undetermined.empty()) {
    nlohmann::json gaps = nlohmann::json::array();
    for (const auto& [lo, hi] : model.input_map_undetermined) gaps.push_back({lo, hi});
    j["input_map_undetermined"] = std::move(gaps);
  }
  return j;
}

// The continuous form of a model file written before the key
// "continuous_form" existed, from the note the estimator wrote then.
static ContinuousForm LegacyContinuousForm(const std::vector<std::string>& notes) {
  for (const std::string& note : notes) {
    if (note.find("continuous form by tustin d2c") != std::string::npos)
      return ContinuousForm::kTustin;
    if (note.find("no continuous (zoh d2c) equivalent") != std::string::npos)
      return ContinuousForm::kNone;
  }
  return ContinuousForm::kZoh;
}

IdentifiedModel IdentifiedModelFromJson(const nlohmann::json& j) {
  PNEUMID_CHECK(j.is_object(), "an identified model must be a JSON object, got a JSON {}",
                j.type_name());
  for (const char* key : {"method", "structure", "params", "tf"}) {
    PNEUMID_CHECK(j.contains(key), "identified model without the key '{}'", key);
  }
  IdentifiedModel m;
  m.method = j.at("method").get<std::string>();
  m.structure = j.at("structure").get<std::string>();
  m.params = ModelParamsFromJson(j.at("params"));
  if (j.contains("param_std")) m.param_std = ModelParamsFromJson(j.at("param_std"));
  m.tf = TransferFunctionFromJson(j.at("tf"));
  if (j.contains("discrete")) m.discrete = TransferFunctionFromJson(j.at("discrete"));
  // A model that could not be scored is written with fit -inf / iae inf, which
  // JSON stores as null.
  auto number = [&j](const char* key, double missing) {
    return j.contains(key) && j.at(key).is_number() ? j.at(key).get<double>() : missing;
  };
  m.fit_percent = number("fit_percent", -std::numeric_limits<double>::infinity());
  m.iae = number("iae", std::numeric_limits<double>::infinity());
  if (j.contains("notes")) m.notes = j.at("notes").get<std::vector<std::string>>();
  if (j.contains("continuous_form")) {
    m.continuous_form = ContinuousFormFromString(j.at("continuous_form").get<std::string>());
  } else if (m.discrete) {
    m.continuous_form = LegacyContinuousForm(m.notes);
  }
  if (j.contains("operating_point")) {
    const nlohmann::json& op = j.at("operating_point");
    PNEUMID_CHECK(op.is_object(), "'operating_point' must be an object with u0 and y0, got {}",
                  Excerpt(op.dump()));
    for (const char* key : {"u0", "y0"}) {
      PNEUMID_CHECK(!op.contains(key) || op.at(key).is_number(),
                    "'operating_point.{}' must be a number, got {}", key,
                    Excerpt(op.at(key).dump()));
    }
    m.u0 = op.value("u0", 0.0);
    m.y0 = op.value("y0", 0.0);
  } else if (const std::optional<double> y0 = m.params.FindScalar("y0")) {
    m.y0 = *y0;  // files written before the operating point was stored
  }
  if (j.contains("termination")) {
    PNEUMID_CHECK(j.at("termination").is_string(), "'termination' must be a string, got {}",
                  Excerpt(j.at("termination").dump()));
    m.termination = TerminationFromString(j.at("termination").get<std::string>());
  }
  m.validation_fit_percent =
      number("validation_fit_percent", std::numeric_limits<double>::quiet_NaN());
  if (j.contains("flags")) {
    PNEUMID_CHECK(j.at("flags").is_array(), "'flags' must be an array, got {}",
                  Excerpt(j.at("flags").dump()));
    for (const nlohmann::json& f : j.at("flags")) {
      PNEUMID_CHECK(f.is_object() && f.contains("flag") && f.at("flag").is_string(),
                    "each element of 'flags' needs a string 'flag', got {}", Excerpt(f.dump()));
      m.flags.push_back(
          {ModelFlagFromString(f.at("flag").get<std::string>()), f.value("reason", std::string())});
    }
  }
  if (j.contains("preprocessing"))
    m.preprocessing = PreprocessRecordFromJson(j.at("preprocessing"));
  if (j.contains("covariance")) m.covariance = CovarianceFromJson(j.at("covariance"));
  if (j.contains("input_map")) m.input_map = StaticMapFromJson(j.at("input_map"));
  if (j.contains("output_map")) m.output_map = StaticMapFromJson(j.at("output_map"));
  if (j.contains("narx")) m.narx = NarxModelFromJson(j.at("narx"));
  if (j.contains("input_map_undetermined")) {
    const nlohmann::json& gaps = j.at("input_map_undetermined");
    PNEUMID_CHECK(gaps.is_array(),
                  "model key 'input_map_undetermined' must be a list of "
                  "[lo, hi] pairs, got {}",
                  gaps.dump());
    for (const nlohmann::json& g : gaps) {
      PNEUMID_CHECK(g.is_array() && g.size() == 2 && g[0].is_number() && g[1].is_number() &&
                        g[0].get<double>() < g[1].get<double>(),
                    "model key 'input_map_undetermined': each entry must be [lo, hi] with "
                    "lo < hi, got {}",
                    g.dump());
      m.input_map_undetermined.emplace_back(g[0].get<double>(), g[1].get<double>());
    }
  }
  return m;
}

std::optional<IdentifiedModel> LoadIdentifiedModel(const std::string& spec) {
  std::string path;
  const std::optional<nlohmann::json> entry = ReadModelEntry(spec, &path);
  const bool json_name = path.size() > 5 && path.compare(path.size() - 5, 5, ".json") == 0;
  if (!json_name) return std::nullopt;
  std::error_code ec;
  if (!entry && !std::filesystem::exists(path, ec))
    throw DataError(fmt::format("{}: cannot open model file: {}", path, std::strerror(ENOENT)));
  if (!entry || !entry->is_object() || !entry->contains("params") || !entry->contains("tf"))
    return std::nullopt;
  try {
    return IdentifiedModelFromJson(*entry);
  } catch (const InvalidArgument& e) {
    throw DataError(fmt::format("{}: {}", path, e.what()));
  }
}

nlohmann::json ModelFileDocument(const std::vector<IdentifiedModel>& models) {
  nlohmann::json j;
  j["models"] = nlohmann::json::array();
  for (const IdentifiedModel& m : models) j["models"].push_back(ToJson(m));
  return j;
}

void SaveModelFile(const std::string& path, const nlohmann::json& document) {
  std::ofstream f(path);
  if (!f) throw DataError(fmt::format("{}: cannot open for writing", path));
  f << document.dump(2) << "\n";
  if (!f) throw DataError(fmt::format("{}: write failed", path));
}

}  // namespace pneumid
