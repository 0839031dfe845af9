#include "app_api.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <type_traits>

#include <fmt/format.h>

#include "../command_json.hpp"
#include "../data_options.hpp"
#include "../output_options.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/strings.hpp"
#include "pneumid/common/version.hpp"
#include "pneumid/data/load.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/evaluation/model_evaluation.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/lti/frequency.hpp"
#include "pneumid/lti/response.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/models/model_file_scope.hpp"
#include "pneumid/plant/signal.hpp"
#include "pneumid/realtime/io_backend.hpp"
#include "pneumid/realtime/realtime_config.hpp"
#include "pneumid/report/figures.hpp"
#include "pneumid/report/identification_report.hpp"
#include "pneumid/workflow/commission.hpp"
#include "pneumid/workflow/commission_files.hpp"

namespace pneumid::app {
namespace fs = std::filesystem;
namespace {

constexpr Eigen::Index kMaxPoints = 2000;  // signals sent for drawing
constexpr std::size_t kMaxSteps = 1000;    // per-step metrics listed by /api/control
constexpr std::size_t kMaxDataSets = 32;   // data sets held (uploaded or opened)

// An error with its HTTP status.
struct HttpError : std::runtime_error {
  HttpError(int s, const std::string& message) : std::runtime_error(message), status(s) {}
  int status;
};

Response JsonResponse(const nlohmann::ordered_json& j, int status = 200) {
  Response r;
  r.status = status;
  r.body = j.dump();
  return r;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw DataError(fmt::format("{}: cannot open", path.string()));
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string ContentType(const fs::path& path) {
  const std::string ext = path.extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json" || ext == ".map") return "application/json";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".png") return "image/png";
  if (ext == ".ico") return "image/x-icon";
  if (ext == ".woff2") return "font/woff2";
  if (ext == ".woff") return "font/woff";
  return "application/octet-stream";
}

bool IsDataFile(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext == ".csv" || ext == ".txt" || ext == ".tsv" || ext == ".dat" || ext == ".mat";
}

// True when `path` lies inside `dir` (both canonical).
bool Inside(const fs::path& path, const fs::path& dir) {
  auto p = path.begin();
  for (auto d = dir.begin(); d != dir.end(); ++d, ++p) {
    if (d->empty()) continue;  // a trailing separator
    if (p == path.end() || *p != *d) return false;
  }
  return true;
}

// The indices drawn: every k-th sample so that at most kMaxPoints remain.
Eigen::Index Stride(Eigen::Index n) {
  return std::max<Eigen::Index>(1, (n + kMaxPoints - 1) / kMaxPoints);
}

nlohmann::json Decimate(const Eigen::VectorXd& v) {
  nlohmann::json out = nlohmann::json::array();
  const Eigen::Index step = Stride(v.size());
  for (Eigen::Index k = 0; k < v.size(); k += step) out.push_back(v[k]);
  return out;
}

// Optional fields of a request body, with their type checked.
template <typename T>
bool Get(const nlohmann::json& body, const char* key, T& out) {
  if (!body.contains(key) || body[key].is_null()) return false;
  const nlohmann::json& v = body[key];
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
    // An integer field takes an integer within its type's range: 2.5 or
    // 1e308 is an error, not 2 or a wrapped value.
    if (v.is_number_float()) {
      const double x = v.get<double>();
      if (!(std::floor(x) == x) || x < static_cast<double>(std::numeric_limits<T>::min()) ||
          x > static_cast<double>(std::numeric_limits<T>::max()))
        throw HttpError(422, fmt::format("field '{}' must be an integer in [{}, {}], got {}", key,
                                         std::numeric_limits<T>::min(),
                                         std::numeric_limits<T>::max(), Excerpt(v.dump())));
    } else if (v.is_number_unsigned() &&
               v.get<std::uint64_t>() > static_cast<std::uint64_t>(std::numeric_limits<T>::max())) {
      throw HttpError(422, fmt::format("field '{}' must be at most {}, got {}", key,
                                       std::numeric_limits<T>::max(), Excerpt(v.dump())));
    } else if (v.is_number_integer() && !v.is_number_unsigned() &&
               (v.get<std::int64_t>() < static_cast<std::int64_t>(std::numeric_limits<T>::min()) ||
                v.get<std::int64_t>() > static_cast<std::int64_t>(std::numeric_limits<T>::max()))) {
      throw HttpError(422, fmt::format("field '{}' must be an integer in [{}, {}], got {}", key,
                                       std::numeric_limits<T>::min(), std::numeric_limits<T>::max(),
                                       Excerpt(v.dump())));
    }
  }
  try {
    out = v.get<T>();
  } catch (const nlohmann::json::exception&) {
    throw HttpError(400, fmt::format("field '{}' has the wrong type: {}", key, Excerpt(v.dump())));
  }
  return true;
}

// The first line of a CSV-like file that is not a comment, split at its delimiter.
std::vector<std::string> CsvColumns(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    char delim = ',';
    for (char c : {',', ';', '\t'})
      if (line.find(c) != std::string::npos) {
        delim = c;
        break;
      }
    if (line.find(delim) == std::string::npos) delim = ' ';
    std::vector<std::string> cols;
    std::stringstream s(line);
    std::string item;
    while (std::getline(s, item, delim)) {
      const auto a = item.find_first_not_of(" \"");
      const auto b = item.find_last_not_of(" \"");
      if (a != std::string::npos) cols.push_back(item.substr(a, b - a + 1));
    }
    return cols;
  }
  return {};
}

const char* kNoPage = R"(<!doctype html>
<html><head><meta charset="utf-8"><title>pneumid app</title></head>
<body style="font-family: sans-serif; max-width: 40em; margin: 3em auto">
<h1>pneumid app</h1>
<p>The front end was not built: build the project with npm installed (the page is
built into <code>web/</code> beside the program), or give its folder with
<code>--assets DIR</code>.</p>
<p>The HTTP JSON API works without it: see <code>docs/app.md</code>, e.g.
<code>GET /api/version</code>.</p>
</body></html>
)";

}  // namespace

AppApi::AppApi(AppOptions options)
    : options_(std::move(options)), run_((options_.work / "run.csv").string()) {}

AppApi::~AppApi() { Shutdown(); }

void AppApi::Shutdown() {
  shutting_down_ = true;
  run_.Stop();
}

