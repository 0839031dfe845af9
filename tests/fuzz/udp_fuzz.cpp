// The UDP packet decoders (realtime/udp_protocol): any datagram is decoded
// without reading outside it, and a packet that decodes re-encodes to the
// same decoded values.
#include <cstdlib>
#include <cstring>

#include "fuzz_support.hpp"
#include "pneumid/realtime/udp_protocol.hpp"

namespace {

namespace udp = pneumid::udp;

template <typename Message, typename Decode>
void RoundTrip(const std::uint8_t* data, std::size_t size, Decode decode) {
  using udp::DecodeResult;
  Message m{};
  if (decode(data, size, &m) != DecodeResult::kOk) return;
  const udp::Packet p = udp::Encode(m);
  Message again{};
  if (decode(p.data(), p.size(), &again) != DecodeResult::kOk) std::abort();
  const udp::Packet q = udp::Encode(again);
  if (std::memcmp(p.data(), q.data(), p.size()) != 0) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  RoundTrip<udp::Request>(data, size, [](const std::uint8_t* d, std::size_t n, udp::Request* r) {
    return udp::DecodeRequest(d, n, r);
  });
  RoundTrip<udp::Reply>(data, size, [](const std::uint8_t* d, std::size_t n, udp::Reply* r) {
    return udp::DecodeReply(d, n, r);
  });
  return 0;
}
