#include "http_server.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <sys/time.h>

#include <chrono>
#include <condition_variable>
#include <limits>
#include <map>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

#include "pneumid/common/check.hpp"
#include "pneumid/common/strings.hpp"

namespace pneumid::app {
namespace {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

constexpr int kIdleSeconds = 60;  // no byte for this long ends a connection
// A request's header must arrive within this time of the connection's turn to
// send one (a new or a kept-alive connection), however slowly its bytes come:
// idle and slow connections cannot hold the server's connection slots.
constexpr auto kHeaderDeadline = std::chrono::seconds(10);

std::string LimitText(std::size_t bytes) {
  return bytes % (1u << 20) == 0 ? fmt::format("{} MB", bytes >> 20)
                                 : fmt::format("{} bytes", bytes);
}

// "a=1&b=two" -> {a: 1, b: two}.
std::map<std::string, std::string> ParseQuery(const std::string& query) {
  std::map<std::string, std::string> out;
  std::size_t pos = 0;
  while (pos <= query.size() && !query.empty()) {
    const std::size_t amp = std::min(query.find('&', pos), query.size());
    const std::string item = query.substr(pos, amp - pos);
    if (!item.empty()) {
      const std::size_t eq = item.find('=');
      if (eq == std::string::npos)
        out[PercentDecode(item)] = "";
      else
        out[PercentDecode(item.substr(0, eq))] = PercentDecode(item.substr(eq + 1));
    }
    pos = amp + 1;
  }
  return out;
}

std::string CookieValue(const std::string& cookies, const std::string& name) {
  std::size_t pos = 0;
  while (pos < cookies.size()) {
    std::size_t end = cookies.find(';', pos);
    if (end == std::string::npos) end = cookies.size();
    std::string item = cookies.substr(pos, end - pos);
    const std::size_t first = item.find_first_not_of(' ');
    item = first == std::string::npos ? "" : item.substr(first);
    if (item.rfind(name + "=", 0) == 0) return item.substr(name.size() + 1);
    pos = end + 1;
  }
  return "";
}

}  // namespace

Response ErrorResponse(int status, const std::string& message) {
  Response r;
  r.status = status;
  r.body = nlohmann::json{{"error", message}}.dump();
  return r;
}

bool ConstantTimeEquals(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

std::string PercentDecode(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && hex(s[i + 1]) >= 0 && hex(s[i + 2]) >= 0) {
      out += static_cast<char>(hex(s[i + 1]) * 16 + hex(s[i + 2]));
      i += 2;
    } else if (s[i] == '+') {
      out += ' ';
    } else {
      out += s[i];
    }
  }
  return out;
}

struct HttpServer::Impl {
  ServerOptions options;
  Handler handler;
  WebSocketHandler websocket;
  net::io_context ioc{1};
  tcp::acceptor acceptor{ioc};
  std::vector<std::string> origins;  // allowed Origin values
  std::atomic<bool> stopping{false};
  std::mutex mutex;
  std::condition_variable idle;
  std::set<int> sockets;  // native handles of open connections
  int active = 0;
  // Connections waiting for a request header, since when (guarded by mutex).
  std::map<int, std::chrono::steady_clock::time_point> waiting;
  // Requests being computed: their connection, start and cancel flag (guarded by mutex).
  struct Running {
    std::chrono::steady_clock::time_point start;
    std::shared_ptr<std::atomic<bool>> cancel;
    bool deadline = false;  // cancelled by the deadline (not by the client)
  };
  std::map<int, Running> running;

  // Cancels the requests whose client has gone (the connection reads as
  // closed) or whose deadline has passed; with `all`, every one (the server
  // stops). Called with the mutex held.
  void CancelRunning(bool all) {
    const auto now = std::chrono::steady_clock::now();
    for (auto& [fd, r] : running) {
      if (r.cancel->load()) continue;
      bool gone = all;
      if (!gone) {
        pollfd p{fd, POLLIN | POLLRDHUP, 0};
        gone = ::poll(&p, 1, 0) > 0 && (p.revents & (POLLRDHUP | POLLHUP | POLLERR)) != 0;
      }
      if (!gone && options.request_deadline > 0.0 &&
          std::chrono::duration<double>(now - r.start).count() > options.request_deadline) {
        gone = true;
        r.deadline = true;
      }
      if (gone) r.cancel->store(true);
    }
  }

