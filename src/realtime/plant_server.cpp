#include "pneumid/realtime/plant_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/realtime/realtime_loop.hpp"

namespace pneumid {

namespace {
std::int64_t NowNs() noexcept {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}
}  // namespace

bool PlantServerOptions::IsValid(std::string* error) const {
  if (port < 0 || port > 65535) {
    if (error) *error = fmt::format("port must be in 0..65535, got {}", port);
    return false;
  }
  in6_addr a6;
  in_addr a4;
  if (inet_pton(AF_INET, bind_address.c_str(), &a4) != 1 &&
      inet_pton(AF_INET6, bind_address.c_str(), &a6) != 1) {
    if (error)
      *error =
          fmt::format("bind address must be a numeric IPv4/IPv6 address, got '{}'", bind_address);
    return false;
  }
  return true;
}

namespace {

// The fields of a Describe(k) reply (udp_protocol.hpp) for actuator `a`.
void DescribeActuator(const Actuator& a, std::uint32_t k, udp::Reply* rep) {
  const auto is_ipa = [&a](IpaMode mode) {
    const Actuator ipa = IpaActuator(mode);
    return a.hold_name == ipa.hold_name && a.output.unit == ipa.output.unit &&
           a.integrating == ipa.integrating;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (k == 0) {
    const udp::ActuatorKind kind = is_ipa(IpaMode::kForce)      ? udp::ActuatorKind::kIpaForce
                                   : is_ipa(IpaMode::kPosition) ? udp::ActuatorKind::kIpaPosition
                                                                : udp::ActuatorKind::kOther;
    rep->plant_time = static_cast<double>(kind);
    rep->y = a.u_min;
    rep->aux = a.u_max;
  } else if (k == 1) {
    rep->plant_time = a.integrating ? 1.0 : 0.0;
    rep->y = a.y_min;
    rep->aux = a.y_max;
  } else {
    rep->plant_time = rep->y = rep->aux = nan;
  }
}

}  // namespace

PlantServer::PlantServer(std::unique_ptr<Plant> plant, PlantServerOptions options)
    : plant_(std::move(plant)), options_(std::move(options)) {
  PNEUMID_CHECK(plant_ != nullptr, "plant server needs a plant, got null");
  std::string error;
  PNEUMID_CHECK(options_.IsValid(&error), "invalid plant-server options: {}", error);
  actuator_ = PlantActuator(*plant_);
  sockaddr_storage ss{};
  socklen_t len = 0;
  in_addr a4;
  if (inet_pton(AF_INET, options_.bind_address.c_str(), &a4) == 1) {
    auto* sa = reinterpret_cast<sockaddr_in*>(&ss);
    sa->sin_family = AF_INET;
    sa->sin_port = htons(static_cast<std::uint16_t>(options_.port));
    sa->sin_addr = a4;
    len = sizeof(sockaddr_in);
  } else {
    auto* sa = reinterpret_cast<sockaddr_in6*>(&ss);
    sa->sin6_family = AF_INET6;
    sa->sin6_port = htons(static_cast<std::uint16_t>(options_.port));
    inet_pton(AF_INET6, options_.bind_address.c_str(), &sa->sin6_addr);
    len = sizeof(sockaddr_in6);
  }
  fd_ = ::socket(ss.ss_family, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0)
    throw DataError(fmt::format("plant server: cannot create socket: {}", std::strerror(errno)));
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&ss), len) != 0) {
    const int e = errno;
    ::close(fd_);
    fd_ = -1;
    throw DataError(fmt::format("plant server: cannot bind {}:{}: {}", options_.bind_address,
                                options_.port, std::strerror(e)));
  }
  sockaddr_storage bound{};
  socklen_t blen = sizeof(bound);
  getsockname(fd_, reinterpret_cast<sockaddr*>(&bound), &blen);
  port_ = ntohs(bound.ss_family == AF_INET ? reinterpret_cast<sockaddr_in*>(&bound)->sin_port
                                           : reinterpret_cast<sockaddr_in6*>(&bound)->sin6_port);
}

PlantServer::~PlantServer() {
  if (fd_ >= 0) ::close(fd_);
}

