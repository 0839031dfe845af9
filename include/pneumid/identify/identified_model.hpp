// The result every identification method returns, and the request shared by
// the `pneumid identify` command and the bindings.
//
// Parameters are named and typed (ModelParams): FOPDT parameters are K, tau,
// theta (output units per input unit, s, s); polynomial models (ARX, ARMAX,
// OE, BJ) hold "a", "b", "nk", "Ts" (plus "c", "d", "f"), and "tf" is their
// continuous (d2c) form when it exists, the discrete model otherwise. The JSON
// form (`pneumid identify --json`) is in identified_model_io.hpp.
#pragma once

#include <initializer_list>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/subspace.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// One named parameter: a real number, an integer (orders, delays in samples),
/// a coefficient vector, integers per input (delays of a multi-input model) or
/// rows (matrices of state-space models, coefficients per input).
using ParamValue = std::variant<double, int, std::vector<double>, std::vector<int>,
                                std::vector<std::vector<double>>>;

/// Named parameters of an identified model, ordered by name.
class ModelParams {
 public:
  using Map = std::map<std::string, ParamValue>;
  ModelParams() = default;
  ModelParams(std::initializer_list<Map::value_type> values) : values_(values) {}

  /// The parameter `name`, inserted (as 0.0) when missing.
  ParamValue& operator[](const std::string& name) { return values_[name]; }
  bool contains(const std::string& name) const { return values_.count(name) > 0; }
  /// @throws InvalidArgument naming the parameter and the available ones when missing.
  const ParamValue& at(const std::string& name) const;
  /// The number `name` (an int converts).
  /// @throws InvalidArgument when missing or not a number.
  double Scalar(const std::string& name) const;
  /// The number `name`, std::nullopt when missing or not a number.
  std::optional<double> FindScalar(const std::string& name) const;
  /// The coefficient vector `name`.
  /// @throws InvalidArgument when missing or not a vector of reals.
  const std::vector<double>& Vector(const std::string& name) const;

  bool empty() const { return values_.empty(); }
  std::size_t size() const { return values_.size(); }
  Map::const_iterator begin() const { return values_.begin(); }
  Map::const_iterator end() const { return values_.end(); }
  bool operator==(const ModelParams&) const = default;

 private:
  Map values_;
};

struct IdentifiedModel {
  std::string method;     ///< e.g. "reaction-curve", "fit-p1d", "arx"
  std::string structure;  ///< e.g. "FOPDT", "PTn", "P2D", "ARX"
  ModelParams params;     ///< named parameters
  ModelParams param_std;  ///< standard deviations when known (same names as params)
  TransferFunction tf;    ///< model usable by the rest of the toolkit (continuous if possible)
  std::optional<TransferFunction> discrete;  ///< discrete form of polynomial models
  double fit_percent = 0.0;  ///< NRMSE fit, MATLAB compare: 100 (1 - |y - yhat| / |y - mean y|)
  double iae = 0.0;          ///< integral of |y - yhat| dt over the data (output units * s)
  std::vector<std::string> notes;  ///< warnings (poor excitation, not converged, ...)
};

/// Options shared by every method of `pneumid identify`.
struct IdentifyRequest {
  int input = 0;   ///< input column
  int output = 0;  ///< output column
  int order = 2;   ///< PTn / Strejc order n
  int na = 3, nb = 3, nk = 1;  ///< polynomial orders
  int nc = 1, nd = 1, nf = 3;  ///< ARMAX/BJ/OE orders
  bool feedthrough = false;    ///< n4sid: estimate the D term (subspace.hpp)
  SubspaceWeighting n4sid_weight = SubspaceWeighting::kMoesp;  ///< n4sid: W1/W2 weighting
  bool IsValid(std::string* error) const;
};

}  // namespace pneumid
