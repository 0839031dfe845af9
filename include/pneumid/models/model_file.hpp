// Model files: the one reader of the model JSON files pneumid writes
// (`pneumid identify -o`, `pneumid commission`), below identification,
// control and the plants, which all read models through it (docs/models.md).
// A model spec is
//   * a built-in name or an inline spec of lti/model_io.hpp (a linear model);
//   * a model JSON file written by pneumid (`pneumid identify --json`, a single
//     model object, or an object {"num","den","Ts","delay"}); for a list of
//     models the first (best) one is taken, or `FILE.json#method` selects one;
//     a model with a static input map (Hammerstein, static map) gives its
//     linear part by ParseModelSpec and its map by ParseModelInputMap, a
//     Wiener model its output map by ParseModelOutputMap, a NARX model its
//     polynomial part by ParseModelNarx.
// The file's schema (the keys "models", "method", "tf", "discrete",
// "continuous_form", "input_map", "output_map", "narx") is read here and by
// identify/identified_model_io.hpp, which reads whole identified models
// through ReadModelEntry. A ModelFileScope (model_file_scope.hpp) makes a
// command read each file once.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "pneumid/lti/model_io.hpp"
#include "pneumid/lti/transfer_function.hpp"
#include "pneumid/models/narx_model.hpp"
#include "pneumid/models/static_map.hpp"

namespace pneumid {

/// Parses a model spec (see above). Throws InvalidArgument naming the spec and
/// the offending key, or DataError naming the file for an unreadable file,
/// a directory or invalid JSON.
TransferFunction ParseModelSpec(const std::string& spec);

/// The static input map of a model file spec: the "input_map" of the selected
/// model (a static-map or Hammerstein model written by `pneumid identify`),
/// or the file itself when it is a static map {"u": [...], "y": [...]}
/// (StaticMapFromJson). std::nullopt for built-in and inline specs, for
/// models without an input map and for NARX models (whose map feeds the NARX:
/// ParseModelNarx).
/// @throws DataError naming the file for an unreadable file or an invalid map.
std::optional<StaticMap> ParseModelInputMap(const std::string& spec);
/// The static output map of a model file spec: the "output_map" of the
/// selected model (a Wiener or Hammerstein-Wiener model); std::nullopt
/// otherwise (built-in and inline specs, models without one).
/// @throws DataError naming the file for an unreadable file or an invalid map.
std::optional<StaticMap> ParseModelOutputMap(const std::string& spec);
/// ParseModelInputMap, required: @throws DataError naming the file when it
/// holds no static map.
StaticMap ReadStaticMap(const std::string& spec);

/// A NARX model of a model file with its input map (affine-narx models carry
/// one; models/narx_model.hpp).
struct NarxWithMap {
  NarxModel narx;  ///< the polynomial NARX, driven by the mapped input v = f(u) with a map
  /// Static input map v = f(u) run before the NARX (affine-narx); std::nullopt without one.
  std::optional<StaticMap> input_map;
};
/// The NARX model of a model file spec (the "narx" of the selected model,
/// with its "input_map" when present); std::nullopt for built-in and inline
/// specs and models without one.
/// @throws DataError naming the file for an unreadable file or an invalid model.
std::optional<NarxWithMap> ParseModelNarx(const std::string& spec);

/// The JSON object of the model a file spec `FILE[#method]` names: the file's
/// model, or the entry of its "models" list that `#method` selects (the first
/// without one), as every reader of this header selects it; `path` (may be
/// null) receives FILE. Read through the current ModelFileScope (once per
/// scope). std::nullopt when the spec names no regular file (built-in and
/// inline specs). The one reader of model files: the identify area reads its
/// models through it (identified_model_io.hpp, LoadIdentifiedModel).
/// @throws DataError naming the file for an unreadable file, invalid JSON or
///         a selection that names no model.
std::optional<nlohmann::json> ReadModelEntry(const std::string& spec, std::string* path = nullptr);

}  // namespace pneumid