Response AppApi::Handle(const Request& request) {
  // A request reads each model file once, however often it consults it.
  const ModelFileScope model_files;
  try {
    return Route(request);
  } catch (const HttpError& e) {
    return ErrorResponse(e.status, e.what());
  } catch (const nlohmann::json::exception& e) {
    return ErrorResponse(400, fmt::format("invalid JSON: {}", e.what()));
  } catch (const Cancelled& e) {
    // the client has gone (nobody reads this) or the deadline passed (the
    // server answers 503 with the deadline)
    return ErrorResponse(503, e.what());
  } catch (const InvalidArgument& e) {
    return ErrorResponse(400, e.what());
  } catch (const DataError& e) {
    return ErrorResponse(422, e.what());
  } catch (const std::exception& e) {
    return ErrorResponse(500, e.what());
  }
}

Response AppApi::Route(const Request& req) {
  const std::string& p = req.path;
  const bool get = req.method == "GET";
  const bool post = req.method == "POST";
  auto body = [&req] {
    if (req.body.empty()) return nlohmann::json::object();
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(req.body);
    } catch (const nlohmann::json::exception& e) {
      throw HttpError(400, fmt::format("the request body is not JSON: {}", e.what()));
    }
    if (!j.is_object()) throw HttpError(400, "the request body must be a JSON object");
    return j;
  };
  auto method_check = [&](bool ok, const char* allowed) {
    if (!ok) throw HttpError(405, fmt::format("{} takes {}, not {}", p, allowed, req.method));
  };
  if (p == "/" || p == "/index.html") {
    method_check(get, "GET");
    return Page();
  }
  if (p.rfind("/assets/", 0) == 0) {
    method_check(get, "GET");
    return Asset(p.substr(8));
  }
  if (p == "/api/version") {
    method_check(get, "GET");
    return JsonResponse({{"version", Version()}, {"root", options_.root.string()}});
  }
  if (p == "/api/session") {
    method_check(get, "GET");
    return JsonResponse(Session());
  }
  if (p == "/api/files") {
    method_check(get, "GET");
    return JsonResponse(Files(req));
  }
  if (p == "/api/data/open") {
    method_check(post, "POST");
    return JsonResponse(OpenData(body()));
  }
  if (p == "/api/data/upload") {
    method_check(post, "POST");
    return JsonResponse(Upload(req));
  }
  if (p == "/api/identify") {
    method_check(post, "POST");
    return JsonResponse(Identify(body(), req.cancel.get()));
  }
  if (p == "/api/tune") {
    method_check(post, "POST");
    return JsonResponse(Tune(body()));
  }
  if (p == "/api/control") {
    method_check(post, "POST");
    return JsonResponse(Control(body(), req.cancel.get()));
  }
  if (p == "/api/model/views") {
    method_check(post, "POST");
    return JsonResponse(ModelViews(body()));
  }
  if (p == "/api/commission") {
    method_check(post, "POST");
    return JsonResponse(Commission(body(), req.cancel.get()));
  }
  if (p == "/api/run/start") {
    method_check(post, "POST");
    return RunStart(body());
  }
  if (p == "/api/run/status") {
    method_check(get, "GET");
    return JsonResponse(run_.Status());
  }
  if (p == "/api/run/stop") {
    method_check(post, "POST");
    nlohmann::json summary = run_.Stop();
    if (summary.is_null()) throw HttpError(409, "no real-time run has been started");
    return JsonResponse(summary);
  }
  if (p == "/api/run/log") {
    method_check(get, "GET");
    if (!run_.HasLog()) throw HttpError(404, "no real-time run has been started");
    Response r;
    r.content_type = "text/csv";
    r.body = ReadFile(run_.LogPath());
    return r;
  }
  if (p == "/api/run/stream")
    throw HttpError(400, "/api/run/stream is a WebSocket: connect with an Upgrade request");
  if (p == "/api/export/controller") {
    method_check(post, "POST");
    return ExportController(body());
  }
  if (p == "/api/export/report") {
    method_check(post, "POST");
    return ExportReport(body());
  }
  throw HttpError(404, fmt::format("no such path: {}", p));
}

// ---------------------------------------------------------------- page, assets

Response AppApi::Page() {
  Response r;
  r.content_type = "text/html; charset=utf-8";
  // The page's scripts and styles are loaded without the query: the cookie
  // carries the token for them (HttpOnly, same site only).
  r.headers.emplace_back("Set-Cookie", fmt::format("pneumid_token={}; Path=/; HttpOnly; "
                                                   "SameSite=Strict",
                                                   options_.token));
  const fs::path index = options_.assets / "index.html";
  std::error_code ec;
  r.body = fs::is_regular_file(index, ec) ? ReadFile(index) : std::string(kNoPage);
  return r;
}

Response AppApi::Asset(const std::string& rel) {
  std::error_code ec;
  const fs::path dir = fs::weakly_canonical(options_.assets / "assets", ec);
  if (ec || !fs::is_directory(dir)) throw HttpError(404, "the front end was not built");
  const fs::path file = fs::weakly_canonical(dir / rel, ec);
  if (ec || !Inside(file, dir)) throw HttpError(403, fmt::format("{} is outside the assets", rel));
  if (!fs::is_regular_file(file, ec)) throw HttpError(404, fmt::format("no such asset: {}", rel));
  Response r;
  r.content_type = ContentType(file);
  r.body = ReadFile(file);
  return r;
}

// ---------------------------------------------------------------- files and data

fs::path AppApi::Confine(const std::string& path) const {
  if (path.empty()) return options_.root;
  if (path.find('\0') != std::string::npos)
    throw HttpError(400, fmt::format("the path {} holds a NUL byte", Excerpt(path)));
  if (path.size() > 4096)
    throw HttpError(400, fmt::format("the path {} is longer than 4096 bytes", Excerpt(path)));
  std::error_code ec;
  const fs::path given(path);
  const fs::path full =
      fs::weakly_canonical(given.is_absolute() ? given : options_.root / given, ec);
  if (ec || !Inside(full, options_.root))
    throw HttpError(
        403, fmt::format("{} is outside the root {}", Excerpt(path), options_.root.string()));
  return full;
}

std::string AppApi::SignalSpec(const std::string& spec) const {
  // The kind and the path as ParseSignal reads them: blanks trimmed, the
  // kind in any case ("FILE:", " file :" are file signals too).
  const std::string_view text = Trim(spec);
  const std::size_t colon = text.find(':');
  if (colon == std::string_view::npos || ToLower(Trim(text.substr(0, colon))) != "file")
    return spec;
  const std::string_view rest = text.substr(colon + 1);
  const std::size_t comma = rest.find(',');
  const std::string path(Trim(rest.substr(0, comma)));
  return "file:" + Confine(path).string() +
         (comma == std::string_view::npos ? std::string() : std::string(rest.substr(comma)));
}

