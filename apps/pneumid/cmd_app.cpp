// pneumid app: the browser app (docs/app.md). Serves the page and its HTTP JSON
// API on http://HOST:PORT/?token=TOKEN until SIGINT or SIGTERM (a real-time
// run going on is stopped first, the plant in its safe state).
//
//   pneumid app [--port 8050] [--host 127.0.0.1] [--root DIR] [--open]
//               [--assets DIR] [--token TOKEN]
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "app/app_api.hpp"
#include "app/http_server.hpp"
#include "command.hpp"
#include "pneumid/common/check.hpp"

extern char** environ;

namespace pneumid::cli {
namespace {

namespace fs = std::filesystem;

struct AppArgs {
  int port = 8050;
  std::string host = "127.0.0.1";
  std::string root = ".";
  bool open = false;
  std::string assets;
  std::string token;
  std::vector<std::string> allow_devices;
  bool allow_remote = false;
  double request_deadline = 120.0;
};

bool IsLoopback(const std::string& host) {
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

std::string RandomToken() {
  std::random_device rd;
  std::string token;
  for (int i = 0; i < 4; ++i) token += fmt::format("{:08x}", static_cast<std::uint32_t>(rd()));
  return token;
}

// <exe dir>/web, or <exe dir>/../share/pneumid/web (installed).
fs::path DefaultAssets() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  const fs::path dir = exe.parent_path();
  if (fs::is_directory(dir / "web", ec)) return dir / "web";
  return dir / ".." / "share" / "pneumid" / "web";
}

// Runs xdg-open URL in the background when it is installed.
void OpenBrowser(const std::string& url) {
  pid_t pid;
  std::string program = "xdg-open";
  char* argv[] = {program.data(), const_cast<char*>(url.c_str()), nullptr};
  if (posix_spawnp(&pid, "xdg-open", nullptr, nullptr, argv, environ) != 0)
    std::cerr << "pneumid app: xdg-open is not available; open the address by hand\n";
}

void Serve(const AppArgs& c) {
  PNEUMID_CHECK(c.port >= 0 && c.port <= 65535, "--port must be 0 .. 65535, got {}", c.port);
  PNEUMID_CHECK(c.token.find_first_of(" \t\r\n&;=%#?") == std::string::npos,
                "--token must not contain spaces or any of &;=%#?");
  PNEUMID_CHECK(IsLoopback(c.host) || c.allow_remote,
                "--host {} exposes the app to the network (anyone who has the token can read "
                "--root and drive the plant); add --allow-remote to do so, or keep 127.0.0.1",
                c.host);
  if (!IsLoopback(c.host))
    std::cerr << "pneumid app: warning: listening on " << c.host
              << ", reachable from the network; the token is the only protection (no TLS)\n";
  std::error_code ec;
  const fs::path root = fs::canonical(c.root, ec);
  if (ec || !fs::is_directory(root))
    throw DataError(fmt::format("--root {}: not a folder", c.root));

  // The signals go to one thread (sigwait below): blocked here, before any
  // other thread starts, so every thread (the real-time loop too) inherits it.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  // A handler (never run: the signals stay blocked) so that signals a parent
  // shell set to be ignored (background jobs ignore SIGINT) still reach sigwait.
  struct sigaction sa {};
  sa.sa_handler = [](int) {};
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);

  app::AppOptions options;
  options.root = root;
  options.assets = c.assets.empty() ? DefaultAssets() : fs::path(c.assets);
  options.token = c.token.empty() ? RandomToken() : c.token;
  options.allowed_devices = c.allow_devices;
  std::string work = (fs::temp_directory_path() / "pneumid-app-XXXXXX").string();
  if (mkdtemp(work.data()) == nullptr)
    throw DataError(fmt::format("cannot create a temporary folder {}", work));
  options.work = work;
  // Removed on every way out (the uploads, models and logs of the session).
  const std::unique_ptr<const std::string, void (*)(const std::string*)> remove_work(
      &work, [](const std::string* w) {
        std::error_code e;
        fs::remove_all(*w, e);
      });
  // Model specs and other relative names resolve under the root.
  fs::current_path(root);

  app::AppApi api(options);
  app::ServerOptions so;
  so.request_deadline = c.request_deadline;
  so.host = c.host;
  so.port = c.port;
  so.token = options.token;
  // A wildcard address has no one name to check the Host header against.
  so.check_host = !(c.host == "0.0.0.0" || c.host == "::");
  app::HttpServer server(
      so, [&api](const app::Request& r) { return api.Handle(r); },
      [&api](const app::Request& r, const std::function<bool(const std::string&)>& send) {
        api.Stream(r, send);
      });
  const bool wildcard = c.host == "0.0.0.0" || c.host == "::";
  const std::string shown = wildcard ? "127.0.0.1" : c.host;
  if (wildcard)
    std::cerr << "pneumid app: listening on every interface; from another machine use this "
                 "machine's address in place of 127.0.0.1\n";
  const std::string url =
      fmt::format("http://{}:{}/?token={}", shown, server.port(), options.token);
  std::cout << "pneumid app: serving " << root.string() << " at " << url << std::endl;
  std::fflush(stdout);

  std::thread waiter([&] {
    int sig = 0;
    sigwait(&signals, &sig);
    std::cerr << "pneumid app: stopping\n";
    api.Shutdown();  // a run going on: to the safe state, its log completed
    server.Stop();
  });
  if (c.open) OpenBrowser(url);
  server.Run();
  waiter.join();
  if (server.Abandoned()) {
    // A request still computing holds the server: end within the second
    // anyway, the temporary folder removed.
    std::error_code e;
    fs::remove_all(work, e);
    std::cerr << "pneumid app: requests still running were abandoned\n";
    std::fflush(stderr);
    std::_Exit(0);
  }
}

const Registrar reg(
    "app", "Serve the browser app and its HTTP JSON API (docs/app.md)", [](CLI::App& app) {
      auto c = std::make_shared<AppArgs>();
      app.add_option("--port", c->port, "TCP port (0: a free one)")->capture_default_str();
      app.add_option("--host", c->host,
                     "Address to listen on (other than 127.0.0.1 exposes the "
                     "app to the network, behind the token)")
          ->capture_default_str();
      app.add_option("--root", c->root,
                     "Folder whose files the app may read (default: the "
                     "current one)")
          ->capture_default_str();
      app.add_flag("--open", c->open, "Open the page with xdg-open");
      app.add_option("--assets", c->assets,
                     "Folder of the built page (index.html, assets/; default: "
                     "web/ beside the program, or ../share/pneumid/web)");
      app.add_option("--token", c->token, "Access token (default: 32 random hex digits)");
      app.add_flag("--allow-remote", c->allow_remote,
                   "Allow a --host other than loopback (the app is then reachable from the "
                   "network, behind its token, without TLS)");
      app.add_option("--allow-device", c->allow_devices,
                     "A data-acquisition device the page may drive (comedi:PATH), repeatable; "
                     "by default the page drives the simulator or a plant server only");
      app.add_option("--request-deadline", c->request_deadline,
                     "Seconds a request may compute before it is stopped and answered 503 (0: "
                     "none); a request whose client goes away is stopped at once")
          ->capture_default_str()
          ->check(CLI::NonNegativeNumber);
      app.callback([c] { Serve(*c); });
    });

}  // namespace
}  // namespace pneumid::cli
