// The HTTP and WebSocket server of `pneumid app` (Boost.Beast): an acceptor
// thread and one thread per connection (synchronous reads and writes,
// keep-alive), at most `max_connections` at a time. Every request passes the
// security checks of docs/app.md before it reaches the handler:
//
//   - the token, as the query parameter `token=TOKEN`, the header
//     `X-Pneumid-Token: TOKEN` or the cookie `pneumid_token` that the page's
//     answer sets (compared in constant time), else 403;
//   - an `Origin` header, when present, names the server itself
//     (http://127.0.0.1:PORT, http://localhost:PORT, http://HOST:PORT), else 403;
//   - bodies are limited: 50 MB for uploads (POST /api/data/upload), 1 MB for
//     the rest; a larger Content-Length is refused with 413 before the body is
//     read.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace pneumid::app {

/// A request as the handler sees it (after the security checks).
struct Request {
  std::string method;                        ///< "GET", "POST", ...
  std::string path;                          ///< without the query, percent-decoded
  std::map<std::string, std::string> query;  ///< decoded parameters (token removed)
  std::string body;
  std::string content_type;
  /// Set while the handler runs when the client has gone away, the request's
  /// deadline has passed or the server stops: work that can stop should.
  std::shared_ptr<std::atomic<bool>> cancel = std::make_shared<std::atomic<bool>>(false);
};

struct Response {
  int status = 200;
  std::string content_type = "application/json";
  std::string body;
  std::vector<std::pair<std::string, std::string>> headers;  ///< extra headers
};

/// A WebSocket session: sends text frames until it returns. `send` returns
/// false once the peer has gone.
using WebSocketHandler =
    std::function<void(const Request&, const std::function<bool(const std::string&)>& send)>;

struct ServerOptions {
  std::string host = "127.0.0.1";
  int port = 8050;  ///< 0: a free port
  std::string token;
  std::size_t upload_limit = 50u << 20;  ///< bytes
  std::size_t body_limit = 1u << 20;     ///< bytes
  int max_connections = 32;
  /// Refuse a Host header other than this server's address (127.0.0.1:PORT,
  /// localhost:PORT, HOST:PORT): a page of another site that a DNS name
  /// resolves to 127.0.0.1 cannot reach the app. Off for a wildcard --host.
  bool check_host = true;
  /// Seconds a request may compute before Request::cancel is set (its
  /// answer is then 503); 0: no deadline.
  double request_deadline = 120.0;
};

/// The JSON error body {"error": message}.
Response ErrorResponse(int status, const std::string& message);

/// True when a and b are equal, in a time that does not depend on where they differ.
bool ConstantTimeEquals(const std::string& a, const std::string& b);

/// Decodes %XX and '+' of a URL component.
std::string PercentDecode(const std::string& s);

class HttpServer {
 public:
  using Handler = std::function<Response(const Request&)>;

  /// Binds and listens. @throws DataError when the address cannot be bound.
  HttpServer(ServerOptions options, Handler handler, WebSocketHandler websocket);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  /// The port bound (the free one chosen for port 0).
  int port() const { return port_; }
  /// Accepts connections until Stop() (blocks). Returns after Stop(): at once when every connection
  /// has ended, else after 1 s with requests still running (Abandoned()).
  void Run();
  /// Run() returned while requests were still being answered: their threads
  /// use the server, so the process must end without destroying it
  /// (std::_Exit after its own clean-up).
  bool Abandoned() const { return abandoned_; }
  /// Stops accepting and closes the open connections; Run() returns.
  void Stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int port_ = 0;
  bool abandoned_ = false;
};

}  // namespace pneumid::app
