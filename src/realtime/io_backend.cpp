#include "pneumid/realtime/io_backend.hpp"

#include <cstdlib>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"

namespace pneumid {

namespace {
constexpr EnumName<IoKind> kIoKindNames[] = {
    {IoKind::kSim, "sim"},
    {IoKind::kComedi, "comedi"},
    {IoKind::kUdp, "udp"},
};
}  // namespace

const char* ToString(IoKind v) { return EnumToString(kIoKindNames, v).data(); }

std::string IoSpec::ToString() const {
  switch (kind) {
    case IoKind::kSim:
      return "sim";
    case IoKind::kComedi:
      return "comedi:" + device;
    case IoKind::kUdp:
      return fmt::format("udp://{}:{}", host, port);
  }
  return "unknown";
}

IoSpec ParseIoSpec(const std::string& spec) {
  IoSpec s;
  if (spec == "sim") {
    s.kind = IoKind::kSim;
    return s;
  }
  if (spec == "comedi" || spec.rfind("comedi:", 0) == 0) {
    s.kind = IoKind::kComedi;
    if (spec.size() > 7) s.device = spec.substr(7);
    PNEUMID_CHECK(!s.device.empty() && s.device[0] == '/',
                  "--io '{}': comedi device must be an absolute path such as /dev/comedi0", spec);
    return s;
  }
  if (spec.rfind("udp://", 0) == 0) {
    s.kind = IoKind::kUdp;
    const std::string rest = spec.substr(6);
    const auto colon = rest.rfind(':');
    PNEUMID_CHECK(colon != std::string::npos && colon > 0 && colon + 1 < rest.size(),
                  "--io '{}': expected udp://HOST:PORT", spec);
    s.host = rest.substr(0, colon);
    if (s.host.size() > 2 && s.host.front() == '[' && s.host.back() == ']')
      s.host = s.host.substr(1, s.host.size() - 2);
    const std::string port = rest.substr(colon + 1);
    char* end = nullptr;
    const long p = std::strtol(port.c_str(), &end, 10);
    PNEUMID_CHECK(end && *end == '\0' && p >= 1 && p <= 65535,
                  "--io '{}': port must be an integer in 1..65535, got '{}'", spec, port);
    s.port = static_cast<int>(p);
    return s;
  }
  throw InvalidArgument(fmt::format(
      "--io '{}': unknown backend (expected sim, comedi:/dev/comediN or udp://HOST:PORT)", spec));
}

}  // namespace pneumid
