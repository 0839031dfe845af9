#include "pneumid/models/model_file.hpp"
#include "pneumid/models/model_file_scope.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <vector>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/strings.hpp"

namespace pneumid {

namespace {

// The model object `select` names in a model object, a list of them or
// {"models": [...]} (the first when `select` is empty).
const nlohmann::json& SelectModelJson(const nlohmann::json& j, const std::string& where,
                                      const std::string& select) {
  const bool listed = j.is_object() && j.contains("models");
  if (listed || j.is_array()) {
    const nlohmann::json& models = listed ? j.at("models") : j;
    if (listed)
      PNEUMID_CHECK(models.is_array() && !models.empty(), "{}: 'models' must be a non-empty array",
                    where);
    PNEUMID_CHECK(!models.empty(), "{}: empty list of models", where);
    if (select.empty()) return SelectModelJson(models.at(0), where, "");
    std::vector<std::string> names;
    for (const auto& m : models) {
      if (m.is_object() && m.contains("method") && m.at("method").is_string()) {
        names.push_back(m.at("method").get<std::string>());
        if (names.back() == select) return SelectModelJson(m, where, "");
      }
    }
    PNEUMID_CHECK(false, "{}: no model with method '{}' (available: {})", where, select,
                  fmt::join(names, ", "));
  }
  PNEUMID_CHECK(j.is_object(), "{}: expected a JSON object, got {}", where, j.type_name());
  if (!select.empty()) {
    PNEUMID_CHECK(j.contains("method") && j.at("method") == select,
                  "{}: the model is not of method '{}'", where, select);
  }
  return j;
}

// A TF object, a model object holding one under "tf", or {"models": [...]}.
TransferFunction FromModelJson(const nlohmann::json& j_in, const std::string& where,
                               const std::string& select) {
  const nlohmann::json& j = SelectModelJson(j_in, where, select);
  PNEUMID_CHECK(!j.contains("narx"),
                "{}: the model{} is a NARX model, which has no transfer function; a "
                "controller or a linear simulation needs a linear, static-map or Hammerstein "
                "model",
                where,
                j.contains("method") && j.at("method").is_string()
                    ? " '" + j.at("method").get<std::string>() + "'"
                    : std::string());
  // An identified discrete model whose continuous form is only the bilinear
  // (tustin) approximation (no zoh equivalent: a pole on the negative real
  // axis) is used as identified: the tustin form is biproper and its step
  // response differs from the data's model between and at the samples.
  // Files written before the key "continuous_form" said so in a note.
  if (j.contains("discrete")) {
    bool tustin = false;
    if (j.contains("continuous_form")) {
      tustin = j.at("continuous_form") == "tustin";
    } else if (j.contains("notes") && j.at("notes").is_array()) {
      for (const auto& note : j.at("notes"))
        tustin |=
            note.is_string() && note.get<std::string>().find("tustin d2c") != std::string::npos;
    }
    if (tustin) return TransferFunctionFromJson(j.at("discrete"));
  }
  if (j.contains("tf")) return TransferFunctionFromJson(j.at("tf"));
  return TransferFunctionFromJson(j);
}

// An error in the model file `path`: the message with the file's name in
// front, unless it starts with it already.
DataError InFile(const std::string& path, const InvalidArgument& e) {
  const std::string what = e.what();
  return DataError(what.rfind(path + ":", 0) == 0 ? what : fmt::format("{}: {}", path, what));
}

// The files of the current ModelFileScope (model_file_scope.hpp) on this thread, by
// path, with what identifies their content on disk.
struct ScopedModelFile {
  dev_t device = 0;
  ino_t inode = 0;
  off_t size = 0;
  timespec modified{};
  timespec changed{};
  nlohmann::json json;
};
thread_local std::map<std::string, ScopedModelFile>* t_model_files = nullptr;
// The model documents provided in memory to the current scope, by name.
thread_local std::map<std::string, nlohmann::json>* t_provided_models = nullptr;

// The document provided under `path` in the current scope, or null.
const nlohmann::json* ProvidedModel(const std::string& path) {
  if (t_provided_models == nullptr) return nullptr;
  const auto it = t_provided_models->find(path);
  return it == t_provided_models->end() ? nullptr : &it->second;
}

bool Unchanged(const ScopedModelFile& f, const struct stat& st) {
  return f.device == st.st_dev && f.inode == st.st_ino && f.size == st.st_size &&
         f.modified.tv_sec == st.st_mtim.tv_sec && f.modified.tv_nsec == st.st_mtim.tv_nsec &&
         f.changed.tv_sec == st.st_ctim.tv_sec && f.changed.tv_nsec == st.st_ctim.tv_nsec;
}

nlohmann::json ParseModelFile(const std::string& path);

// The JSON of the model file `spec` (FILE.json[#method]), its path and the
// method selected; inside a ModelFileScope read once while unchanged on disk.
nlohmann::json ReadModelFile(const std::string& spec, std::string* path_out,
                             std::string* select_out) {
  std::string path = spec, select;
  const std::size_t hash = spec.rfind('#');
  if (hash != std::string::npos) {
    path = spec.substr(0, hash);
    select = spec.substr(hash + 1);
  }
  *path_out = path;
  *select_out = select;
  if (const nlohmann::json* provided = ProvidedModel(path)) return *provided;
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw DataError(fmt::format("{}: is a directory, not a model file", path));
  }
  if (t_model_files == nullptr) return ParseModelFile(path);
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return ParseModelFile(path);
  if (auto it = t_model_files->find(path); it != t_model_files->end() && Unchanged(it->second, st))
    return it->second.json;
  nlohmann::json j = ParseModelFile(path);
  (*t_model_files)[path] = {st.st_dev, st.st_ino, st.st_size, st.st_mtim, st.st_ctim, j};
  return j;
}

// The JSON of the model file at `path`. @throws DataError naming the file (and
// the line and column of a syntax error).
nlohmann::json ParseModelFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    throw DataError(fmt::format("{}: cannot open model file: {}", path, std::strerror(errno)));
  }
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw DataError(fmt::format("{}: cannot read model file", path));
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    // A parse error knows its 1-based byte offset: report line and column.
    std::size_t byte = 0;
    if (const auto* pe = dynamic_cast<const nlohmann::json::parse_error*>(&e)) byte = pe->byte;
    std::string where = path;
    if (byte > 0) {
      std::size_t line = 1, col = 1;
      for (std::size_t i = 0; i + 1 < byte && i < text.size(); ++i) {
        if (text[i] == '\n') {
          ++line;
          col = 1;
        } else {
          ++col;
        }
      }
      where = fmt::format("{}:{}:{}", path, line, col);
    }
    // nlohmann's messages start with "[json.exception.<kind>.<id>] ".
    std::string what = e.what();
    if (const std::size_t bracket = what.find("] ");
        what.rfind("[json.", 0) == 0 && bracket != std::string::npos) {
      what = what.substr(bracket + 2);
    }
    throw DataError(fmt::format("{}: invalid model JSON: {}", where, what));
  }
  return j;
}

