#include "pneumid/realtime/udp_protocol.hpp"

#include "pneumid/common/enum_names.hpp"

#include <cstring>

namespace pneumid::udp {

namespace {

template <typename T>
void Put(Packet& p, std::size_t off, T v) noexcept {
  std::uint64_t bits = 0;
  static_assert(sizeof(T) <= 8);
  std::memcpy(&bits, &v, sizeof(T));
  for (std::size_t i = 0; i < sizeof(T); ++i)
    p[off + i] = static_cast<std::uint8_t>(bits >> (8 * i));
}

template <typename T>
T Get(const std::uint8_t* d, std::size_t off) noexcept {
  std::uint64_t bits = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i)
    bits |= static_cast<std::uint64_t>(d[off + i]) << (8 * i);
  T v;
  std::memcpy(&v, &bits, sizeof(T));
  return v;
}

bool KnownType(std::uint16_t t) noexcept { return t >= 1 && t <= 6; }

DecodeResult Header(const std::uint8_t* d, std::size_t size, bool reply,
                    PacketType* type) noexcept {
  if (size != kPacketSize) return DecodeResult::kWrongSize;
  if (Get<std::uint32_t>(d, 0) != kMagic) return DecodeResult::kBadMagic;
  if (Get<std::uint16_t>(d, 4) != kVersion) return DecodeResult::kBadVersion;
  std::uint16_t t = Get<std::uint16_t>(d, 6);
  const bool is_reply = (t & kReplyBit) != 0;
  if (reply && !is_reply) return DecodeResult::kNotReply;
  if (!reply && is_reply) return DecodeResult::kNotRequest;
  t = static_cast<std::uint16_t>(t & ~kReplyBit);
  if (!KnownType(t)) return DecodeResult::kBadType;
  *type = static_cast<PacketType>(t);
  return DecodeResult::kOk;
}

}  // namespace

namespace {
constexpr EnumName<PacketStatus> kPacketStatusNames[] = {
    {PacketStatus::kOk, "ok"},
    {PacketStatus::kBadVersion, "bad-version"},
    {PacketStatus::kBadType, "bad-type"},
    {PacketStatus::kBadTs, "bad-Ts"},
    {PacketStatus::kNoSession, "no-session"},
};
constexpr EnumName<DecodeResult> kDecodeResultNames[] = {
    {DecodeResult::kOk, "ok"},
    {DecodeResult::kWrongSize, "wrong size"},
    {DecodeResult::kBadMagic, "bad magic"},
    {DecodeResult::kBadVersion, "unsupported version"},
    {DecodeResult::kBadType, "unknown type"},
    {DecodeResult::kNotReply, "not a reply"},
    {DecodeResult::kNotRequest, "not a request"},
};
}  // namespace

const char* ToString(PacketStatus s) { return EnumToString(kPacketStatusNames, s).data(); }

const char* ToString(DecodeResult r) { return EnumToString(kDecodeResultNames, r).data(); }

Packet Encode(const Request& r) noexcept {
  Packet p{};
  Put(p, 0, kMagic);
  Put(p, 4, kVersion);
  Put(p, 6, static_cast<std::uint16_t>(r.type));
  Put(p, 8, r.sequence);
  Put(p, 12, r.arg);
  Put(p, 16, r.client_time_ns);
  Put(p, 24, r.u);
  Put(p, 32, r.Ts);
  return p;
}

Packet Encode(const Reply& r) noexcept {
  Packet p{};
  Put(p, 0, kMagic);
  Put(p, 4, kVersion);
  Put(p, 6, static_cast<std::uint16_t>(static_cast<std::uint16_t>(r.type) | kReplyBit));
  Put(p, 8, r.sequence);
  Put(p, 12, static_cast<std::uint32_t>(r.status));
  Put(p, 16, r.client_time_ns);
  Put(p, 24, r.server_time_ns);
  Put(p, 32, r.plant_time);
  Put(p, 40, r.y);
  Put(p, 48, r.aux);
  Put(p, 56, r.Ts);
  return p;
}

DecodeResult DecodeRequest(const std::uint8_t* d, std::size_t size, Request* out) noexcept {
  PacketType type;
  const DecodeResult h = Header(d, size, false, &type);
  if (h != DecodeResult::kOk) return h;
  out->type = type;
  out->sequence = Get<std::uint32_t>(d, 8);
  out->arg = Get<std::uint32_t>(d, 12);
  out->client_time_ns = Get<std::int64_t>(d, 16);
  out->u = Get<double>(d, 24);
  out->Ts = Get<double>(d, 32);
  return DecodeResult::kOk;
}

DecodeResult DecodeReply(const std::uint8_t* d, std::size_t size, Reply* out) noexcept {
  PacketType type;
  const DecodeResult h = Header(d, size, true, &type);
  if (h != DecodeResult::kOk) return h;
  out->type = type;
  out->sequence = Get<std::uint32_t>(d, 8);
  out->status = static_cast<PacketStatus>(Get<std::uint32_t>(d, 12));
  out->client_time_ns = Get<std::int64_t>(d, 16);
  out->server_time_ns = Get<std::int64_t>(d, 24);
  out->plant_time = Get<double>(d, 32);
  out->y = Get<double>(d, 40);
  out->aux = Get<double>(d, 48);
  out->Ts = Get<double>(d, 56);
  return DecodeResult::kOk;
}

}  // namespace pneumid::udp