std::string AppApi::PlantSpec(const std::string& spec) const {
  const std::size_t colon = spec.find(':');
  const std::string base = spec.substr(0, colon);
  if ((base == "ipa" || base == "ipa-position") && colon != std::string::npos) {
    // ipa:config=PATH[,mode=..]: the configuration file under the root.
    std::string out = spec.substr(0, colon + 1), rest = spec.substr(colon + 1);
    std::size_t pos = 0;
    bool first = true;
    while (pos <= rest.size()) {
      const std::size_t comma = rest.find(',', pos);
      std::string field = rest.substr(pos, comma == std::string::npos ? comma : comma - pos);
      const std::size_t eq = field.find('=');
      std::string key = field.substr(0, eq);
      key.erase(0, key.find_first_not_of(" \t"));
      key.erase(key.find_last_not_of(" \t") + 1);
      if (key == "config" && eq != std::string::npos)
        field = "config=" + Confine(field.substr(eq + 1)).string();
      out += (first ? "" : ",") + field;
      first = false;
      if (comma == std::string::npos) break;
      pos = comma + 1;
    }
    return out;
  }
  return FileSpec(spec);
}

void AppApi::CheckIo(const std::string& io) const {
  if (io.empty()) return;
  const IoSpec parsed = ParseIoSpec(io);
  if (parsed.kind != IoKind::kComedi) return;
  const auto& allowed = options_.allowed_devices;
  if (std::find(allowed.begin(), allowed.end(), parsed.device) == allowed.end())
    throw HttpError(403, fmt::format("the device {} is not allowed: start the app with "
                                     "--allow-device {} to drive it from the page",
                                     Excerpt(parsed.device), Excerpt(parsed.device)));
}

nlohmann::json AppApi::Files(const Request& req) {
  const auto it = req.query.find("dir");
  const std::string rel = it == req.query.end() ? "" : it->second;
  const fs::path dir = Confine(rel);
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw HttpError(404, fmt::format("{}: not a folder", rel));
  std::vector<nlohmann::json> dirs, files;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.empty() || name[0] == '.') continue;
    std::error_code e2;
    // A symbolic link that leaves the root is not listed (it could not be opened).
    if (e.is_symlink(e2)) {
      const fs::path target = fs::weakly_canonical(e.path(), e2);
      if (e2 || !Inside(target, options_.root)) continue;
    }
    if (e.is_directory(e2)) {
      dirs.push_back({{"name", name}, {"type", "dir"}, {"size", nullptr}});
    } else if (e.is_regular_file(e2) && IsDataFile(e.path())) {
      files.push_back({{"name", name}, {"type", "file"}, {"size", e.file_size(e2)}});
    }
  }
  auto by_name = [](const nlohmann::json& a, const nlohmann::json& b) {
    return a["name"].get<std::string>() < b["name"].get<std::string>();
  };
  std::sort(dirs.begin(), dirs.end(), by_name);
  std::sort(files.begin(), files.end(), by_name);
  nlohmann::json j;
  j["dir"] = fs::relative(dir, options_.root).generic_string();
  j["entries"] = nlohmann::json::array();
  for (auto& d : dirs) j["entries"].push_back(std::move(d));
  for (auto& f : files) j["entries"].push_back(std::move(f));
  return j;
}

nlohmann::json AppApi::LoadDataSet(std::string name, const cli::DataOptions& o, bool session) {
  DataSet set;
  set.name = std::move(name);
  set.path = o.path;
  set.t = o.time_col;
  set.u = o.input_col;
  set.y = o.output_col;
  set.data = cli::LoadFromOptions(o);
  set.data.set_source(set.name);  // as the client named it (not the app's folder)
  set.columns = DataFormatFromPath(o.path) == DataFormat::kMat
                    ? std::vector<std::string>{o.time_col, o.input_col, o.output_col}
                    : CsvColumns(o.path);
  return AddDataSet(std::move(set), session);
}

nlohmann::json AppApi::AddDataSet(DataSet set, bool session) {
  const Dataset& d = set.data;
  nlohmann::json j;
  {
    std::lock_guard lock(mutex_);
    set.id = fmt::format("d{}", next_data_++);
  }
  j["id"] = set.id;
  j["name"] = set.name;
  j["columns"] = set.columns;
  j["t"] = set.t;
  j["u"] = set.u;
  j["y"] = set.y;
  j["samples"] = d.size();
  j["Ts"] = d.size() >= 2 ? nlohmann::json(d.MedianSampleInterval()) : nlohmann::json(nullptr);
  j["signals"] = {{"t", Decimate(d.time())},
                  {"u", d.num_inputs() > 0 ? Decimate(d.u(0)) : nlohmann::json::array()},
                  {"y", d.num_outputs() > 0 ? Decimate(d.y(0)) : nlohmann::json::array()}};
  j["decimated"] = Stride(d.size()) > 1;
  std::lock_guard lock(mutex_);
  const std::string id = set.id;
  data_[id] = std::make_shared<const DataSet>(std::move(set));
  // The app holds the last kMaxDataSets data sets: every upload or open
  // stayed in memory for the app's life (25-40 MB each for a large record).
  while (data_.size() > kMaxDataSets) {
    const auto oldest = std::min_element(data_.begin(), data_.end(), [](const auto& a,
                                                                         const auto& b) {
      return std::stoi(a.first.substr(1)) < std::stoi(b.first.substr(1));
    });
    data_.erase(oldest);
  }
  if (session) {
    session_data_ = j;
    session_identify_ = nullptr;
    session_identify_request_ = nullptr;
  }
  return j;
}

// What a reloaded or second page restores: the last data set opened, its
// last identification with the request that made it, and the run's status.
nlohmann::json AppApi::Session() {
  nlohmann::json j;
  {
    std::lock_guard lock(mutex_);
    j["data"] = session_data_;
    j["identify"] = session_identify_;
    j["identify_request"] = session_identify_request_;
  }
  j["run"] = run_.Status();
  return j;
}

nlohmann::json AppApi::OpenData(const nlohmann::json& body) {
  std::string path;
  if (!Get(body, "path", path) || path.empty()) throw HttpError(400, "field 'path' is missing");
  const fs::path file = Confine(path);
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw HttpError(404, fmt::format("{}: no such file", path));
  cli::DataOptions o;
  o.path = file.string();
  Get(body, "t", o.time_col);
  Get(body, "u", o.input_col);
  Get(body, "y", o.output_col);
  bool validation = false;
  Get(body, "validation", validation);
  return LoadDataSet(path, o, !validation);
}

