// Datagram protocol between the real-time loop (client) and a plant server
// (`pneumid plant-server`), version 1. Documented in docs/realtime.md.
//
// Every datagram is exactly 64 bytes, all fields little-endian, no padding:
//
//   Request (client -> server)             Reply (server -> client)
//   off size field                          off size field
//    0   4   magic 0x444D4E50 ("PNMD")       0   4   magic
//    4   2   version = 1                      4   2   version
//    6   2   type (Hello, Step, Safe, Bye,    6   2   type | 0x80
//            Info, Describe)
//    8   4   sequence                         8   4   sequence (echoed)
//   12   4   arg (safe state for Safe,       12   4   status (PacketStatus)
//            gap index for Info, field
//            index for Describe)
//   16   8   client time, ns (int64)         16   8   client time (echoed)
//   24   8   u, duty % (float64)             24   8   server time, ns (int64, monotonic)
//   32   8   Ts, s (Hello) (float64)         32   8   plant time, s (float64)
//   40  24   reserved, zero                  40   8   y, measured output (float64)
//                                            48   8   aux (pressure, Pa, or NaN)
//                                            56   8   the server plant's Ts, s (float64;
//                                                      0 from servers that do not say)
//
// Semantics (one exchange per period):
//   Hello(Ts)  -> the server resets its plant and replies y_0 (status BadTs when the
//                 plant's sample time differs from Ts; the reply's Ts says which it is).
//   Step(u_k)  -> the server holds u_k for one period (Plant::Advance) and replies
//                 y_(k+1); a repeated sequence number is answered again, not re-applied.
//   Safe(s)    -> the server drives its plant's outputs to safe state s and replies.
//   Bye        -> the session ends (the server keeps serving new Hellos).
//   Info(k)    -> the inputs the server plant's actuator cannot hold (its input
//                 gaps, plant/actuator.hpp: a PWM valve's minimum pulse, IPA
//                 duties 0..15 and 85..100 % at 300 Hz): the reply's plant time
//                 field holds their number n, y and aux the low and high end of
//                 gap k (NaN for k >= n). The plant is not touched, and no
//                 session is needed. Servers older than this message do not
//                 answer it (the client then knows no gaps).
//   Describe(k) -> the server plant's actuator (plant/actuator.hpp), without
//                 touching the plant: k = 0: plant time = its kind
//                 (ActuatorKind), y and aux = the input range u_min, u_max;
//                 k = 1: plant time = 1 when the output integrates the input
//                 (a positioning drive), else 0, y and aux = the output range
//                 y_min, y_max (infinite = unbounded); k >= 2: NaN. Servers
//                 older than this message do not answer it (the client then
//                 takes the IPA in force mode, as before).
#pragma once

#include <array>
#include <cstdint>
#include <limits>

namespace pneumid::udp {

inline constexpr std::uint32_t kMagic = 0x444D4E50u;  ///< first field; bytes "PNMD" on the wire
inline constexpr std::uint16_t kVersion = 1;          ///< protocol version written and accepted
inline constexpr std::size_t kPacketSize = 64;        ///< bytes of every datagram
inline constexpr std::uint16_t kReplyBit = 0x80;      ///< set in the type field of a reply

/// Kind of exchange (semantics above).
enum class PacketType : std::uint16_t {
  kHello = 1,
  kStep = 2,
  kSafe = 3,
  kBye = 4,
  kInfo = 5,
  kDescribe = 6
};
/// What a Describe(0) reply names the server plant's actuator: the words and
/// safe states of IpaActuator(mode) for the IPA, the generic ones otherwise.
enum class ActuatorKind : std::uint32_t { kOther = 0, kIpaForce = 1, kIpaPosition = 2 };
/// Server's verdict on a request, in the reply.
enum class PacketStatus : std::uint32_t {
  kOk = 0,
  kBadVersion = 1,
  kBadType = 2,
  kBadTs = 3,
  kNoSession = 4,  ///< Step before Hello
};
/// "ok", "bad-version", "bad-type", "bad-Ts", "no-session".
const char* ToString(PacketStatus s);

/// One datagram as sent on the wire (layout above).
using Packet = std::array<std::uint8_t, kPacketSize>;

/// A client -> server datagram, decoded.
struct Request {
  PacketType type = PacketType::kStep;  ///< Hello, Step, Safe, Bye, Info or Describe
  std::uint32_t sequence = 0;           ///< request number; a repeated Step is not re-applied
  std::uint32_t arg = 0;  ///< SafeState for Safe, gap index for Info, field for Describe, else 0
  std::int64_t client_time_ns = 0;  ///< client's monotonic clock at sending, ns (echoed)
  double u = 0.0;                   ///< input to hold for one period (Step), duty %
  double Ts = 0.0;                  ///< client's sample period (Hello), s
};

/// A server -> client datagram, decoded.
struct Reply {
  PacketType type = PacketType::kStep;      ///< type of the request answered
  std::uint32_t sequence = 0;               ///< sequence of the request answered
  PacketStatus status = PacketStatus::kOk;  ///< kOk, or why the request was refused
  std::int64_t client_time_ns = 0;          ///< the request's client time (round-trip time)
  std::int64_t server_time_ns = 0;          ///< server's monotonic clock at replying, ns
  double plant_time = 0.0;  ///< plant time after the request, s (Info: gaps; Describe: above)
  double y = 0.0;           ///< measured output (IPA: force N; Info: gap's low end)
  /// Chamber pressure, Pa, or NaN (Info: the gap's high end).
  double aux = std::numeric_limits<double>::quiet_NaN();
  double Ts = 0.0;  ///< the server plant's sample time, s (0: not told)
};

/// Result of decoding a datagram.
enum class DecodeResult {
  kOk,
  kWrongSize,
  kBadMagic,
  kBadVersion,
  kBadType,
  kNotReply,
  kNotRequest
};
/// "ok", "wrong size", "bad magic", "unsupported version", "unknown type", "not a reply",
/// "not a request".
const char* ToString(DecodeResult r);

/// Serialization (allocation-free, usable on the loop thread).
Packet Encode(const Request& r) noexcept;
Packet Encode(const Reply& r) noexcept;  ///< sets kReplyBit in the type field
/// Decodes `size` bytes at `data`.
DecodeResult DecodeRequest(const std::uint8_t* data, std::size_t size, Request* out) noexcept;
/// Decodes a reply (`size` bytes at `data`); *out is written only when kOk.
DecodeResult DecodeReply(const std::uint8_t* data, std::size_t size, Reply* out) noexcept;

}  // namespace pneumid::udp