  void WaitingForHeader(int fd, bool waits) {
    std::lock_guard lock(mutex);
    if (waits)
      waiting[fd] = std::chrono::steady_clock::now();
    else
      waiting.erase(fd);
  }

  // Ends the connections whose header is overdue; with `oldest`, also the one
  // that has waited longest (to make room). Returns whether one was ended.
  // Called with the mutex held.
  bool EndWaiting(bool oldest) {
    const auto now = std::chrono::steady_clock::now();
    bool ended = false;
    auto longest = waiting.end();
    for (auto it = waiting.begin(); it != waiting.end();) {
      if (now - it->second > kHeaderDeadline) {
        ::shutdown(it->first, SHUT_RDWR);
        it = waiting.erase(it);
        ended = true;
        continue;
      }
      if (longest == waiting.end() || it->second < longest->second) longest = it;
      ++it;
    }
    if (oldest && !ended && longest != waiting.end()) {
      ::shutdown(longest->first, SHUT_RDWR);
      waiting.erase(longest);
      ended = true;
    }
    return ended;
  }

  // The security checks; an empty optional when the request may go on.
  std::optional<Response> Check(const http::request<http::string_body>& req,
                                const std::string& query_token) const {
    if (options.check_host) {
      const auto host = req.find(http::field::host);
      const std::string value = host == req.end() ? std::string() : std::string(host->value());
      bool ok = false;
      for (const std::string& o : origins) ok = ok || "http://" + value == o;
      if (!ok)
        return ErrorResponse(403, fmt::format("host '{}' is not this server's ({})", Excerpt(value),
                                              origins.front().substr(7)));
    }
    const auto origin = req.find(http::field::origin);
    if (origin != req.end()) {
      const std::string value(origin->value());
      bool ok = false;
      for (const std::string& o : origins) ok = ok || value == o;
      if (!ok)
        return ErrorResponse(
            403, fmt::format("origin {} is not this server's ({})", value, origins.front()));
    }
    std::string token = query_token;
    if (token.empty()) {
      const auto h = req.find("X-Pneumid-Token");
      if (h != req.end()) token = std::string(h->value());
    }
    if (token.empty()) {
      const auto c = req.find(http::field::cookie);
      if (c != req.end()) token = CookieValue(std::string(c->value()), "pneumid_token");
    }
    if (token.empty())
      return ErrorResponse(403,
                           "missing token: add ?token=TOKEN (printed at start) or the "
                           "header X-Pneumid-Token");
    if (!ConstantTimeEquals(token, options.token)) return ErrorResponse(403, "wrong token");
    return std::nullopt;
  }

  static void Write(tcp::socket& socket, const Response& r, unsigned version, bool keep_alive,
                    beast::error_code& ec) {
    http::response<http::string_body> res{static_cast<http::status>(r.status), version};
    res.set(http::field::server, "pneumid");
    res.set(http::field::content_type, r.content_type);
    res.set(http::field::cache_control, "no-store");
    res.set("X-Content-Type-Options", "nosniff");
    // The page loads only its own scripts, styles and connections, and no
    // other site may frame it.
    res.set("Content-Security-Policy",
            "default-src 'self'; script-src 'self'; style-src 'self' 'unsafe-inline'; "
            "img-src 'self' data: blob:; connect-src 'self' ws: wss:; object-src 'none'; "
            "base-uri 'none'; frame-ancestors 'none'; form-action 'self'");
    res.set("X-Frame-Options", "DENY");
    res.set("Referrer-Policy", "no-referrer");
    for (const auto& [k, v] : r.headers) res.set(k, v);
    res.keep_alive(keep_alive);
    res.body() = r.body;
    res.prepare_payload();
    http::write(socket, res, ec);
  }

