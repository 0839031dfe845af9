// The HTTP JSON API of `pneumid app` (docs/app.md): the page and its assets,
// data sets kept in memory by id, identification, tuning, closed-loop
// simulation, the real-time run with its live stream, and the exports. The
// answers are the JSON that the command line prints (command_json.hpp).
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../data_options.hpp"
#include "http_server.hpp"
#include "live_run.hpp"
#include "pneumid/data/dataset.hpp"

namespace pneumid::app {

struct AppOptions {
  std::filesystem::path root;    ///< canonical; files are read only below it
  std::filesystem::path assets;  ///< the built page (index.html, assets/); may not exist
  std::filesystem::path work;    ///< the server's own temporary folder
  std::string token;
  /// Device paths a request may name as its I/O (comedi:PATH); none by default.
  std::vector<std::string> allowed_devices;
};

class AppApi {
 public:
  explicit AppApi(AppOptions options);
  ~AppApi();

  /// Answers one request (never throws: errors become {"error": ...}).
  Response Handle(const Request& request);
  /// GET /api/run/stream: the live samples of the run as text frames.
  void Stream(const Request& request, const std::function<bool(const std::string&)>& send);
  /// Stops a run going on (the plant to its safe state) and ends the streams.
  void Shutdown();

 private:
  struct DataSet {
    std::string id, name, path;
    std::vector<std::string> columns;
    std::string t, u, y;
    Dataset data;
  };

  Response Route(const Request& request);
  Response Page();
  Response Asset(const std::string& path);
  nlohmann::json Files(const Request& request);
  nlohmann::json OpenData(const nlohmann::json& body);
  nlohmann::json Upload(const Request& request);
  nlohmann::json Session();
  nlohmann::json Identify(const nlohmann::json& body, const std::atomic<bool>* cancel = nullptr);
  nlohmann::ordered_json Tune(const nlohmann::json& body);
  nlohmann::ordered_json Control(const nlohmann::json& body,
                                 const std::atomic<bool>* cancel = nullptr);
  nlohmann::ordered_json Commission(const nlohmann::json& body,
                                    const std::atomic<bool>* cancel = nullptr);
  nlohmann::ordered_json ModelViews(const nlohmann::json& body);
  Response RunStart(const nlohmann::json& body);
  Response ExportController(const nlohmann::json& body);
  Response ExportReport(const nlohmann::json& body);

  /// Loads the data file of `o` (opened or uploaded) as a data set named `name`.
  /// `session`: the set becomes the session's data set (GET /api/session);
  /// a validation set does not.
  nlohmann::json LoadDataSet(std::string name, const cli::DataOptions& o, bool session = true);
  nlohmann::json AddDataSet(DataSet set, bool session = true);
  std::shared_ptr<const DataSet> FindDataSet(const nlohmann::json& id, const char* field) const;
  std::filesystem::path Confine(const std::string& path) const;
  /// The model spec of a request's "model": a spec string (files confined to
  /// the root), or a model object provided in memory to the request's
  /// ModelFileScope under a name that the spec then is.
  std::string ModelSpec(const nlohmann::json& model);
  std::string FileSpec(const std::string& spec) const;
  /// A set-point or input signal spec whose file (file:PATH,...) lies under
  /// the root, with the path made absolute; other signals unchanged.
  std::string SignalSpec(const std::string& spec) const;
  /// A plant spec whose files (ipa:config=PATH, FILE.json, FILE.toml) lie
  /// under the root, with the configuration path made absolute.
  std::string PlantSpec(const std::string& spec) const;
  /// An I/O spec; a device (comedi:PATH) only from options_.allowed_devices.
  void CheckIo(const std::string& io) const;

  AppOptions options_;
  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<const DataSet>> data_;
  int next_data_ = 1;
  int next_file_ = 1;
  int next_commission_ = 1;
  // The session a reloaded or second page takes over (GET /api/session,
  // guarded by mutex_): the last data set opened and its last identification.
  nlohmann::json session_data_;
  nlohmann::json session_identify_;
  nlohmann::json session_identify_request_;
  LiveRun run_;
  std::atomic<bool> shutting_down_{false};
};

}  // namespace pneumid::app