nlohmann::json AppApi::Upload(const Request& req) {
  const auto it = req.query.find("name");
  std::string name =
      it == req.query.end() ? "upload.csv" : fs::path(it->second).filename().string();
  if (name.empty() || name[0] == '.') name = "upload.csv";
  if (!IsDataFile(name))
    throw HttpError(400, fmt::format("{}: a data file is .csv, .txt, .tsv, .dat or .mat", name));
  int n;
  {
    std::lock_guard lock(mutex_);
    n = next_file_++;
  }
  const fs::path dir = options_.work / fmt::format("upload{}", n);
  fs::create_directories(dir);
  // The upload is read into memory and its file removed (they stayed on disk
  // for the app's life, failed ones too).
  struct RemoveDir {
    fs::path dir;
    ~RemoveDir() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } remove{dir};
  const fs::path file = dir / name;
  {
    std::ofstream out(file, std::ios::binary);
    out.write(req.body.data(), static_cast<std::streamsize>(req.body.size()));
    if (!out) throw DataError(fmt::format("{}: cannot store the upload", name));
  }
  cli::DataOptions o;
  o.path = file.string();
  auto q = [&](const char* key, std::string& out) {
    if (auto i = req.query.find(key); i != req.query.end() && !i->second.empty()) out = i->second;
  };
  q("t", o.time_col);
  q("u", o.input_col);
  q("y", o.output_col);
  // Messages name the upload as the client did, not the app's folder.
  const auto named = [&](const std::exception& e) {
    std::string m = e.what();
    for (std::size_t at; (at = m.find(file.string())) != std::string::npos;)
      m.replace(at, file.string().size(), name);
    return m;
  };
  try {
    return LoadDataSet(name, o);
  } catch (const DataError& e) {
    throw DataError(named(e));
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(named(e));
  }
}

std::shared_ptr<const AppApi::DataSet> AppApi::FindDataSet(const nlohmann::json& id,
                                                           const char* field) const {
  if (!id.is_string()) throw HttpError(400, fmt::format("field '{}' must be a data set id", field));
  std::lock_guard lock(mutex_);
  const auto it = data_.find(id.get<std::string>());
  if (it == data_.end())
    throw HttpError(404, fmt::format("{}: no data set {} (open or upload it first; the app "
                                     "holds the last {} opened)",
                                     field, id.get<std::string>(), kMaxDataSets));
  return it->second;
}

// ---------------------------------------------------------------- identify

nlohmann::json AppApi::Identify(const nlohmann::json& body, const std::atomic<bool>* cancel) {
  if (!body.contains("data")) throw HttpError(400, "field 'data' is missing");
  const auto set = FindDataSet(body["data"], "data");
  std::shared_ptr<const DataSet> validation;
  if (body.contains("validation") && !body["validation"].is_null())
    validation = FindDataSet(body["validation"], "validation");
  IdentifyWorkflowOptions args;
  if (body.contains("methods")) {
    const auto& m = body["methods"];
    if (m.is_string()) {
      args.methods = m.get<std::string>();
    } else if (m.is_array() && !m.empty()) {
      std::vector<std::string> names;
      for (const auto& x : m) {
        if (!x.is_string()) throw HttpError(400, "field 'methods' must list method names");
        names.push_back(x.get<std::string>());
      }
      args.methods = fmt::format("{}", fmt::join(names, ","));
    } else {
      throw HttpError(400, "field 'methods' must be a list of method names");
    }
  }
  Get(body, "detrend", args.preprocess.detrend);
  Get(body, "window", args.preprocess.window);
  Get(body, "order", args.request.order);
  // As `pneumid identify`: without na, nb, nk the nonlinear structures are chosen.
  const bool na = Get(body, "na", args.request.na);
  const bool nb = Get(body, "nb", args.request.nb);
  const bool nk = Get(body, "nk", args.request.nk);
  args.nonlinear.choose_structure = !na && !nb && !nk;
  const IdentifyWorkflowResult out =
      RunIdentifyWorkflow(args, set->data, validation ? &validation->data : nullptr,
                          [cancel](std::size_t, std::size_t, const std::string& method) {
                            if (cancel != nullptr && cancel->load())
                              throw Cancelled("identification stopped on request before " + method);
                          });
  if (out.summary.models.empty()) {
    // Each method's reason, as `identify --json` lists them in "failures".
    std::string reasons;
    for (const auto& [method, reason] : out.summary.failures)
      reasons += fmt::format("{}{}: {}", reasons.empty() ? "" : "; ", method, reason);
    throw HttpError(422, reasons.empty() ? out.summary.message
                                         : fmt::format("{}: {}", out.summary.message, reasons));
  }
  const nlohmann::json model_file = out.ToJson();
  nlohmann::json j = model_file;
  nlohmann::json responses;
  responses["t"] = Decimate(out.data.time());
  for (const IdentifiedModel& m : out.summary.models) {
    try {
      const Eigen::VectorXd yhat = SimulateModel(m, out.data, 0);
      responses[m.method] = Decimate(yhat);
    } catch (const std::exception&) {
      responses[m.method] = nullptr;  // cannot be simulated on these data
    }
  }
  j["responses"] = std::move(responses);
  j["model_file"] = model_file;
  {
    std::lock_guard lock(mutex_);
    if (session_data_.is_object() && session_data_.value("id", "") == set->id) {
      session_identify_ = j;
      session_identify_request_ = body;
    }
  }
  return j;
}

// ---------------------------------------------------------------- controllers

std::string AppApi::FileSpec(const std::string& spec) const {
  // A spec naming a file (FILE.json[#method], FILE.toml) is read only under the root.
  const std::string file = spec.substr(0, spec.find('#'));
  const auto ends = [&](const char* ext) {
    const std::string e(ext);
    return file.size() > e.size() && file.compare(file.size() - e.size(), e.size(), e) == 0;
  };
  if (ends(".json") || ends(".toml") || file.find('/') != std::string::npos) Confine(file);
  return spec;
}

std::string AppApi::ModelSpec(const nlohmann::json& model) {
  if (model.is_string()) return FileSpec(model.get<std::string>());
  if (!model.is_object())
    throw HttpError(400, "field 'model' must be a model spec or a model object");
  // A model object (an entry of a model file): read as a model file of one
  // model, held in memory by the request's ModelFileScope (no file written).
  int n;
  {
    std::lock_guard lock(mutex_);
    n = next_file_++;
  }
  const std::string name = fmt::format("request-model-{}.json", n);
  ModelFileScope::Provide(name, nlohmann::json{{"models", nlohmann::json::array({model})}});
  return name;
}