  // After refusing a body: says it is done sending and reads what the client
  // still sends for a moment, so that closing does not reset the connection
  // (a reset would discard the answer before the client reads it).
  static void Drain(tcp::socket& socket) {
    beast::error_code ec;
    socket.shutdown(tcp::socket::shutdown_send, ec);
    timeval tv{0, 200000};
    ::setsockopt(socket.native_handle(), SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    std::vector<char> sink(64 * 1024);
    while (std::chrono::steady_clock::now() < end) {
      socket.read_some(net::buffer(sink), ec);
      if (ec) break;
    }
  }

  void Session(tcp::socket socket) {
    beast::error_code ec;
    beast::flat_buffer buffer;
    for (;;) {
      http::request_parser<http::string_body> parser;
      parser.header_limit(64 * 1024);
      // The limit is set once the path is known (a larger Content-Length would fail
      // read_header itself, without an answer).
      parser.body_limit(std::numeric_limits<std::uint64_t>::max());
      WaitingForHeader(socket.native_handle(), true);
      http::read_header(socket, buffer, parser, ec);
      WaitingForHeader(socket.native_handle(), false);
      if (ec) {
        // A malformed request gets a status before the connection closes
        // (not a connection that ended or timed out).
        if (ec == http::error::header_limit) {
          Write(socket, ErrorResponse(431, "the request header is larger than 64 KB"), 11, false,
                ec);
          Drain(socket);
        } else if (ec.category() == beast::error_code(http::error::bad_content_length).category()) {
          Write(socket, ErrorResponse(400, "malformed request: " + ec.message()), 11, false, ec);
          Drain(socket);
        }
        return;
      }
      const auto& head = parser.get();
      const std::string target(head.target());
      const std::size_t q = target.find('?');
      Request request;
      request.method = std::string(head.method_string());
      request.path = PercentDecode(target.substr(0, q));
      request.query = ParseQuery(q == std::string::npos ? "" : target.substr(q + 1));
      std::string token;
      if (auto it = request.query.find("token"); it != request.query.end()) {
        token = it->second;
        request.query.erase(it);
      }
      if (auto denied = Check(head, token)) {
        Write(socket, *denied, head.version(), false, ec);
        break;
      }
      const bool upload = request.path == "/api/data/upload";
      const std::size_t limit = upload ? options.upload_limit : options.body_limit;
      auto too_large = [&](std::optional<std::uint64_t> n) {
        const std::string what = upload ? "upload" : "request body";
        return ErrorResponse(
            413, n ? fmt::format("{} of {} bytes is larger than the {} limit", what, *n,
                                 LimitText(limit))
                   : fmt::format("{} is larger than the {} limit", what, LimitText(limit)));
      };
      if (parser.content_length() && *parser.content_length() > limit) {
        Write(socket, too_large(*parser.content_length()), head.version(), false, ec);
        Drain(socket);
        return;
      }
      parser.body_limit(limit);
      if (!parser.is_done() && beast::iequals(head[http::field::expect], "100-continue")) {
        http::response<http::empty_body> go_on{http::status::continue_, head.version()};
        http::write(socket, go_on, ec);
      }
      if (!parser.is_done()) http::read(socket, buffer, parser, ec);
      if (ec == http::error::body_limit) {
        Write(socket, too_large(std::nullopt), head.version(), false, ec);
        Drain(socket);
        return;
      }
      if (ec && ec != http::error::end_of_stream &&
          ec.category() == beast::error_code(http::error::bad_content_length).category()) {
        Write(socket, ErrorResponse(400, "malformed request body: " + ec.message()), head.version(),
              false, ec);
        Drain(socket);
        return;
      }
      if (ec) break;
      auto req = parser.release();
      if (websocket::is_upgrade(req)) {
        websocket::stream<tcp::socket> ws(std::move(socket));
        ws.set_option(websocket::stream_base::decorator(
            [](websocket::response_type& res) { res.set(http::field::server, "pneumid"); }));
        ws.accept(req, ec);
        if (ec) return;
        ws.text(true);
        auto send = [&ws](const std::string& text) {
          beast::error_code wec;
          ws.write(net::buffer(text), wec);
          return !wec;
        };
        try {
          websocket(request, send);
        } catch (const std::exception&) {
          // the peer went away or the stream failed: nothing to answer
        }
        ws.close(websocket::close_code::normal, ec);
        return;
      }
      request.body = std::move(req.body());
      if (auto ct = req.find(http::field::content_type); ct != req.end())
        request.content_type = std::string(ct->value());
      Response response;
      const int fd = socket.native_handle();
      {
        std::lock_guard lock(mutex);
        running[fd] = {std::chrono::steady_clock::now(), request.cancel, false};
      }
      try {
        response = handler(request);
      } catch (const std::exception& e) {
        response = ErrorResponse(500, e.what());
      }
      bool deadline = false;
      {
        std::lock_guard lock(mutex);
        deadline = running[fd].deadline;
        running.erase(fd);
      }
      if (request.cancel->load() && deadline)
        response = ErrorResponse(503, fmt::format("the request was stopped after its deadline of "
                                                  "{:g} s",
                                                  options.request_deadline));
      Write(socket, response, req.version(), req.keep_alive(), ec);
      if (ec || !req.keep_alive() || stopping) break;
    }
    socket.shutdown(tcp::socket::shutdown_send, ec);
  }
};

HttpServer::HttpServer(ServerOptions options, Handler handler, WebSocketHandler websocket)
    : impl_(std::make_unique<Impl>()) {
  impl_->options = std::move(options);
  impl_->handler = std::move(handler);
  impl_->websocket = std::move(websocket);
  const auto& o = impl_->options;
  beast::error_code ec;
  auto address = net::ip::make_address(o.host, ec);
  if (ec) {  // a name, e.g. localhost: its first address
    tcp::resolver resolver(impl_->ioc);
    const auto found = resolver.resolve(o.host, "", ec);
    if (ec || found.empty())
      throw DataError(fmt::format("--host {}: not an address or a known name ({})", o.host,
                                  ec ? ec.message() : "no address"));
    address = found.begin()->endpoint().address();
  }
  const tcp::endpoint endpoint(address, static_cast<unsigned short>(o.port));
  auto& acc = impl_->acceptor;
  acc.open(endpoint.protocol(), ec);
  if (!ec) acc.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) acc.bind(endpoint, ec);
  if (!ec) acc.listen(net::socket_base::max_listen_connections, ec);
  if (ec) throw DataError(fmt::format("cannot listen on {}:{}: {}", o.host, o.port, ec.message()));
  port_ = acc.local_endpoint().port();
  impl_->origins = {fmt::format("http://127.0.0.1:{}", port_),
                    fmt::format("http://localhost:{}", port_),
                    fmt::format("http://{}:{}", o.host, port_)};
}

