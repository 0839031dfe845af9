// UDP backend (client side of the plant-server protocol, udp_protocol.hpp).
//
// Per period: Read() collects the reply to the previous Step (y_k) without
// blocking longer than reply_wait; Write(u_k) sends the next Step and returns
// at once. A reply that has not arrived gives a stale sample (the last value is
// repeated and flagged); max_missed consecutive stale samples give
// IoStatus::kTimeout, so a server that stops answering is detected within
// max_missed periods.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "pneumid/realtime/io_backend.hpp"
#include "pneumid/realtime/udp_protocol.hpp"

namespace pneumid {

/// Server address and timeouts of a UdpBackend.
struct UdpBackendOptions {
  std::string host = "127.0.0.1";  ///< plant server host name or address (not empty)
  int port = 5000;                 ///< plant server UDP port, 1..65535
  int max_missed = 3;              ///< consecutive missing replies before a timeout fault (>= 1)
  double reply_wait = 0.25;        ///< fraction of the period Read() may wait for a late reply
  double hello_timeout = 1.0;      ///< s to wait for the server's answer to Hello (per attempt)
  int hello_attempts = 3;          ///< Hello requests sent before Open() gives up (>= 1)
  /// When the server's plant runs at another period than the one Open() asks
  /// for, take the server's (adopted_period()) instead of refusing: for a
  /// command whose period was not given (the loop then runs at the plant's).
  bool adopt_server_period = false;
  /// True for a non-empty host, port 1..65535, max_missed >= 1, reply_wait in [0, 0.9],
  /// hello_timeout in (0, 60] s and hello_attempts >= 1; otherwise false with the reason
  /// in *error (when not null).
  bool IsValid(std::string* error) const;
};

/// IoBackend talking to a plant server over UDP, one Step exchange per period (see above).
class UdpBackend : public IoBackend {
 public:
  /// @throws InvalidArgument on invalid options.
  explicit UdpBackend(UdpBackendOptions options);
  ~UdpBackend() override;
  /// Resolves the host, connects and sends Hello(period) (again with the
  /// server's period when it differs and adopt_server_period is set), then
  /// asks the server for its plant's input gaps (Info; none from a server
  /// that does not answer it within 0.2 s) and its actuator (Describe: input
  /// and output ranges, whether it integrates, the IPA's mode).
  /// @throws DataError when the host cannot be resolved, the server does not answer,
  /// or it rejects the period.
  void Open(double period) override;
  /// The server's period when Open() adopted it, else NaN.
  double adopted_period() const override { return adopted_period_; }
  IoStatus Read(Measurement* m) noexcept override;
  IoStatus Write(double u) noexcept override;
  /// Sends Safe(state) and waits up to one period (at least 20 ms) for the answer.
  IoStatus EnterSafeState(SafeState state) noexcept override;
  void Close() override;
  std::string Describe() const override;
  /// The actuator the server described at Open() (Describe: the IPA in force
  /// or position mode, or a generic plant with its input and output ranges),
  /// with the input gaps it told; IpaActuator() in force mode from a server
  /// that does not describe it (one older than Describe).
  Actuator actuator() const override;
  /// The input gaps the server told at Open() (empty: none, or not told).
  const std::vector<InputGap>& input_gaps() const { return input_gaps_; }

  /// Periods whose reply had not arrived in time (last value repeated) since Open().
  std::int64_t stale_samples() const { return stale_total_; }
  /// Round-trip time of the last reply (us).
  double last_rtt_us() const { return last_rtt_us_; }

 private:
  // Receives pending replies; returns true when the one for `expect_seq_` arrived.
  bool Collect(std::int64_t wait_ns) noexcept;
  // One request about the server's plant (Info, Describe), answered within
  // 0.2 s with status ok; false otherwise (a server older than it).
  bool AskServer(udp::PacketType type, std::uint32_t arg, udp::Reply* reply);
  // Info requests: the server plant's input gaps (empty when it does not say).
  std::vector<InputGap> AskInputGaps();
  // Describe requests: the server plant's actuator, without its gaps (nullopt
  // when it does not say or says something inconsistent).
  std::optional<Actuator> AskActuator();
  // Waits up to `timeout` s for the reply of `type` to `sequence`; false on none.
  bool AwaitReply(udp::PacketType type, std::uint32_t sequence, double timeout, udp::Reply* reply);

  UdpBackendOptions options_;
  int fd_ = -1;
  double period_ = 0.01;
  double adopted_period_ = std::numeric_limits<double>::quiet_NaN();
  std::vector<InputGap> input_gaps_;
  std::optional<Actuator> described_;  // by Describe at Open()
  std::uint32_t seq_ = 0;
  std::uint32_t expect_seq_ = 0;
  bool have_reply_ = false;  // reply for expect_seq_ received
  bool bad_status_ = false;
  double last_y_ = 0.0;
  double last_aux_ = 0.0;
  int missed_ = 0;
  std::int64_t stale_total_ = 0;
  double last_rtt_us_ = 0.0;
};

}  // namespace pneumid