bool PlantServer::Handle(const std::uint8_t* data, std::size_t size, udp::Packet* out) {
  udp::Request req;
  const udp::DecodeResult dr = udp::DecodeRequest(data, size, &req);
  udp::Reply rep;
  rep.Ts = plant_->Ts();
  if (dr != udp::DecodeResult::kOk) {
    ++stats_.bad_packets;
    if (dr != udp::DecodeResult::kBadVersion || size != udp::kPacketSize) return false;
    // Tell a client speaking another version why it gets no service.
    rep.status = udp::PacketStatus::kBadVersion;
    rep.sequence = 0;
    *out = udp::Encode(rep);
    return true;
  }
  ++stats_.requests;
  rep.type = req.type;
  rep.sequence = req.sequence;
  rep.client_time_ns = req.client_time_ns;
  switch (req.type) {
    case udp::PacketType::kHello:
      ++stats_.sessions;
      if (!(std::abs(req.Ts - plant_->Ts()) <= 1e-9)) {
        rep.status = udp::PacketStatus::kBadTs;
        session_ = false;
        break;
      }
      plant_->Reset();
      plant_->SetLoadDisturbance(LoadAt(options_.load_steps, plant_->time(), plant_->Ts()));
      session_ = true;
      have_last_ = false;
      break;
    case udp::PacketType::kStep:
      if (!session_) {
        rep.status = udp::PacketStatus::kNoSession;
        break;
      }
      if (have_last_ && req.sequence == last_seq_) {  // retransmission: answer again
        *out = last_reply_;
        return true;
      }
      if (options_.stop_answering_after >= 0 && stats_.steps >= options_.stop_answering_after)
        return false;
      plant_->Advance(req.u);
      plant_->SetLoadDisturbance(LoadAt(options_.load_steps, plant_->time(), plant_->Ts()));
      ++stats_.steps;
      break;
    case udp::PacketType::kSafe:
      ++stats_.safe_requests;
      stats_.last_safe_state = static_cast<int>(req.arg);
      if (options_.stop_answering_after >= 0 && stats_.steps >= options_.stop_answering_after)
        return false;
      break;
    case udp::PacketType::kBye:
      session_ = false;
      return false;
    case udp::PacketType::kInfo: {
      // The plant is not measured (that would draw its noise).
      const std::vector<InputGap>& gaps = actuator_.input_gaps;
      const std::size_t k = req.arg;
      const double nan = std::numeric_limits<double>::quiet_NaN();
      rep.plant_time = static_cast<double>(gaps.size());
      rep.y = k < gaps.size() ? gaps[k].lo : nan;
      rep.aux = k < gaps.size() ? gaps[k].hi : nan;
      rep.server_time_ns = NowNs();
      *out = udp::Encode(rep);
      return true;
    }
    case udp::PacketType::kDescribe:
      DescribeActuator(actuator_, req.arg, &rep);
      rep.server_time_ns = NowNs();
      *out = udp::Encode(rep);
      return true;
  }
  rep.server_time_ns = NowNs();
  rep.plant_time = plant_->time();
  rep.y = plant_->Measure();
  *out = udp::Encode(rep);
  if (req.type == udp::PacketType::kStep) {
    last_seq_ = req.sequence;
    last_reply_ = *out;
    have_last_ = true;
  }
  return true;
}

void PlantServer::Serve(const std::atomic<bool>& stop) {
  while (!stop.load() && StopRequestSignal() < 0) {
    pollfd p{fd_, POLLIN, 0};
    const int rc = ::poll(&p, 1, 50);
    if (rc <= 0) continue;
    udp::Packet buf{};
    std::uint8_t raw[512];
    sockaddr_storage from{};
    socklen_t flen = sizeof(from);
    const ssize_t got =
        ::recvfrom(fd_, raw, sizeof(raw), 0, reinterpret_cast<sockaddr*>(&from), &flen);
    if (got < 0) continue;
    if (Handle(raw, static_cast<std::size_t>(got), &buf))
      ::sendto(fd_, buf.data(), buf.size(), 0, reinterpret_cast<sockaddr*>(&from), flen);
  }
}

}  // namespace pneumid