HttpServer::~HttpServer() { Stop(); }

void HttpServer::Run() {
  Impl& s = *impl_;
  // The header deadline's watchdog.
  std::thread watchdog([&s] {
    while (!s.stopping) {
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
      std::lock_guard lock(s.mutex);
      s.EndWaiting(false);
      s.CancelRunning(false);
    }
  });
  while (!s.stopping) {
    beast::error_code ec;
    tcp::socket socket(s.ioc);
    s.acceptor.accept(socket, ec);
    if (s.stopping) break;
    if (ec) continue;
    const int fd = socket.native_handle();
    timeval tv{kIdleSeconds, 0};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
    {
      std::lock_guard lock(s.mutex);
      // Full: a connection that has sent no request yet makes room.
      if (s.active >= s.options.max_connections && !s.EndWaiting(true)) {
        Impl::Write(socket, ErrorResponse(503, "too many connections"), 11, false, ec);
        continue;
      }
      ++s.active;
      s.sockets.insert(fd);
      // Waiting for its header from now on, before its session's thread
      // runs: a burst of connections that send nothing can then always be
      // made room for (under load their threads may not have started yet).
      s.waiting[fd] = std::chrono::steady_clock::now();
    }
    std::thread([&s, fd, sock = std::move(socket)]() mutable {
      try {
        s.Session(std::move(sock));
      } catch (const std::exception&) {
        // a broken connection ends its session only
      }
      std::lock_guard lock(s.mutex);
      s.sockets.erase(fd);
      s.waiting.erase(fd);
      --s.active;
      s.idle.notify_all();
    }).detach();
  }
  watchdog.join();
  // Wait for the connection threads (they use `s`), at most 1 s: a request
  // still computing is abandoned (the caller ends the process).
  std::unique_lock lock(s.mutex);
  abandoned_ = !s.idle.wait_for(lock, std::chrono::seconds(1), [&] { return s.active == 0; });
}

void HttpServer::Stop() {
  Impl& s = *impl_;
  if (s.stopping.exchange(true)) return;
  {
    std::lock_guard lock(s.mutex);
    s.CancelRunning(true);
    for (int fd : s.sockets) ::shutdown(fd, SHUT_RDWR);
  }
  // Unblock accept(): shutdown on the listening socket makes it return.
  ::shutdown(s.acceptor.native_handle(), SHUT_RDWR);
}

}  // namespace pneumid::app