namespace {

// The controller settings of a request (the command line's names).
void ReadControllerSettings(const nlohmann::json& b, ControllerSettings& s) {
  Get(b, "controller", s.controller);
  Get(b, "rule", s.rule);
  // P and M as the flags take them: at least 1 (0 read as "the rule's").
  for (const auto& [key, value] : {std::pair{"P", &s.P}, std::pair{"M", &s.M}})
    if (Get(b, key, *value) && *value < 1)
      throw HttpError(422, fmt::format("field '{}' must be at least 1 (as --{}), got {}", key,
                                       key, *value));
  Get(b, "lambda", s.lambda);
  Get(b, "constrained", s.constrained);
  Get(b, "pid_rule", s.pid_rule);
  Get(b, "tau_c", s.tau_c);
  Get(b, "Kc", s.pid_kc);
  Get(b, "Ti", s.pid_ti);
  Get(b, "Td", s.pid_td);
  Get(b, "Kff", s.pid_kff);
  Get(b, "t_filter", s.t_filter);
  Get(b, "disturbance", s.disturbance);
  Get(b, "measurement_noise", s.measurement_noise);
  Get(b, "state_noise", s.state_noise);
  Get(b, "disturbance_noise", s.disturbance_noise);
  Get(b, "response_time", s.response_time);
  Get(b, "overshoot", s.overshoot);
  Get(b, "aggressiveness", s.aggressiveness);
  Get(b, "du_max", s.limits.du_max);
  Get(b, "y_min", s.y_min);
  Get(b, "y_max", s.y_max);
}

std::vector<std::string> LoadSteps(const nlohmann::json& b) {
  std::vector<std::string> out;
  if (!b.contains("load_step") || b["load_step"].is_null()) return out;
  const auto& l = b["load_step"];
  if (l.is_string()) {
    if (!l.get<std::string>().empty()) out.push_back(l.get<std::string>());
  } else if (l.is_array()) {
    for (const auto& x : l)
      if (x.is_string()) out.push_back(x.get<std::string>());
  } else {
    throw HttpError(400, "field 'load_step' must be \"at=T,size=D\" or a list of them");
  }
  return out;
}

nlohmann::json Trace(const ClosedLoopResult& r) {
  return {{"t", Decimate(r.t)}, {"r", Decimate(r.r)}, {"y", Decimate(r.y)}, {"u", Decimate(r.u)}};
}

// Bounded work per request: the sample time, the samples of a run and the
// horizons (each with the limit it broke; 422).
constexpr double kMinTs = 1e-4;      // s
constexpr double kMaxSamples = 2e6;  // duration / Ts
constexpr int kMaxHorizon = 5000;    // P, M (samples)
void CheckWork(double Ts, double duration, int P, int M) {
  if (!(Ts >= kMinTs) || !std::isfinite(Ts))
    throw HttpError(422,
                    fmt::format("Ts must be at least {:g} s in the app, got {:g}", kMinTs, Ts));
  if (std::isfinite(duration) && duration / Ts > kMaxSamples)
    throw HttpError(422, fmt::format("duration / Ts = {:.3g} samples, above the app's limit of "
                                     "{:g} per request",
                                     duration / Ts, kMaxSamples));
  if (!std::isfinite(duration))
    throw HttpError(422, fmt::format("duration must be finite, got {}", duration));
  if (P > kMaxHorizon || M > kMaxHorizon)
    throw HttpError(422, fmt::format("horizons above {} samples are refused in the app, got "
                                     "P = {}, M = {}",
                                     kMaxHorizon, P, M));
}

// A model's dead time and order become the states of the MPC's observer and
// of the predictions, and the design's work grows with their cube (a 12 s
// delay at Ts = 0.01 s: 1200 states, 18 s of design no deadline stops). The
// app designs for at most kMaxModelStates of them per request.
constexpr int kMaxModelStates = 1000;
void CheckModelSize(const std::string& model, double Ts) {
  const TransferFunction tf = ParseControllerModel(model);
  const double states = std::round(tf.delay() / Ts) + tf.Order();
  if (states > kMaxModelStates)
    throw HttpError(422, fmt::format("the model's dead time of {:g} s and order {} make {:.0f} "
                                     "states at Ts = {:g} s, above the app's limit of {} per "
                                     "request (a longer Ts, or `pneumid control` without the "
                                     "limit)",
                                     tf.delay(), tf.Order(), states, Ts, kMaxModelStates));
}

}  // namespace

nlohmann::ordered_json AppApi::Tune(const nlohmann::json& b) {
  TuneWorkflowOptions c;
  if (!b.contains("model")) throw HttpError(400, "field 'model' is missing");
  c.model = ModelSpec(b["model"]);
  c.Ts = 0.01;
  Get(b, "Ts", c.Ts);
  Get(b, "rule", c.rule);
  if (c.rule.empty()) c.rule = "shridhar-cooper";
  Get(b, "M", c.M);
  Get(b, "P", c.P);
  Get(b, "lambda", c.lambda);
  CheckWork(c.Ts, 0.0, c.P, c.M);
  CheckModelSize(c.model, c.Ts);
  // A controller, when given, must be one (whatever the rule).
  std::string controller;
  if (Get(b, "controller", controller)) ControllerTypeFromString(controller);
  if (c.rule == "auto") {
    if (!controller.empty()) c.controller = controller;
    Get(b, "response_time", c.response_time);
    Get(b, "overshoot", c.overshoot);
    Get(b, "aggressiveness", c.aggressiveness);
    Get(b, "u_min", c.u_min);
    Get(b, "u_max", c.u_max);
    Get(b, "du_max", c.du_max);
    Get(b, "measurement_noise", c.measurement_noise);
    Get(b, "state_noise", c.state_noise);
    Get(b, "disturbance_noise", c.disturbance_noise);
    // The loop's plant bounds the design as in /api/control: the review then
    // describes the controller that runs.
    if (Get(b, "plant", c.plant)) c.plant = PlantSpec(c.plant);
  }
  return RunTuneWorkflow(c).ToJson();
}

