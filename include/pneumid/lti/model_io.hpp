// Linear model specifications (the built-in names and inline specs every
// command and binding accepts) and the JSON form of a transfer function:
//   * built-in names:   arx-paper     the paper's ARX(3,3,1) force model, Ts = 0.01 (Eq. 5)
//                       arx-paper-ct  its zoh d2c continuous equivalent (Eq. 6)
//                       fopdt-paper   1.6 exp(-0.001 s) / (0.245 s + 1) (Eq. 2)
//   * inline specs:     fopdt:K=1.6,tau=0.245,theta=0.001
//                       sopdt:K=..,tau1=..,tau2=..,theta=..
//                       tf:num=1 2,den=1 3 2[,Ts=0.01][,delay=0]   (coefficients separated
//                       by spaces, ';' or ',': tf:num=1,den=1,-1 is den = [1, -1]; as in
//                       TransferFunction, delay in seconds; syntax in common/spec.hpp)
// Model files written by pneumid (and every spec above) are read by
// models/model_file.hpp (ParseModelSpec), the layer above this one.
// JSON form of a transfer function: {"num": [...], "den": [...], "Ts": x, "delay": s}.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {

/// The transfer function of a built-in name or an inline spec (see above);
/// std::nullopt for any other text (a file name, for models/model_file.hpp).
/// @throws InvalidArgument naming the spec and the offending key for an
///         inline spec that is malformed, and for an empty spec.
std::optional<TransferFunction> ParseLinearSpec(const std::string& spec);

/// {"num", "den", "Ts", "delay"} with a monic denominator.
nlohmann::json ToJson(const TransferFunction& g);
/// Inverse of ToJson; throws InvalidArgument naming the missing/invalid key.
TransferFunction TransferFunctionFromJson(const nlohmann::json& j);

/// The paper's models (docs/paper.md, reference values 2-4).
TransferFunction PaperArxModel();
/// 1.6 exp(-0.001 s) / (0.245 s + 1): the paper's FOPDT (reaction curve, Eq. 2).
TransferFunction PaperFopdtModel();

}  // namespace pneumid