TransferFunction ParseFile(const std::string& spec) {
  std::string path, select;
  const nlohmann::json j = ReadModelFile(spec, &path, &select);
  try {
    return FromModelJson(j, path, select);
  } catch (const InvalidArgument& e) {
    throw InFile(path, e);
  }
}

bool IsBareStaticMap(const nlohmann::json& j) {
  return j.is_object() && j.contains("u") && j.contains("y") && !j.contains("models") &&
         !j.contains("tf") && !j.contains("num");
}

}  // namespace

TransferFunction ParseModelSpec(const std::string& spec_in) {
  const std::string spec(Trim(spec_in));
  if (std::optional<TransferFunction> g = ParseLinearSpec(spec)) return *g;
  const std::string path = spec.substr(0, spec.rfind('#'));
  const bool looks_like_file = path.size() > 5 && path.substr(path.size() - 5) == ".json";
  std::error_code ec;
  if (looks_like_file || std::filesystem::exists(path, ec)) return ParseFile(spec);
  PNEUMID_CHECK(false,
                "unknown model spec '{}'; valid: arx-paper, arx-paper-ct, fopdt-paper, "
                "fopdt:K=..,tau=..,theta=.., sopdt:K=..,tau1=..,tau2=..,theta=.., "
                "tf:num=..,den=..[,Ts=..][,delay=..], or a model JSON file",
                spec);
  return TransferFunction();
}

namespace {

// The path of a model file spec FILE[#method] (FILE without the selection).
std::string SpecPath(const std::string& spec) {
  const std::size_t hash = spec.rfind('#');
  return hash == std::string::npos ? spec : spec.substr(0, hash);
}

// The JSON of the model file `spec` when it names a regular file (built-in
// and inline specs do not): the file's JSON, its path and the method selected.
std::optional<nlohmann::json> ReadModelFileIfAny(const std::string& spec, std::string* path,
                                                 std::string* select) {
  std::error_code ec;
  const std::string p = SpecPath(spec);
  if (p.empty() || (ProvidedModel(p) == nullptr && !std::filesystem::is_regular_file(p, ec)))
    return std::nullopt;
  return ReadModelFile(spec, path, select);
}

}  // namespace