nlohmann::ordered_json AppApi::Control(const nlohmann::json& b, const std::atomic<bool>* cancel) {
  cli::ControlArgs c;
  c.stop = cancel;
  if (!b.contains("model")) throw HttpError(400, "field 'model' is missing");
  c.model = ModelSpec(b["model"]);
  ReadControllerSettings(b, c.controller);
  Get(b, "u_min", c.controller.limits.u_min);
  Get(b, "u_max", c.controller.limits.u_max);
  if (Get(b, "plant", c.plant)) c.plant = PlantSpec(c.plant);
  Get(b, "Ts", c.Ts);
  if (!Get(b, "setpoint", c.setpoint)) throw HttpError(400, "field 'setpoint' is missing");
  c.setpoint = SignalSpec(c.setpoint);
  if (!Get(b, "duration", c.duration)) throw HttpError(400, "field 'duration' is missing");
  PNEUMID_CHECK(c.duration > 0.0, "duration must be positive, got {}", c.duration);
  CheckWork(c.Ts, c.duration, c.controller.P, c.controller.M);
  Get(b, "noise", c.noise);
  Get(b, "seed", c.seed);
  c.load_steps = LoadSteps(b);
  std::vector<std::string> warnings;
  CheckModelSize(c.model, c.Ts);
  std::vector<cli::ControlRun> runs = cli::SimulateControl(c, &warnings);
  // A set-point that changes at every sample (a sine, a PRBS) makes every
  // sample a step: the answer lists the first kMaxSteps of them (the summary
  // is over all) and says how many there were, instead of growing to
  // hundreds of MB (2e6 samples: 663 MB, 5 GB of server memory).
  std::vector<std::size_t> step_counts;
  for (cli::ControlRun& r : runs) {
    std::vector<StepMetrics>& steps = r.result.metrics.steps;
    step_counts.push_back(steps.size());
    if (steps.size() > kMaxSteps) steps.resize(kMaxSteps);
  }
  nlohmann::ordered_json j = cli::ControlJson(runs, warnings);
  for (std::size_t i = 0; i < runs.size(); ++i) {
    nlohmann::ordered_json& run = runs.size() == 1 ? j : j["compare"][i];
    run["steps_total"] = step_counts[i];
  }
  j["trace"] = Trace(runs.front().result);
  return j;
}

// ---------------------------------------------------------------- model views

namespace {

using cli::JsonNumbers;

// The model simulated on a data set from an estimated initial state (as
// `pneumid validate --initial-state estimate`), its fit and the residual
// correlations (MATLAB resid: whiteness and independence from the input).
nlohmann::ordered_json OnData(const IdentifiedModel& m, const Dataset& data) {
  nlohmann::ordered_json j;
  const Eigen::VectorXd yhat = SimulateModel(m, data, 0, 0, InitialCondition::kEstimate);
  const Eigen::VectorXd y = data.y(0);
  j["fit_percent"] = NrmseFit(y, yhat);
  j["t"] = Decimate(data.time());
  j["y"] = Decimate(y);
  j["y_model"] = Decimate(yhat);
  const Eigen::VectorXd e = y - yhat;
  if (e.allFinite()) {
    const Eigen::VectorXd ec = e.array() - e.mean();
    const Eigen::VectorXd uc = data.u(0).array() - data.u(0).mean();
    const int max_lag = static_cast<int>(std::min<Eigen::Index>(25, e.size() - 2));
    try {
      const ResidualCorrelation c = ComputeResidualCorrelation(ec, uc, max_lag);
      j["residuals"] = {{"auto_lags", JsonNumbers(c.auto_lags)},
                        {"autocorr", JsonNumbers(c.autocorr)},
                        {"cross_lags", JsonNumbers(c.cross_lags)},
                        {"crosscorr", JsonNumbers(c.crosscorr)},
                        {"bound", c.bound},
                        {"confidence", c.confidence},
                        {"auto_outside", c.auto_outside},
                        {"cross_outside", c.cross_outside}};
    } catch (const InvalidArgument& ex) {
      j["residuals"] = {{"error", ex.what()}};
    }
  } else {
    j["residuals"] = {{"error", "the simulated output is not finite (the model diverges)"}};
  }
  return j;
}

}  // namespace

// Step, Bode and, on the estimation and validation data, the simulated
// output and the residual correlations of one model (an entry of a model
// file, as /api/identify's model_file holds it).
nlohmann::ordered_json AppApi::ModelViews(const nlohmann::json& b) {
  if (!b.contains("model") || !b["model"].is_object())
    throw HttpError(400, "field 'model' must be a model object (an entry of a model file)");
  IdentifiedModel m;
  try {
    m = IdentifiedModelFromJson(b["model"]);
  } catch (const std::exception& e) {
    throw HttpError(400, fmt::format("field 'model': {}", e.what()));
  }
  nlohmann::ordered_json j;
  j["method"] = m.method;
  // The linear dynamics (of a block-oriented model: its linear part).
  const TransferFunction& g = m.discrete ? *m.discrete : m.tf;
  j["linear_part"] = m.input_map.has_value() || m.output_map.has_value();
  try {
    const TimeResponse s = Step(g);
    j["step"] = {{"t", Decimate(s.t)}, {"y", Decimate(s.y)}};
  } catch (const std::exception& e) {
    j["step"] = {{"error", e.what()}};
  }
  try {
    const BodeData bd = Bode(g);
    j["bode"] = {{"omega", JsonNumbers(bd.omega)},
                 {"magnitude_db", JsonNumbers(bd.magnitude_db)},
                 {"phase_deg", JsonNumbers(bd.phase_deg)}};
  } catch (const std::exception& e) {
    j["bode"] = {{"error", e.what()}};
  }
  if (b.contains("data") && !b["data"].is_null())
    j["estimation"] = OnData(m, FindDataSet(b["data"], "data")->data);
  if (b.contains("validation") && !b["validation"].is_null())
    j["validation"] = OnData(m, FindDataSet(b["validation"], "validation")->data);
  return j;
}

// ---------------------------------------------------------------- commissioning

namespace {
constexpr double kMaxCommissionBudget = 600.0;  // s of plant time per request
}  // namespace

