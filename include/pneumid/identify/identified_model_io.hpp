// JSON form of identified models: one element of the "models" array written by
// `pneumid identify --json` / `-o FILE` and `pneumid report` (models.json):
//
//   {"method": "reaction-curve", "structure": "FOPDT",
//    "params": {"K": 1.6, "t63": 0.246, "tau": 0.245, "theta": 0.001},
//    "param_std": {...}                        (only when known)
//    "tf": {"num": [...], "den": [...], "Ts": 0, "delay": 0.001},
//    "discrete": {...}                         (polynomial models only)
//    "fit_percent": 97.1, "iae": 0.8, "notes": [...]   (notes only when any)
//    "covariance": {"names": ["a1", "b1"], "matrix": [[...], [...]]}
//                                              (only when known; model_uncertainty.hpp)
//    "input_map": {"u": [...], "y": [...], "extrapolation": "clamp"}
//                                              (static-map, hammerstein; models/static_map.hpp)
//    "output_map": {...}                       (wiener)
//    "narx": {"ny", "nu", "nk", "degree", "Ts", "terms", "theta", "err"}
//                                              (narx; identify/narx.hpp)}
// The nonlinear keys are optional: files without them read as before.
//
// The keys are a file format read back by `pneumid step/bode/control --model
// FILE` (models/model_file.hpp reads "tf") and `pneumid validate` (the polynomial
// "params"); keep them. Parameters map to JSON numbers (integers stay
// integers), arrays and arrays of arrays, in the order of their names.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pneumid/identify/identified_model.hpp"

namespace pneumid {

/// {"name": value, ...}.
nlohmann::json ToJson(const ModelParams& params);

/// Inverse of ToJson(const ModelParams&): integers become int, other numbers
/// double, arrays of integers std::vector<int>, other arrays of numbers
/// std::vector<double>, arrays of arrays of numbers rows.
/// @throws InvalidArgument naming the key for any other JSON value.
ModelParams ModelParamsFromJson(const nlohmann::json& j);

/// The JSON form above.
nlohmann::json ToJson(const IdentifiedModel& model);

/// Inverse of ToJson(const IdentifiedModel&).
/// @throws InvalidArgument naming the key that is missing or malformed.
IdentifiedModel IdentifiedModelFromJson(const nlohmann::json& j);

/// The identified model a file spec `FILE.json[#method]` names (written by
/// `pneumid identify -o` or `--json`; the first model without `#method`), read
/// through the model file reader of models/model_file.hpp (ReadModelEntry: once per
/// ModelFileScope). std::nullopt when the spec is no JSON file name (built-in and inline specs) or
/// the entry is a plain transfer function {"num", "den", ...}.
/// @throws DataError naming the file for a missing or unreadable file,
///         invalid JSON, a selection that names no model or an invalid model.
std::optional<IdentifiedModel> LoadIdentifiedModel(const std::string& spec);

/// The document of a model file: {"models": [ToJson(m), ...]} with `models`
/// in their order (best first). Its writers add their own keys: `pneumid
/// identify -o` "best" and "ranked_by" and each model's "rank_reason",
/// `pneumid commission` "best" and "ranked_by", `pneumid report` "data" and
/// "failures".
nlohmann::json ModelFileDocument(const std::vector<IdentifiedModel>& models);

/// Writes a model file document (ModelFileDocument) to `path`, indented by 2
/// with a final newline: the file LoadIdentifiedModel and every model spec
/// `path#method` read back.
/// @throws DataError naming the path when it cannot be opened or written.
void SaveModelFile(const std::string& path, const nlohmann::json& document);

}  // namespace pneumid