std::optional<nlohmann::json> ReadModelEntry(const std::string& spec, std::string* path_out) {
  std::string path, select;
  const std::optional<nlohmann::json> j = ReadModelFileIfAny(spec, &path, &select);
  if (path_out != nullptr) *path_out = path.empty() ? SpecPath(spec) : path;
  if (!j) return std::nullopt;
  try {
    return SelectModelJson(*j, path, select);
  } catch (const InvalidArgument& e) {
    throw InFile(path, e);
  }
}

ModelFileScope::ModelFileScope() : outermost_(t_model_files == nullptr) {
  if (outermost_) {
    t_model_files = new std::map<std::string, ScopedModelFile>();
    t_provided_models = new std::map<std::string, nlohmann::json>();
  }
}

void ModelFileScope::Provide(const std::string& name, nlohmann::json document) {
  PNEUMID_CHECK(t_provided_models != nullptr,
                "a model document '{}' can only be provided inside a ModelFileScope", name);
  PNEUMID_CHECK(!name.empty() && name.find('#') == std::string::npos,
                "a provided model document needs a name without '#', got '{}'", name);
  (*t_provided_models)[name] = std::move(document);
}

ModelFileScope::~ModelFileScope() {
  if (!outermost_) return;
  delete t_model_files;
  t_model_files = nullptr;
  delete t_provided_models;
  t_provided_models = nullptr;
}

namespace {

// fn(entry) on the entry of the model file `spec` names (nullptr for a file
// that is a bare static map, whose document is passed as `document`), with
// errors named after the file; std::nullopt when the spec names no file.
template <typename T, typename Fn>
std::optional<T> FromModelFile(const std::string& spec, Fn&& fn) {
  std::string path, select;
  const std::optional<nlohmann::json> j = ReadModelFileIfAny(spec, &path, &select);
  if (!j) return std::nullopt;
  try {
    if (IsBareStaticMap(*j)) return fn(*j, nullptr);
    return fn(*j, &SelectModelJson(*j, path, select));
  } catch (const InvalidArgument& e) {
    throw InFile(path, e);
  }
}

}  // namespace

std::optional<StaticMap> ParseModelInputMap(const std::string& spec) {
  return FromModelFile<StaticMap>(
      spec,
      [](const nlohmann::json& document, const nlohmann::json* m) -> std::optional<StaticMap> {
        if (m == nullptr) return StaticMapFromJson(document);
        if (m->contains("narx")) return std::nullopt;  // its map feeds the NARX
        if (m->contains("input_map")) return StaticMapFromJson(m->at("input_map"));
        return std::nullopt;
      });
}

std::optional<StaticMap> ParseModelOutputMap(const std::string& spec) {
  return FromModelFile<StaticMap>(
      spec, [](const nlohmann::json&, const nlohmann::json* m) -> std::optional<StaticMap> {
        if (m == nullptr || !m->contains("output_map")) return std::nullopt;
        return StaticMapFromJson(m->at("output_map"));
      });
}

std::optional<NarxWithMap> ParseModelNarx(const std::string& spec) {
  return FromModelFile<NarxWithMap>(
      spec, [](const nlohmann::json&, const nlohmann::json* m) -> std::optional<NarxWithMap> {
        if (m == nullptr || !m->contains("narx")) return std::nullopt;
        NarxWithMap n{NarxModelFromJson(m->at("narx")), std::nullopt};
        if (m->contains("input_map")) n.input_map = StaticMapFromJson(m->at("input_map"));
        return n;
      });
}

StaticMap ReadStaticMap(const std::string& spec) {
  std::error_code ec;
  const std::string path = SpecPath(spec);
  if (ProvidedModel(path) == nullptr && !std::filesystem::exists(path, ec))
    throw DataError(
        fmt::format("{}: cannot open static map file: {}", path, std::strerror(ENOENT)));
  if (std::filesystem::is_directory(path, ec))
    throw DataError(fmt::format("{}: is a directory, not a static map file", path));
  if (ParseModelNarx(spec))
    throw DataError(
        fmt::format("{}: a NARX model's input map is not the plant's static map; "
                    "use a static-map or Hammerstein model",
                    spec));
  const std::optional<StaticMap> map = ParseModelInputMap(spec);
  if (!map)
    throw DataError(fmt::format(
        "{}: holds no static map (the input_map of a static-map or Hammerstein model written by "
        "pneumid identify, or an object {{\"u\": [...], \"y\": [...]}})",
        spec));
  return *map;
}

}  // namespace pneumid