// The library's Commission() on a simulated plant, and the files of
// `pneumid commission -o DIR` (WriteCommissionFiles): in DIR under the root
// when the request names one, else in the app's temporary folder.
nlohmann::ordered_json AppApi::Commission(const nlohmann::json& b,
                                          const std::atomic<bool>* cancel) {
  std::string plant_spec = "ipa";
  if (Get(b, "plant", plant_spec)) plant_spec = PlantSpec(plant_spec);
  double Ts = 0.01;
  const bool ts_given = Get(b, "Ts", Ts);
  CommissionOptions o;
  if (b.contains("range") && !b["range"].is_null()) {
    const nlohmann::json& r = b["range"];
    if (!r.is_array() || r.size() != 2 || !r[0].is_number() || !r[1].is_number())
      throw HttpError(400,
                      fmt::format("field 'range' must be [low, high], got {}", Excerpt(r.dump())));
    o.range_min = r[0].get<double>();
    o.range_max = r[1].get<double>();
  }
  Get(b, "budget", o.budget);
  if (!(o.budget > 0.0 && o.budget <= kMaxCommissionBudget))
    throw HttpError(422, fmt::format("budget must lie in (0, {:g}] s of plant time in the app, "
                                     "got {:g}",
                                     kMaxCommissionBudget, o.budget));
  CheckWork(Ts, o.budget, 0, 0);
  Get(b, "controller", o.controller);
  Get(b, "aggressiveness", o.aggressiveness);
  Get(b, "methods", o.methods);
  double limit = 0.0;
  if (Get(b, "u_min", limit)) o.u_min = limit;
  if (Get(b, "u_max", limit)) o.u_max = limit;
  std::uint64_t seed = 1;
  if (Get(b, "seed", seed)) o.seed = seed;
  PlantOptions po;
  po.seed = o.seed;
  double noise = 0.0;
  if (Get(b, "noise", noise)) po.noise_sigma = noise;
  std::string gaps = "plant";
  Get(b, "input_gaps", gaps);
  std::string error;
  PNEUMID_CHECK(o.IsValid(&error), "{}", error);
  // The command's loop period: one PWM period on the IPA, unless given.
  CommissionPlant made =
      MakeCommissionPlant(plant_spec, ts_given ? std::optional<double>(Ts) : std::nullopt, po, Ts);
  std::unique_ptr<Plant> plant = std::move(made.plant);
  Ts = made.Ts;
  CheckWork(Ts, o.budget, 0, 0);
  SetInputGaps(o, *plant, gaps);
  // The plant's default specification (a positioning drive's: 2 % and 1 s),
  // unless the request gives one.
  SetDefaultSpecification(o, PlantActuator(*plant));
  Get(b, "overshoot", o.overshoot);
  Get(b, "settling", o.settling);
  PNEUMID_CHECK(o.IsValid(&error), "{}", error);
  std::string dir_field;
  fs::path dir;
  if (Get(b, "dir", dir_field) && !dir_field.empty()) {
    dir = Confine(dir_field);
  } else {
    std::lock_guard<std::mutex> lock(mutex_);
    dir = options_.work / fmt::format("commission{}", next_commission_++);
  }
  fs::create_directories(dir);
  o.directory = dir.string();
  // The client leaving, the deadline and the server stopping set `cancel`
  // (without a server, the app's shutdown flag).
  o.stop = cancel != nullptr ? cancel : &shutting_down_;
  const CommissionResult r = pneumid::Commission(*plant, o);
  const Actuator act = o.actuator ? *o.actuator : PlantActuator(*plant);
  CommissionFilesOptions fo;
  fo.directory = dir.string();
  fo.Ts = Ts;
  fo.plant = plant_spec;
  fo.plant_description = plant->Describe();
  fo.report = true;
  const CommissionFiles files = WriteCommissionFiles(r, act, fo);
  nlohmann::ordered_json j = r.ToJson();
  j["directory"] = Inside(dir, options_.root) ? fs::relative(dir, options_.root).string() : "";
  j["files"] = files.ToJson();
  j["c_module"] = files.c_module;
  const fs::path toml = dir / "controller.toml";
  std::error_code ec;
  j["controller_toml"] = fs::is_regular_file(toml, ec) ? ReadFile(toml) : "";
  const Dataset& data = r.experiment.data;
  if (data.size() > 0)
    j["experiment_trace"] = {
        {"t", Decimate(data.time())}, {"u", Decimate(data.u(0))}, {"y", Decimate(data.y(0))}};
  if (!r.attempts.empty()) j["trace"] = Trace(r.attempts.back().result);
  return j;
}

// ---------------------------------------------------------------- real-time run

Response AppApi::RunStart(const nlohmann::json& b) {
  if (run_.Running())
    return ErrorResponse(409, "a real-time run is going on (POST /api/run/stop ends it)");
  cli::RunArgs o;
  if (b.contains("model")) {
    o.model = ModelSpec(b["model"]);
    // The run's thread reads a model object from its own scope.
    if (b["model"].is_object())
      o.model_document = nlohmann::json{{"models", nlohmann::json::array({b["model"]})}};
  }
  ReadControllerSettings(b, o.controller);
  if (Get(b, "setpoint", o.setpoint)) o.setpoint = SignalSpec(o.setpoint);
  o.load_steps = LoadSteps(b);
  double u = 0.0;
  if (Get(b, "u_min", u)) o.safety.u_min = u;
  if (Get(b, "u_max", u)) o.safety.u_max = u;
  if (Get(b, "rate_max", u)) o.safety.rate_max = u;
  RealtimeConfig config;
  if (Get(b, "io", config.io)) CheckIo(config.io);
  if (Get(b, "plant", config.plant)) config.plant = PlantSpec(config.plant);
  Get(b, "Ts", config.loop.period);
  Get(b, "duration", config.loop.duration);
  CheckWork(config.loop.period, config.loop.duration, o.controller.P, o.controller.M);
  Get(b, "seed", o.rt.seed);
  double noise = 0.0;
  if (Get(b, "noise", noise)) o.rt.noise = noise;
  std::string safe_state;
  if (Get(b, "safe_state", safe_state)) config.safety.safe_state = SafeStateFromString(safe_state);
  Get(b, "max_overruns", config.safety.max_overruns);
  const IoSpec io = ParseIoSpec(config.io);
  // The simulator needs no real-time priority (nor the server's memory locked).
  config.loop.realtime = io.kind != IoKind::kSim;
  std::string error;
  PNEUMID_CHECK(config.loop.IsValid(&error), "{}", error);
  o.safety.ApplyTo(config.safety);
  PNEUMID_CHECK(config.safety.IsValid(&error), "invalid safety settings: {}", error);
  // Errors in the settings answer here rather than in the run's status.
  CheckModelSize(o.model, config.loop.period);
  ParseSignal(o.setpoint);
  ToControllerSpec(o.controller);  // the controller type, rules and names
  if (!run_.Start(std::move(o), std::move(config)))
    return ErrorResponse(409, "a real-time run is going on (POST /api/run/stop ends it)");
  return JsonResponse({{"state", "running"}});
}

