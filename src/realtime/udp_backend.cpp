#include "pneumid/realtime/udp_backend.hpp"

#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"

namespace pneumid {

namespace {
std::int64_t NowNs() noexcept {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

// Waits until fd is readable or wait_ns elapsed; true when readable.
bool WaitReadable(int fd, std::int64_t wait_ns) noexcept {
  pollfd p{fd, POLLIN, 0};
  timespec ts{static_cast<time_t>(wait_ns / 1000000000), static_cast<long>(wait_ns % 1000000000)};
  const int rc = ppoll(&p, 1, &ts, nullptr);
  return rc > 0 && (p.revents & POLLIN);
}
}  // namespace

bool UdpBackendOptions::IsValid(std::string* error) const {
  auto fail = [error](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (host.empty()) return fail("udp host must not be empty");
  if (port < 1 || port > 65535)
    return fail(fmt::format("udp port must be in 1..65535, got {}", port));
  if (max_missed < 1) return fail(fmt::format("max_missed must be >= 1, got {}", max_missed));
  if (!(reply_wait >= 0.0 && reply_wait <= 0.9))
    return fail(fmt::format("reply_wait must be in [0, 0.9] periods, got {}", reply_wait));
  if (!(hello_timeout > 0.0 && hello_timeout <= 60.0))
    return fail(fmt::format("hello_timeout must be in (0, 60] s, got {}", hello_timeout));
  if (hello_attempts < 1)
    return fail(fmt::format("hello_attempts must be >= 1, got {}", hello_attempts));
  return true;
}

UdpBackend::UdpBackend(UdpBackendOptions options) : options_(std::move(options)) {
  std::string error;
  PNEUMID_CHECK(options_.IsValid(&error), "invalid udp options: {}", error);
}

UdpBackend::~UdpBackend() {
  if (fd_ >= 0) ::close(fd_);
}

std::string UdpBackend::Describe() const {
  return fmt::format("udp://{}:{} (protocol v{})", options_.host, options_.port, udp::kVersion);
}

void UdpBackend::Open(double period) {
  PNEUMID_CHECK(period > 0.0, "period must be positive, got {}", period);
  period_ = period;
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* res = nullptr;
  const std::string port = std::to_string(options_.port);
  const int gai = getaddrinfo(options_.host.c_str(), port.c_str(), &hints, &res);
  if (gai != 0)
    throw DataError(fmt::format("udp://{}:{}: cannot resolve host: {}", options_.host,
                                options_.port, gai_strerror(gai)));
  for (addrinfo* a = res; a; a = a->ai_next) {
    fd_ = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd_ < 0) continue;
    if (::connect(fd_, a->ai_addr, a->ai_addrlen) == 0) break;
    ::close(fd_);
    fd_ = -1;
  }
  freeaddrinfo(res);
  if (fd_ < 0)
    throw DataError(fmt::format("udp://{}:{}: cannot open socket: {}", options_.host, options_.port,
                                std::strerror(errno)));
  // Hello: reset the remote plant and get y_0.
  adopted_period_ = std::numeric_limits<double>::quiet_NaN();
  input_gaps_.clear();
  described_.reset();
  for (int attempt = 0; attempt < options_.hello_attempts; ++attempt) {
    udp::Request req;
    req.type = udp::PacketType::kHello;
    req.sequence = ++seq_;
    req.client_time_ns = NowNs();
    req.Ts = period;
    const udp::Packet p = udp::Encode(req);
    ::send(fd_, p.data(), p.size(), 0);  // failures show up as no answer
    udp::Reply rep;
    if (!AwaitReply(udp::PacketType::kHello, req.sequence, options_.hello_timeout, &rep)) {
      if (attempt + 1 < options_.hello_attempts) ::usleep(100000);
      continue;
    }
    if (rep.status == udp::PacketStatus::kBadTs && rep.Ts > 0.0 && options_.adopt_server_period &&
        !std::isfinite(adopted_period_)) {
      // Ask again at the server's period (once; this attempt does not count).
      period = period_ = adopted_period_ = rep.Ts;
      --attempt;
      continue;
    }
    if (rep.status == udp::PacketStatus::kBadTs && rep.Ts > 0.0)
      throw DataError(fmt::format(
          "udp://{}:{}: plant server refused the session: its plant runs at Ts = {:.17g} s, "
          "not {:.17g} s: give that period (--Ts {:.17g}) or start the server with --Ts {:.17g}",
          options_.host, options_.port, rep.Ts, period, rep.Ts, period));
    if (rep.status != udp::PacketStatus::kOk)
      throw DataError(fmt::format("udp://{}:{}: plant server refused the session: {} (period {} s)",
                                  options_.host, options_.port, udp::ToString(rep.status), period));
    last_y_ = rep.y;
    last_aux_ = rep.aux;
    input_gaps_ = AskInputGaps();
    described_ = AskActuator();
    have_reply_ = true;
    expect_seq_ = req.sequence;
    missed_ = 0;
    stale_total_ = 0;
    return;
  }
  ::close(fd_);
  fd_ = -1;
  throw DataError(fmt::format(
      "udp://{}:{}: no answer from a plant server after {} attempts of {} s (is `pneumid "
      "plant-server --port {}` running?)",
      options_.host, options_.port, options_.hello_attempts, options_.hello_timeout,
      options_.port));
}

bool UdpBackend::AwaitReply(udp::PacketType type, std::uint32_t sequence, double timeout,
                            udp::Reply* reply) {
  const std::int64_t until = NowNs() + static_cast<std::int64_t>(timeout * 1e9);
  for (std::int64_t now = NowNs(); now < until; now = NowNs()) {
    if (!WaitReadable(fd_, until - now)) return false;
    udp::Packet buf;
    const ssize_t got = ::recv(fd_, buf.data(), buf.size(), 0);
    if (got < 0) {
      if (errno == ECONNREFUSED) return false;  // nobody listening (yet)
      continue;
    }
    if (udp::DecodeReply(buf.data(), static_cast<std::size_t>(got), reply) ==
            udp::DecodeResult::kOk &&
        reply->type == type && reply->sequence == sequence)
      return true;
  }
  return false;
}

bool UdpBackend::AskServer(udp::PacketType type, std::uint32_t arg, udp::Reply* reply) {
  udp::Request req;
  req.type = type;
  req.sequence = ++seq_;
  req.arg = arg;
  req.client_time_ns = NowNs();
  const udp::Packet p = udp::Encode(req);
  ::send(fd_, p.data(), p.size(), 0);
  return AwaitReply(type, req.sequence, 0.2, reply) && reply->status == udp::PacketStatus::kOk;
}

std::vector<InputGap> UdpBackend::AskInputGaps() {
  // A gap of the IPA's duty is a few % wide; a server telling more than a few
  // gaps, or ends out of order, is not believed.
  constexpr std::uint32_t kMaxGaps = 16;
  std::vector<InputGap> gaps;
  for (std::uint32_t k = 0; k < kMaxGaps; ++k) {
    udp::Reply rep;
    if (!AskServer(udp::PacketType::kInfo, k, &rep)) return {};  // a server before Info
    const double n = rep.plant_time;
    if (!(n >= 0.0 && n <= kMaxGaps) || n != std::floor(n)) return {};
    if (k >= static_cast<std::uint32_t>(n)) break;
    if (!(std::isfinite(rep.y) && std::isfinite(rep.aux) && rep.y < rep.aux)) return {};
    gaps.push_back({rep.y, rep.aux});
  }
  return gaps;
}

std::optional<Actuator> UdpBackend::AskActuator() {
  udp::Reply field[2];
  for (std::uint32_t k = 0; k < 2; ++k)
    if (!AskServer(udp::PacketType::kDescribe, k, &field[k]))
      return std::nullopt;  // a server before Describe
  const double kind = field[0].plant_time, integrating = field[1].plant_time;
  Actuator a;
  if (kind == static_cast<double>(udp::ActuatorKind::kIpaForce))
    a = IpaActuator(IpaMode::kForce);
  else if (kind == static_cast<double>(udp::ActuatorKind::kIpaPosition))
    a = IpaActuator(IpaMode::kPosition);
  else if (kind != static_cast<double>(udp::ActuatorKind::kOther))
    return std::nullopt;
  // Ranges: ordered, not NaN (infinite ends are unbounded).
  const auto range = [](const udp::Reply& r) { return r.y < r.aux; };
  if (!range(field[0]) || !range(field[1]) || !(integrating == 0.0 || integrating == 1.0))
    return std::nullopt;
  a.u_min = field[0].y;
  a.u_max = field[0].aux;
  a.y_min = field[1].y;
  a.y_max = field[1].aux;
  a.integrating = integrating == 1.0;
  return a;
}

Actuator UdpBackend::actuator() const {
  Actuator a = described_ ? *described_ : IpaActuator();
  a.input_gaps = input_gaps_;
  return a;
}

bool UdpBackend::Collect(std::int64_t wait_ns) noexcept {
  const std::int64_t until = NowNs() + wait_ns;
  for (;;) {
    udp::Packet buf;
    const ssize_t got = ::recv(fd_, buf.data(), buf.size(), MSG_DONTWAIT);
    if (got >= 0) {
      udp::Reply rep;
      if (udp::DecodeReply(buf.data(), static_cast<std::size_t>(got), &rep) ==
              udp::DecodeResult::kOk &&
          rep.sequence == expect_seq_ && !have_reply_) {
        have_reply_ = true;
        bad_status_ = rep.status != udp::PacketStatus::kOk;
        last_y_ = rep.y;
        last_aux_ = rep.aux;
        last_rtt_us_ = static_cast<double>(NowNs() - rep.client_time_ns) * 1e-3;
      }
      continue;  // drain older/duplicate replies too
    }
    if (have_reply_) return true;
    // EAGAIN: nothing queued; ECONNREFUSED: nobody listening (treated as no answer).
    const std::int64_t now = NowNs();
    if (now >= until) return false;
    if (!WaitReadable(fd_, until - now)) return have_reply_;
  }
}

IoStatus UdpBackend::Read(Measurement* m) noexcept {
  if (fd_ < 0) return IoStatus::kError;
  const bool fresh =
      have_reply_ || Collect(static_cast<std::int64_t>(options_.reply_wait * period_ * 1e9));
  m->y = last_y_;
  m->aux = last_aux_;
  if (fresh) {
    missed_ = 0;
    return bad_status_ ? IoStatus::kError : IoStatus::kOk;
  }
  ++stale_total_;
  if (++missed_ >= options_.max_missed) return IoStatus::kTimeout;
  return IoStatus::kStale;
}

IoStatus UdpBackend::Write(double u) noexcept {
  if (fd_ < 0) return IoStatus::kError;
  udp::Request req;
  req.type = udp::PacketType::kStep;
  req.sequence = ++seq_;
  req.client_time_ns = NowNs();
  req.u = u;
  const udp::Packet p = udp::Encode(req);
  expect_seq_ = req.sequence;
  have_reply_ = false;
  const ssize_t sent = ::send(fd_, p.data(), p.size(), MSG_DONTWAIT);
  if (sent == static_cast<ssize_t>(p.size())) return IoStatus::kOk;
  // A refused or full socket is a missing reply for the next Read, not an error yet.
  if (sent < 0 && (errno == ECONNREFUSED || errno == EAGAIN || errno == EWOULDBLOCK))
    return IoStatus::kOk;
  return IoStatus::kError;
}

IoStatus UdpBackend::EnterSafeState(SafeState state) noexcept {
  if (fd_ < 0) return IoStatus::kError;
  udp::Request req;
  req.type = udp::PacketType::kSafe;
  req.sequence = ++seq_;
  req.arg = static_cast<std::uint32_t>(state);
  req.client_time_ns = NowNs();
  const udp::Packet p = udp::Encode(req);
  expect_seq_ = req.sequence;
  have_reply_ = false;
  ::send(fd_, p.data(), p.size(), MSG_DONTWAIT);
  const auto wait = static_cast<std::int64_t>(std::max(period_, 0.02) * 1e9);
  return Collect(wait) ? IoStatus::kOk : IoStatus::kTimeout;
}

void UdpBackend::Close() {
  if (fd_ < 0) return;
  udp::Request req;
  req.type = udp::PacketType::kBye;
  req.sequence = ++seq_;
  req.client_time_ns = NowNs();
  const udp::Packet p = udp::Encode(req);
  ::send(fd_, p.data(), p.size(), MSG_DONTWAIT);
  ::close(fd_);
  fd_ = -1;
}

}  // namespace pneumid
