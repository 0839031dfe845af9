#include "pneumid/lti/model_io.hpp"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/lti/conversion.hpp"

namespace pneumid {

namespace {

std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

double ParseNumber(const std::string& spec, const std::string& field, const std::string& text) {
  const std::string t = Trim(text);
  double v = 0.0;
  const char* first = t.data();
  const char* last = t.data() + t.size();
  if (!t.empty() && *first == '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, last, v);
  PNEUMID_CHECK(!t.empty() && ec == std::errc() && ptr == last && std::isfinite(v),
                "model spec '{}': field '{}': not a finite number: '{}'", spec, field, t);
  return v;
}

std::vector<double> ParseList(const std::string& spec, const std::string& field,
                              const std::string& text) {
  std::vector<double> out;
  std::string token;
  std::istringstream in(text);
  std::string cleaned = text;
  for (char& c : cleaned) {
    if (c == ';') c = ' ';
  }
  std::istringstream words(cleaned);
  while (words >> token) out.push_back(ParseNumber(spec, field, token));
  PNEUMID_CHECK(!out.empty(), "model spec '{}': field '{}' has no coefficients", spec, field);
  return out;
}

// "key=value,key=value" -> map; values may contain spaces or ';'.
std::map<std::string, std::string> ParseFields(const std::string& spec, const std::string& body,
                                               const std::vector<std::string>& allowed) {
  std::map<std::string, std::string> fields;
  std::size_t pos = 0;
  while (pos <= body.size()) {
    const std::size_t comma = body.find(',', pos);
    const std::string item =
        Trim(body.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos));
    pos = comma == std::string::npos ? body.size() + 1 : comma + 1;
    if (item.empty()) continue;
    const std::size_t eq = item.find('=');
    PNEUMID_CHECK(eq != std::string::npos, "model spec '{}': expected key=value, got '{}'", spec,
                  item);
    const std::string key = Trim(item.substr(0, eq));
    bool ok = false;
    for (const auto& a : allowed) ok = ok || a == key;
    PNEUMID_CHECK(ok, "model spec '{}': unknown field '{}' (valid: {})", spec, key,
                  fmt::join(allowed, ", "));
    PNEUMID_CHECK(fields.count(key) == 0, "model spec '{}': field '{}' given twice", spec, key);
    fields[key] = item.substr(eq + 1);
  }
  return fields;
}

const std::string& Require(const std::map<std::string, std::string>& fields,
                           const std::string& spec, const std::string& key) {
  const auto it = fields.find(key);
  PNEUMID_CHECK(it != fields.end(), "model spec '{}': missing field '{}'", spec, key);
  return it->second;
}

std::vector<double> JsonNumbers(const nlohmann::json& j, const char* key) {
  PNEUMID_CHECK(j.contains(key), "model JSON: missing key '{}'", key);
  const nlohmann::json& a = j.at(key);
  PNEUMID_CHECK(a.is_array() && !a.empty(), "model JSON: '{}' must be a non-empty array of numbers",
                key);
  std::vector<double> v;
  for (const auto& e : a) {
    PNEUMID_CHECK(e.is_number(), "model JSON: '{}' must contain only numbers, got {}", key,
                  e.dump());
    v.push_back(e.get<double>());
  }
  return v;
}

double JsonScalar(const nlohmann::json& j, const char* key, double fallback) {
  if (!j.contains(key) || j.at(key).is_null()) return fallback;
  PNEUMID_CHECK(j.at(key).is_number(), "model JSON: '{}' must be a number, got {}", key,
                j.at(key).dump());
  return j.at(key).get<double>();
}

// A TF object, a model object holding one under "tf", or {"models": [...]}.
TransferFunction FromModelJson(const nlohmann::json& j, const std::string& where,
                               const std::string& select) {
  if (j.is_object() && j.contains("models")) {
    const nlohmann::json& models = j.at("models");
    PNEUMID_CHECK(models.is_array() && !models.empty(), "{}: 'models' must be a non-empty array",
                  where);
    if (select.empty()) return FromModelJson(models.at(0), where, "");
    std::vector<std::string> names;
    for (const auto& m : models) {
      if (m.is_object() && m.contains("method") && m.at("method").is_string()) {
        names.push_back(m.at("method").get<std::string>());
        if (names.back() == select) return FromModelJson(m, where, "");
      }
    }
    PNEUMID_CHECK(false, "{}: no model with method '{}' (available: {})", where, select,
                  fmt::join(names, ", "));
  }
  if (j.is_array()) {
    PNEUMID_CHECK(!j.empty(), "{}: empty list of models", where);
    return FromModelJson(nlohmann::json{{"models", j}}, where, select);
  }
  PNEUMID_CHECK(j.is_object(), "{}: expected a JSON object, got {}", where, j.type_name());
  if (!select.empty()) {
    PNEUMID_CHECK(j.contains("method") && j.at("method") == select,
                  "{}: the model is not of method '{}'", where, select);
  }
  if (j.contains("tf")) return TransferFunctionFromJson(j.at("tf"));
  return TransferFunctionFromJson(j);
}

TransferFunction ParseFile(const std::string& spec) {
  std::string path = spec, select;
  const std::size_t hash = spec.rfind('#');
  if (hash != std::string::npos) {
    path = spec.substr(0, hash);
    select = spec.substr(hash + 1);
  }
  std::ifstream in(path);
  if (!in) {
    throw DataError(fmt::format("{}: cannot open model file: {}", path, std::strerror(errno)));
  }
  nlohmann::json j;
  try {
    in >> j;
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is the 1-based offset of the error; report line and column.
    std::ifstream again(path);
    std::string text((std::istreambuf_iterator<char>(again)), std::istreambuf_iterator<char>());
    std::size_t line = 1, col = 1;
    for (std::size_t i = 0; i + 1 < e.byte && i < text.size(); ++i) {
      if (text[i] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    throw DataError(fmt::format("{}:{}:{}: invalid JSON: {}", path, line, col, e.what()));
  }
  try {
    return FromModelJson(j, path, select);
  } catch (const InvalidArgument& e) {
    throw DataError(fmt::format("{}: {}", path, e.what()));
  }
}

}  // namespace

TransferFunction PaperArxModel() {
  return TransferFunction::Discrete({0.0, 0.03938, 0.04506, 0.01286},
                                    {1.0, -0.60870, -0.27020, -0.06021}, 0.01);
}

TransferFunction PaperFopdtModel() { return TransferFunction::Fopdt(1.6, 0.245, 0.001); }

TransferFunction ParseModelSpec(const std::string& spec_in) {
  const std::string spec = Trim(spec_in);
  PNEUMID_CHECK(!spec.empty(),
                "model spec is empty; give a built-in name (arx-paper, "
                "arx-paper-ct, fopdt-paper), fopdt:/sopdt:/tf: or a JSON file");
  if (spec == "arx-paper") return PaperArxModel();
  if (spec == "arx-paper-ct") return D2C(PaperArxModel(), DiscretizationMethod::kZoh);
  if (spec == "fopdt-paper") return PaperFopdtModel();
  const std::size_t colon = spec.find(':');
  const std::string kind = colon == std::string::npos ? "" : spec.substr(0, colon);
  const std::string body = colon == std::string::npos ? "" : spec.substr(colon + 1);
  if (kind == "fopdt") {
    const auto f = ParseFields(spec, body, {"K", "tau", "theta"});
    const double theta = f.count("theta") ? ParseNumber(spec, "theta", f.at("theta")) : 0.0;
    return TransferFunction::Fopdt(ParseNumber(spec, "K", Require(f, spec, "K")),
                                   ParseNumber(spec, "tau", Require(f, spec, "tau")), theta);
  }
  if (kind == "sopdt") {
    const auto f = ParseFields(spec, body, {"K", "tau1", "tau2", "theta"});
    const double theta = f.count("theta") ? ParseNumber(spec, "theta", f.at("theta")) : 0.0;
    return TransferFunction::Sopdt(ParseNumber(spec, "K", Require(f, spec, "K")),
                                   ParseNumber(spec, "tau1", Require(f, spec, "tau1")),
                                   ParseNumber(spec, "tau2", Require(f, spec, "tau2")), theta);
  }
  if (kind == "tf") {
    const auto f = ParseFields(spec, body, {"num", "den", "Ts", "delay"});
    const std::vector<double> num = ParseList(spec, "num", Require(f, spec, "num"));
    const std::vector<double> den = ParseList(spec, "den", Require(f, spec, "den"));
    const double Ts = f.count("Ts") ? ParseNumber(spec, "Ts", f.at("Ts")) : 0.0;
    const double delay = f.count("delay") ? ParseNumber(spec, "delay", f.at("delay")) : 0.0;
    return TransferFunction(Eigen::Map<const Eigen::VectorXd>(num.data(), num.size()),
                            Eigen::Map<const Eigen::VectorXd>(den.data(), den.size()), Ts, delay);
  }
  const std::string path = spec.substr(0, spec.rfind('#'));
  const bool looks_like_file = path.size() > 5 && path.substr(path.size() - 5) == ".json";
  if (looks_like_file || std::ifstream(path).good()) return ParseFile(spec);
  PNEUMID_CHECK(false,
                "unknown model spec '{}'; valid: arx-paper, arx-paper-ct, fopdt-paper, "
                "fopdt:K=..,tau=..,theta=.., sopdt:K=..,tau1=..,tau2=..,theta=.., "
                "tf:num=..,den=..[,Ts=..][,delay=..], or a model JSON file",
                spec);
  return TransferFunction();
}

nlohmann::json ToJson(const TransferFunction& g) {
  const TransferFunction n = g.Normalized();
  std::vector<double> num(n.num().data(), n.num().data() + n.num().size());
  std::vector<double> den(n.den().data(), n.den().data() + n.den().size());
  nlohmann::json j;
  j["num"] = num;
  j["den"] = den;
  j["Ts"] = n.Ts();
  j["delay"] = n.delay();
  return j;
}

TransferFunction TransferFunctionFromJson(const nlohmann::json& j) {
  PNEUMID_CHECK(j.is_object(), "model JSON: expected an object with num, den, Ts, delay; got {}",
                j.type_name());
  const std::vector<double> num = JsonNumbers(j, "num");
  const std::vector<double> den = JsonNumbers(j, "den");
  const double Ts = JsonScalar(j, "Ts", 0.0);
  const double delay = JsonScalar(j, "delay", 0.0);
  return TransferFunction(Eigen::Map<const Eigen::VectorXd>(num.data(), num.size()),
                          Eigen::Map<const Eigen::VectorXd>(den.data(), den.size()), Ts, delay);
}

}  // namespace pneumid