void AppApi::Stream(const Request& req, const std::function<bool(const std::string&)>& send) {
  if (req.path != "/api/run/stream") {
    send(nlohmann::json{{"error", fmt::format("no WebSocket at {}", req.path)}}.dump());
    return;
  }
  std::uint64_t run_id = 0;
  std::size_t sent = 0;
  auto idle_since = std::chrono::steady_clock::now();
  while (!shutting_down_) {
    LiveRun::Update u = run_.Since(run_id, sent);
    if (u.run_id != run_id) {
      run_id = u.run_id;
      sent = 0;
    }
    if (!u.samples.empty()) {
      nlohmann::json t = nlohmann::json::array(), r = t, y = t, uu = t;
      for (const LogRecord& rec : u.samples) {
        t.push_back(rec.t);
        r.push_back(rec.r);
        y.push_back(rec.y);
        uu.push_back(rec.u);
      }
      sent += u.samples.size();
      if (!send(nlohmann::json{{"t", t}, {"r", r}, {"y", y}, {"u", uu}}.dump())) return;
      idle_since = std::chrono::steady_clock::now();
    }
    if (u.ended) {
      send(nlohmann::json{{"done", true}, {"summary", u.summary}}.dump());
      return;
    }
    if (std::chrono::steady_clock::now() - idle_since > std::chrono::seconds(2)) {
      if (!send("")) return;  // a ping: has the page gone?
      idle_since = std::chrono::steady_clock::now();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

// ---------------------------------------------------------------- exports

Response AppApi::ExportController(const nlohmann::json& b) {
  RealtimeConfig config;
  if (Get(b, "io", config.io)) CheckIo(config.io);
  if (Get(b, "plant", config.plant)) PlantSpec(config.plant);
  Get(b, "Ts", config.loop.period);
  Get(b, "duration", config.loop.duration);
  Get(b, "u_min", config.safety.u_min);
  Get(b, "u_max", config.safety.u_max);
  Get(b, "rate_max", config.safety.rate_max);
  Get(b, "max_overruns", config.safety.max_overruns);
  ParseIoSpec(config.io);
  std::string error;
  PNEUMID_CHECK(config.loop.IsValid(&error), "{}", error);
  PNEUMID_CHECK(config.safety.IsValid(&error), "{}", error);

  // The controller goes on the command line (the configuration holds the loop,
  // backend and safety settings).
  std::string cmd = "pneumid run --config controller.toml";
  std::string model_note;
  if (b.contains("model") && b["model"].is_string()) {
    cmd += " --model " + ShellQuote(FileSpec(b["model"].get<std::string>()));
  } else if (b.contains("model") && b["model"].is_object()) {
    cmd += " --model model.json";
    model_note = "# model.json: {\"models\": [" + b["model"].dump() + "]}\n";
  }
  auto flag = [&](const char* key, const char* name) {
    if (!b.contains(key) || b[key].is_null()) return;
    const auto& v = b[key];
    if (v.is_boolean()) {
      if (v.get<bool>()) cmd += fmt::format(" --{}", name);
    } else {
      cmd += fmt::format(" --{} {}", name,
                         ShellQuote(v.is_string() ? v.get<std::string>() : v.dump()));
    }
  };
  flag("controller", "controller");
  flag("rule", "rule");
  flag("P", "P");
  flag("M", "M");
  flag("lambda", "lambda");
  flag("response_time", "response-time");
  flag("overshoot", "overshoot");
  flag("aggressiveness", "aggressiveness");
  flag("constrained", "constrained");
  flag("pid_rule", "pid-rule");
  flag("Kc", "Kc");
  flag("Ti", "Ti");
  flag("Td", "Td");
  flag("Kff", "Kff");
  flag("disturbance", "disturbance");
  flag("measurement_noise", "measurement-noise");
  flag("state_noise", "state-noise");
  flag("disturbance_noise", "disturbance-noise");
  flag("setpoint", "setpoint");
  for (const std::string& l : LoadSteps(b)) cmd += " --load-step " + ShellQuote(l);

  const auto q = [](const std::string& s) { return nlohmann::json(s).dump(); };
  std::string toml;
  toml += "# Real-time configuration written by `pneumid app`; run the controller with\n";
  toml += "#   " + cmd + "\n";
  toml += model_note;
  toml += fmt::format("\n[loop]\nperiod = {}\nduration = {}\n",
                      nlohmann::json(config.loop.period).dump(),
                      nlohmann::json(config.loop.duration).dump());
  toml += fmt::format("\n[io]\nbackend = {}\nplant = {}\n", q(config.io), q(config.plant));
  toml += fmt::format("\n[safety]\nu_min = {}\nu_max = {}\nrate_max = {}\nmax_overruns = {}\n",
                      nlohmann::json(config.safety.u_min).dump(),
                      nlohmann::json(config.safety.u_max).dump(),
                      nlohmann::json(config.safety.rate_max).dump(), config.safety.max_overruns);
  // Settings `run` has no flag for go in the configuration's [controller].
  std::string controller;
  for (const char* key : {"tau_c", "t_filter", "du_max", "y_min", "y_max"}) {
    if (!b.contains(key) || b[key].is_null()) continue;
    if (!b[key].is_number())
      throw HttpError(400, fmt::format("field '{}' must be a number", key));
    controller += fmt::format("{} = {}\n", key, b[key].dump());
  }
  if (!controller.empty()) toml += "\n[controller]\n" + controller;
  ParseRealtimeConfig(toml, "controller.toml");  // what `run --config` will read
  Response r;
  r.content_type = "text/plain; charset=utf-8";
  r.body = toml;
  return r;
}

Response AppApi::ExportReport(const nlohmann::json& b) {
  if (!b.contains("data")) throw HttpError(400, "field 'data' is missing");
  const auto set = FindDataSet(b["data"], "data");
  ReportOptions o;
  if (b.contains("methods")) {
    if (!b["methods"].is_array()) throw HttpError(400, "field 'methods' must be a list");
    o.methods.clear();
    for (const auto& m : b["methods"])
      if (m.is_string()) o.methods.push_back(m.get<std::string>());
  }
  o.title = fmt::format("Identification report: {}", set->name);
  o.choose_structure = true;  // as `pneumid report` without orders
  o.commands = {fmt::format("pneumid report {} --method {} --output-dir report",
                            ShellQuote(set->name), fmt::join(o.methods, ","))};
  std::string error;
  PNEUMID_CHECK(o.IsValid(&error), "{}", error);
  int n;
  {
    std::lock_guard lock(mutex_);
    n = next_file_++;
  }
  const fs::path dir = options_.work / fmt::format("report{}", n);
  const ReportSummary s = WriteIdentificationReport(set->data, o, dir.string());
  Response r;
  r.content_type = "text/html; charset=utf-8";
  r.body = ReadFile(s.html_path);
  return r;
}

}  // namespace pneumid::app
