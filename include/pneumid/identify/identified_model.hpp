// The result every identification method returns, and the request shared by
// the `pneumid identify` command and the bindings.
//
// JSON form (one element of `pneumid identify --json`'s "models" array):
//   {"method": "reaction-curve", "structure": "FOPDT",
//    "params": {"K": 1.6, "tau": 0.245, "theta": 0.001},
//    "tf": {"num": [...], "den": [...], "Ts": 0, "delay": 0.001},
//    "fit_percent": 97.1, "iae": 0.8, ...}
// FOPDT parameters are named K, tau, theta. Polynomial models (ARX, ARMAX, OE,
// BJ) hold "a", "b", "nk", "Ts" in params, and "tf" is their continuous (d2c)
// form when it exists, the discrete model otherwise.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pneumid/data/dataset.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

struct IdentifiedModel {
  std::string method;     ///< e.g. "reaction-curve", "fit-p1d", "arx"
  std::string structure;  ///< e.g. "FOPDT", "PTn", "P2D", "ARX"
  nlohmann::json params = nlohmann::json::object();  ///< named parameters
  nlohmann::json param_std = nlohmann::json::object();  ///< standard deviations when known
  TransferFunction tf;    ///< model usable by the rest of the toolkit (continuous if possible)
  std::optional<TransferFunction> discrete;  ///< discrete form of polynomial models
  double fit_percent = 0.0;  ///< NRMSE fit, MATLAB compare: 100 (1 - |y - yhat| / |y - mean y|)
  double iae = 0.0;          ///< integral of |y - yhat| dt over the data (output units * s)
  std::vector<std::string> notes;  ///< warnings (poor excitation, not converged, ...)

  nlohmann::json ToJson() const;
};

/// Options shared by every method of `pneumid identify`.
struct IdentifyRequest {
  int input = 0;   ///< input column
  int output = 0;  ///< output column
  int order = 2;   ///< PTn / Strejc order n
  int na = 3, nb = 3, nk = 1;  ///< polynomial orders
  int nc = 1, nd = 1, nf = 3;  ///< ARMAX/BJ/OE orders
  bool IsValid(std::string* error) const;
};

}  // namespace pneumid
