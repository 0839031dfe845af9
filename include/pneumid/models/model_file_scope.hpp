// Reading a model file once per command (docs/models.md): the model specs of
// models/model_file.hpp name files that a command consults several times (the
// linear part, the NARX part, the input and output maps, each controller of
// a comparison).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace pneumid {

/// While an object of this class lives, the model files read on its thread
/// (ParseModelSpec, ParseModelInputMap, ParseModelOutputMap, ParseModelNarx,
/// ReadStaticMap of models/model_file.hpp and the controllers built from them) are
/// opened and parsed once each. A file changed on disk since (its size,
/// modification or change time, or inode) is read again. Scopes nest; the
/// outermost keeps the files. Without a scope every call reads the file.
/// `pneumid` opens one per command, the app one per request.
class ModelFileScope {
 public:
  /// Opens a scope on this thread (within another one: joins it).
  ModelFileScope();
  /// Closes the scope; the outermost one forgets the files it kept.
  ~ModelFileScope();
  /// Holds `document` (the JSON of a model file) in memory under `name`:
  /// until the outermost scope on this thread closes, the model specs
  /// `name` and `name#method` read it as if it were that file, and no file
  /// of that name is opened. The app passes the model objects of its
  /// requests this way.
  /// @throws InvalidArgument outside a scope, or for an empty name or one with '#'.
  static void Provide(const std::string& name, nlohmann::json document);

  ModelFileScope(const ModelFileScope&) = delete;             ///< not copyable
  ModelFileScope& operator=(const ModelFileScope&) = delete;  ///< not assignable

 private:
  bool outermost_ = false;
};

}  // namespace pneumid
