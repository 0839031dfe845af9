#include "pneumid/lti/model_io.hpp"

#include <vector>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/spec.hpp"
#include "pneumid/common/strings.hpp"
#include "pneumid/lti/conversion.hpp"

namespace pneumid {

namespace {

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

}  // namespace

TransferFunction PaperArxModel() {
  return TransferFunction::Discrete({0.0, 0.03938, 0.04506, 0.01286},
                                    {1.0, -0.60870, -0.27020, -0.06021}, 0.01);
}

TransferFunction PaperFopdtModel() { return TransferFunction::Fopdt(1.6, 0.245, 0.001); }

std::optional<TransferFunction> ParseLinearSpec(const std::string& spec_in) {
  const std::string spec(Trim(spec_in));
  PNEUMID_CHECK(!spec.empty(),
                "model spec is empty; give a built-in name (arx-paper, "
                "arx-paper-ct, fopdt-paper), fopdt:/sopdt:/tf: or a JSON file");
  if (spec == "arx-paper") return PaperArxModel();
  if (spec == "arx-paper-ct") return D2C(PaperArxModel(), DiscretizationMethod::kZoh);
  if (spec == "fopdt-paper") return PaperFopdtModel();
  const std::size_t colon = spec.find(':');
  const std::string kind = colon == std::string::npos ? "" : spec.substr(0, colon);
  if (kind == "fopdt" || kind == "sopdt" || kind == "tf") {
    Spec f("model spec", spec);
    TransferFunction g;
    if (kind == "fopdt") {
      const double K = f.Number("K"), tau = f.Number("tau");
      g = TransferFunction::Fopdt(K, tau, f.Number("theta", 0.0));
    } else if (kind == "sopdt") {
      const double K = f.Number("K"), tau1 = f.Number("tau1"), tau2 = f.Number("tau2");
      g = TransferFunction::Sopdt(K, tau1, tau2, f.Number("theta", 0.0));
    } else {
      const std::vector<double> num = f.List("num");
      const std::vector<double> den = f.List("den");
      const double Ts = f.Number("Ts", 0.0);
      const double delay = f.Number("delay", 0.0);
      f.Finish();
      return TransferFunction(Eigen::Map<const Eigen::VectorXd>(num.data(), num.size()),
                              Eigen::Map<const Eigen::VectorXd>(den.data(), den.size()), Ts, delay);
    }
    f.Finish();
    return g;
  }
  return std::nullopt;
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
