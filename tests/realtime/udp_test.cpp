// The plant-server protocol: byte layout, decoding of bad datagrams, and a
// closed loop through a plant server on 127.0.0.1 replayed sample by sample
// offline (late replies included, as stale samples); a server that stops
// answering is detected within max_missed periods.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/realtime/io_plant.hpp"
#include "pneumid/realtime/plant_server.hpp"
#include "pneumid/realtime/realtime_loop.hpp"
#include "pneumid/realtime/udp_backend.hpp"
#include "pneumid/realtime/udp_protocol.hpp"
#include "test_support.hpp"

namespace pneumid {
namespace {

using testing::CountingPi;
using testing::FirstOrderPlant;
using ::testing::HasSubstr;

TEST(UdpProtocol, RequestLayoutIsLittleEndianAtTheDocumentedOffsets) {
  udp::Request r;
  r.type = udp::PacketType::kStep;
  r.sequence = 0x01020304;
  r.arg = 7;
  r.client_time_ns = 0x1122334455667788LL;
  r.u = 1.5;  // 0x3FF8000000000000
  r.Ts = 0.01;
  const udp::Packet p = udp::Encode(r);
  EXPECT_EQ(p[0], 'P');
  EXPECT_EQ(p[1], 'N');
  EXPECT_EQ(p[2], 'M');
  EXPECT_EQ(p[3], 'D');
  EXPECT_EQ(p[4], 1);  // version 1
  EXPECT_EQ(p[5], 0);
  EXPECT_EQ(p[6], 2);  // Step
  EXPECT_EQ(p[8], 0x04);
  EXPECT_EQ(p[11], 0x01);
  EXPECT_EQ(p[12], 7);
  EXPECT_EQ(p[16], 0x88);
  EXPECT_EQ(p[23], 0x11);
  EXPECT_EQ(p[30], 0xF8);
  EXPECT_EQ(p[31], 0x3F);
  for (std::size_t i = 40; i < 64; ++i) EXPECT_EQ(p[i], 0) << i;
  udp::Request back;
  ASSERT_EQ(udp::DecodeRequest(p.data(), p.size(), &back), udp::DecodeResult::kOk);
  EXPECT_EQ(back.sequence, r.sequence);
  EXPECT_EQ(back.client_time_ns, r.client_time_ns);
  EXPECT_EQ(back.u, 1.5);
  EXPECT_EQ(back.Ts, 0.01);
}

TEST(UdpProtocol, ReplyRoundTripAndRejections) {
  udp::Reply r;
  r.type = udp::PacketType::kHello;
  r.sequence = 9;
  r.status = udp::PacketStatus::kBadTs;
  r.server_time_ns = 123456789;
  r.plant_time = 2.5;
  r.y = -12.25;
  r.Ts = 1.0 / 300.0;
  const udp::Packet p = udp::Encode(r);
  double at56 = 0.0;
  std::memcpy(&at56, p.data() + 56, 8);  // offset 56: the server plant's Ts
  EXPECT_EQ(at56, 1.0 / 300.0);
  EXPECT_EQ(p[6], 0x81);  // Hello | reply bit
  udp::Reply back;
  ASSERT_EQ(udp::DecodeReply(p.data(), p.size(), &back), udp::DecodeResult::kOk);
  EXPECT_EQ(back.status, udp::PacketStatus::kBadTs);
  EXPECT_EQ(back.y, -12.25);
  EXPECT_TRUE(std::isnan(back.aux));
  EXPECT_EQ(back.Ts, 1.0 / 300.0);
  udp::Request req;
  EXPECT_EQ(udp::DecodeRequest(p.data(), p.size(), &req), udp::DecodeResult::kNotRequest);
  EXPECT_EQ(udp::DecodeReply(p.data(), 63, &back), udp::DecodeResult::kWrongSize);
  udp::Packet bad = p;
  bad[0] = 'X';
  EXPECT_EQ(udp::DecodeReply(bad.data(), bad.size(), &back), udp::DecodeResult::kBadMagic);
  bad = p;
  bad[4] = 2;
  EXPECT_EQ(udp::DecodeReply(bad.data(), bad.size(), &back), udp::DecodeResult::kBadVersion);
  bad = p;
  bad[6] = 0x87;  // type 7: unknown (1..6 are Hello, Step, Safe, Bye, Info, Describe)
  EXPECT_EQ(udp::DecodeReply(bad.data(), bad.size(), &back), udp::DecodeResult::kBadType);
}

TEST(PlantServer, HandlesHelloStepRetransmissionAndBadPeriod) {
  PlantServerOptions o;
  o.port = 0;
  PlantServer server(std::make_unique<FirstOrderPlant>(0.01, 0.5, 1.0), o);
  EXPECT_GT(server.port(), 0);
  udp::Packet out;
  udp::Reply rep;
  udp::Request step;
  step.type = udp::PacketType::kStep;
  step.sequence = 1;
  step.u = 2.0;
  udp::Packet p = udp::Encode(step);
  ASSERT_TRUE(server.Handle(p.data(), p.size(), &out));
  udp::DecodeReply(out.data(), out.size(), &rep);
  EXPECT_EQ(rep.status, udp::PacketStatus::kNoSession);

  udp::Request hello;
  hello.type = udp::PacketType::kHello;
  hello.Ts = 0.02;
  p = udp::Encode(hello);
  ASSERT_TRUE(server.Handle(p.data(), p.size(), &out));
  udp::DecodeReply(out.data(), out.size(), &rep);
  EXPECT_EQ(rep.status, udp::PacketStatus::kBadTs);
  EXPECT_EQ(rep.Ts, 0.01);  // the period the server's plant runs at
  hello.Ts = 0.01;
  p = udp::Encode(hello);
  ASSERT_TRUE(server.Handle(p.data(), p.size(), &out));
  udp::DecodeReply(out.data(), out.size(), &rep);
  EXPECT_EQ(rep.status, udp::PacketStatus::kOk);
  EXPECT_EQ(rep.y, 0.0);

  p = udp::Encode(step);
  ASSERT_TRUE(server.Handle(p.data(), p.size(), &out));
  udp::DecodeReply(out.data(), out.size(), &rep);
  EXPECT_EQ(rep.y, 2.0);                                 // y1 = 0.5 * 0 + 1.0 * 2
  ASSERT_TRUE(server.Handle(p.data(), p.size(), &out));  // same sequence: not applied again
  udp::DecodeReply(out.data(), out.size(), &rep);
  EXPECT_EQ(rep.y, 2.0);
  step.sequence = 2;
  p = udp::Encode(step);
  ASSERT_TRUE(server.Handle(p.data(), p.size(), &out));
  udp::DecodeReply(out.data(), out.size(), &rep);
  EXPECT_EQ(rep.y, 3.0);  // 0.5 * 2 + 2
  EXPECT_DOUBLE_EQ(rep.plant_time, 0.02);
  EXPECT_FALSE(server.Handle(p.data(), 10, &out));
  EXPECT_EQ(server.stats().steps, 2);
  EXPECT_EQ(server.stats().bad_packets, 1);
}

TEST(PlantServer, PortInUseIsAClearError) {
  PlantServerOptions o;
  o.port = 0;
  PlantServer a(std::make_unique<FirstOrderPlant>(0.01, 0.5, 1.0), o);
  o.port = a.port();
  try {
    PlantServer b(std::make_unique<FirstOrderPlant>(0.01, 0.5, 1.0), o);
    FAIL() << "second bind succeeded";
  } catch (const DataError& e) {
    EXPECT_THAT(e.what(), HasSubstr("cannot bind"));
  }
}

struct ServerThread {
  explicit ServerThread(PlantServerOptions o,
                        std::unique_ptr<Plant> plant = std::make_unique<FirstOrderPlant>(0.01, 0.95,
                                                                                         0.05))
      : server(std::move(plant), o), thread([this] { server.Serve(stop); }) {}
  ~ServerThread() {
    stop = true;
    thread.join();
  }
  std::atomic<bool> stop{false};
  PlantServer server;
  std::thread thread;
};

// The test plant of the closed loops below, which takes `delay` longer to
// compute the listed plant steps (1-based), so that the plant server answers
// them late.
class SlowStepsPlant : public FirstOrderPlant {
 public:
  SlowStepsPlant(std::vector<int> slow_steps, std::chrono::milliseconds delay)
      : FirstOrderPlant(0.01, 0.95, 0.05), slow_steps_(std::move(slow_steps)), delay_(delay) {}
  void Reset() override {
    FirstOrderPlant::Reset();
    steps_ = 0;
  }
  void Advance(double u) override {
    FirstOrderPlant::Advance(u);
    if (std::find(slow_steps_.begin(), slow_steps_.end(), ++steps_) != slow_steps_.end())
      std::this_thread::sleep_for(delay_);
  }

 private:
  std::vector<int> slow_steps_;
  std::chrono::milliseconds delay_;
  int steps_ = 0;
};

struct LoggedRun {
  std::vector<double> u, y;
  std::vector<bool> stale;
};

LoggedRun ReadLog(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  LoggedRun run;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 't') continue;
    std::vector<std::string> c;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) c.push_back(cell);
    run.u.push_back(std::stod(c[1]));
    run.y.push_back(std::stod(c[2]));
    run.stale.push_back((std::stoi(c[8]) & kLogStale) != 0);
  }
  return run;
}

// A run of CountingPi(0.8, 4.0) towards set-point 10 through the plant server
// of FirstOrderPlant(0.01, 0.95, 0.05), replayed offline sample by sample
// from its log. The server applies every Step it receives, in order, so the
// plant follows the logged inputs whether or not a reply came late; a reply
// that misses its period makes that sample stale: the loop repeats the last
// measurement and the controller acts on it. So, at every sample k:
//   fresh: y_k is the plant's output after the inputs u_0 .. u_{k-1};
//   stale: y_k is y_{k-1};
//   and u_k is the controller's answer to the y_k it saw.
// Without stale samples this is the offline simulation of the same loop.
void ExpectLogReplaysTheLoop(const LoggedRun& run) {
  FirstOrderPlant plant(0.01, 0.95, 0.05);
  CountingPi pi(0.8, 4.0, 0.01);
  plant.Reset();
  pi.Reset();
  int mismatches = 0;
  std::string first;
  auto check = [&](bool ok, const std::string& what) {
    if (ok) return;
    if (mismatches++ == 0) first = what;
  };
  ASSERT_EQ(run.u.size(), run.y.size());
  for (std::size_t k = 0; k < run.y.size(); ++k) {
    const double y_plant = plant.Measure();
    if (run.stale[k]) {
      check(k > 0 && run.y[k] == run.y[k - 1],
            fmt::format("stale sample {}: y = {} is not the previous {}", k, run.y[k],
                        k > 0 ? run.y[k - 1] : std::nan("")));
    } else {
      check(std::abs(run.y[k] - y_plant) <= 1e-6 * (1.0 + std::abs(y_plant)),
            fmt::format("sample {}: y = {}, the plant gives {}", k, run.y[k], y_plant));
    }
    const double u =
        std::clamp(pi.Update(static_cast<std::int64_t>(k), 10.0, run.y[k]), 0.0, 100.0);
    check(std::abs(run.u[k] - u) <= 1e-6 * (1.0 + std::abs(u)),
          fmt::format("sample {}: u = {}, the controller gives {}", k, run.u[k], u));
    plant.Advance(run.u[k]);
  }
  EXPECT_EQ(mismatches, 0) << "first: " << first;
}

TEST(UdpBackend, ClosedLoopThroughThePlantServerMatchesTheOfflineSimulation) {
  PlantServerOptions so;
  so.port = 0;
  auto srv = std::make_unique<ServerThread>(so);
  UdpBackendOptions uo;
  uo.port = srv->server.port();
  // Correctness here: a loaded machine's late replies are checked below, not a fault.
  uo.max_missed = 1000;
  UdpBackend io(uo);
  CountingPi pi(0.8, 4.0, 0.01);
  SafetyOptions safety_options;
  safety_options.max_overruns = -1;  // correctness here; timing is measured in bench/
  SafetyMonitor safety(safety_options);
  const std::string path = std::string(PNEUMID_BINARY_DIR) + "/realtime_test_udp.csv";
  LogWriter log(path, {{"io", io.Describe()}});
  LoopOptions o;
  o.period = 0.01;
  o.duration = 3.0;
  o.realtime = false;
  const LoopSummary s = RunLoop(o, io, pi, {10.0}, safety, &log);
  log.Close(s.timing.BriefReport(), s.message);
  srv.reset();

  EXPECT_EQ(s.termination, Termination::kSuccess) << s.message;
  EXPECT_EQ(s.samples, 300);
  EXPECT_EQ(pi.allocations_during_run(), 0);
  const LoggedRun run = ReadLog(path);
  ASSERT_EQ(run.y.size(), 300u);
  EXPECT_EQ(std::count(run.stale.begin(), run.stale.end(), true), io.stale_samples());
  ExpectLogReplaysTheLoop(run);
  // The loop reached the set-point (the plant's gain is 1).
  EXPECT_NEAR(run.y.back(), 10.0, 0.05);
}

TEST(UdpBackend, LateRepliesAreStaleSamplesThatTheLoopActsOn) {
  // Five plant steps take 60 ms, six periods: their replies come after the
  // 2.5 ms the loop's Read waits for them (unless the loop itself wakes over
  // 57 ms late), so each gives at least one stale sample.
  const std::vector<int> slow = {50, 100, 150, 200, 250};
  PlantServerOptions so;
  so.port = 0;
  auto srv = std::make_unique<ServerThread>(
      so, std::make_unique<SlowStepsPlant>(slow, std::chrono::milliseconds(60)));
  UdpBackendOptions uo;
  uo.port = srv->server.port();
  uo.max_missed = 1000;
  UdpBackend io(uo);
  CountingPi pi(0.8, 4.0, 0.01);
  SafetyOptions safety_options;
  safety_options.max_overruns = -1;
  SafetyMonitor safety(safety_options);
  const std::string path = std::string(PNEUMID_BINARY_DIR) + "/realtime_test_udp_late.csv";
  LogWriter log(path, {{"io", io.Describe()}});
  LoopOptions o;
  o.period = 0.01;
  o.duration = 3.0;
  o.realtime = false;
  const LoopSummary s = RunLoop(o, io, pi, {10.0}, safety, &log);
  log.Close(s.timing.BriefReport(), s.message);
  srv.reset();

  EXPECT_EQ(s.termination, Termination::kSuccess) << s.message;
  const LoggedRun run = ReadLog(path);
  ASSERT_EQ(run.y.size(), 300u);
  const auto stale = std::count(run.stale.begin(), run.stale.end(), true);
  EXPECT_EQ(stale, io.stale_samples());
  EXPECT_GE(stale, static_cast<long>(slow.size()));
  // The sample whose reply was delayed (the loop's sample n gets the reply to step n) is stale.
  for (int n : slow) EXPECT_TRUE(run.stale[static_cast<std::size_t>(n)]) << "sample " << n;
  ExpectLogReplaysTheLoop(run);
}

TEST(UdpBackend, SilentServerIsATimeoutWithinMaxMissedPeriods) {
  PlantServerOptions so;
  so.port = 0;
  so.stop_answering_after = 50;
  auto srv = std::make_unique<ServerThread>(so);
  UdpBackendOptions uo;
  uo.port = srv->server.port();
  uo.max_missed = 3;
  UdpBackend io(uo);
  CountingPi pi(0.8, 4.0, 0.01);
  SafetyOptions safety_options;
  safety_options.max_overruns = -1;
  safety_options.safe_state = SafeState::kRelease;
  SafetyMonitor safety(safety_options);
  const std::string path = std::string(PNEUMID_BINARY_DIR) + "/realtime_test_udp_timeout.csv";
  LogWriter log(path, {});
  LoopOptions o;
  o.period = 0.01;
  o.duration = 3.0;
  o.realtime = false;
  const LoopSummary s = RunLoop(o, io, pi, {10.0}, safety, &log);
  log.Close(s.timing.BriefReport(), s.message);
  srv.reset();
  EXPECT_EQ(s.termination, Termination::kFailure);
  EXPECT_EQ(s.fault, Fault::kTimeout);
  // 50 steps answered (samples 0..50 fresh), then 3 missing replies: fault at sample 53.
  EXPECT_EQ(s.samples, 54);
  EXPECT_THAT(s.message, HasSubstr("timeout"));
  // The served plant is a first-order one: its release state has the
  // generic name (an IPA server's is "exhaust-open").
  EXPECT_THAT(s.message, HasSubstr("outputs set to release"));
}

TEST(UdpBackend, NoServerIsAClearErrorAtOpen) {
  PlantServerOptions so;
  so.port = 0;
  int port = 0;
  {
    PlantServer probe(std::make_unique<FirstOrderPlant>(0.01, 0.5, 1.0), so);
    port = probe.port();
  }  // closed: nobody listens on `port` now
  UdpBackendOptions uo;
  uo.port = port;
  uo.hello_timeout = 0.1;
  uo.hello_attempts = 2;
  UdpBackend io(uo);
  try {
    io.Open(0.01);
    FAIL() << "Open succeeded without a server";
  } catch (const DataError& e) {
    EXPECT_THAT(e.what(), HasSubstr("no answer from a plant server"));
  }
  EXPECT_THROW(UdpBackend(UdpBackendOptions{"", 1}), InvalidArgument);
}

// A request about the plant (Info or Describe) of argument k, handled by
// `server`; the reply, checked to answer it with status ok.
udp::Reply AskPlantServer(PlantServer& server, udp::PacketType type, std::uint32_t k) {
  udp::Request req;
  req.type = type;
  req.sequence = 7 + k;
  req.arg = k;
  const udp::Packet p = udp::Encode(req);
  udp::Packet out;
  EXPECT_TRUE(server.Handle(p.data(), p.size(), &out));
  udp::Reply rep;
  EXPECT_EQ(udp::DecodeReply(out.data(), out.size(), &rep), udp::DecodeResult::kOk);
  EXPECT_EQ(rep.type, type);
  EXPECT_EQ(rep.sequence, 7 + k);
  EXPECT_EQ(rep.status, udp::PacketStatus::kOk);
  return rep;
}

// Info(k) tells the server plant's input gaps (the IPA's from its valves'
// minimum pulse at 300 Hz: 0..15 and 85..100 % duty; none for a linear
// plant) without touching the plant.
TEST(PlantServer, InfoTellsThePlantsInputGapsWithoutTouchingIt) {
  PlantServerOptions o;
  o.port = 0;
  const auto info = [](PlantServer& server, std::uint32_t k) {
    return AskPlantServer(server, udp::PacketType::kInfo, k);
  };
  PlantServer ipa(MakePlant("ipa", 1.0 / 300.0), o);
  const std::vector<InputGap> gaps = PlantActuator(*MakePlant("ipa", 1.0 / 300.0)).input_gaps;
  ASSERT_EQ(gaps.size(), 2u);
  for (std::uint32_t k = 0; k < 2; ++k) {
    const udp::Reply rep = info(ipa, k);
    EXPECT_EQ(rep.plant_time, 2.0);
    EXPECT_EQ(rep.y, gaps[k].lo);
    EXPECT_EQ(rep.aux, gaps[k].hi);
  }
  EXPECT_TRUE(std::isnan(info(ipa, 2).y));
  EXPECT_EQ(ipa.stats().steps, 0);

  PlantServer linear(std::make_unique<FirstOrderPlant>(0.01, 0.5, 1.0), o);
  const udp::Reply none = info(linear, 0);
  EXPECT_EQ(none.plant_time, 0.0);
  EXPECT_TRUE(std::isnan(none.y) && std::isnan(none.aux));
}

// Describe(k) tells the server plant's actuator: the IPA in force mode (duty
// 0..100 %, force unbounded), in position mode (command -100..100 %, the
// stroke, integrating) and a generic plant (unbounded), without a step.
TEST(PlantServer, DescribeTellsThePlantsActuatorWithoutTouchingIt) {
  PlantServerOptions o;
  o.port = 0;
  const auto describe = [](PlantServer& server, std::uint32_t k) {
    return AskPlantServer(server, udp::PacketType::kDescribe, k);
  };
  const double inf = std::numeric_limits<double>::infinity();
  PlantServer force(MakePlant("ipa", 1.0 / 300.0), o);
  udp::Reply r = describe(force, 0);
  EXPECT_EQ(r.plant_time, static_cast<double>(udp::ActuatorKind::kIpaForce));
  EXPECT_EQ(r.y, 0.0);
  EXPECT_EQ(r.aux, 100.0);
  r = describe(force, 1);
  EXPECT_EQ(r.plant_time, 0.0);
  EXPECT_EQ(r.y, -inf);
  EXPECT_EQ(r.aux, inf);
  EXPECT_TRUE(std::isnan(describe(force, 2).y));
  EXPECT_EQ(force.stats().steps, 0);

  const double stroke = PlantActuator(*MakePlant("ipa-position", 1.0 / 300.0)).y_max;
  ASSERT_GT(stroke, 0.0);
  PlantServer position(MakePlant("ipa-position", 1.0 / 300.0), o);
  r = describe(position, 0);
  EXPECT_EQ(r.plant_time, static_cast<double>(udp::ActuatorKind::kIpaPosition));
  EXPECT_EQ(r.y, -100.0);
  EXPECT_EQ(r.aux, 100.0);
  r = describe(position, 1);
  EXPECT_EQ(r.plant_time, 1.0);
  EXPECT_EQ(r.y, 0.0);
  EXPECT_EQ(r.aux, stroke);

  PlantServer linear(std::make_unique<FirstOrderPlant>(0.01, 0.5, 1.0), o);
  r = describe(linear, 0);
  EXPECT_EQ(r.plant_time, static_cast<double>(udp::ActuatorKind::kOther));
  EXPECT_EQ(r.y, -inf);
  EXPECT_EQ(r.aux, inf);
}

// A client of a positioning drive's server gets that actuator: a signed
// command, the stroke as output range, integrating, the four gaps; a
// client of a linear plant's server gets the generic one, not the IPA's.
TEST(UdpBackend, LearnsThePositioningDrivesActuatorFromItsServer) {
  PlantServerOptions so;
  so.port = 0;
  const Actuator want = PlantActuator(*MakePlant("ipa-position", 1.0 / 300.0));
  auto srv = std::make_unique<ServerThread>(so, MakePlant("ipa-position", 1.0 / 300.0));
  UdpBackendOptions uo;
  uo.port = srv->server.port();
  IoPlant plant(std::make_unique<UdpBackend>(uo), 1.0 / 300.0, false);
  const Actuator a = plant.actuator();
  EXPECT_TRUE(a.integrating);
  EXPECT_EQ(a.u_min, -100.0);
  EXPECT_EQ(a.u_max, 100.0);
  EXPECT_EQ(a.y_min, 0.0);
  EXPECT_EQ(a.y_max, want.y_max);
  EXPECT_EQ(a.output.unit, "m");
  EXPECT_EQ(a.output_label, "position");
  EXPECT_EQ(a.hold_name, want.hold_name);
  EXPECT_EQ(a.input_gaps, want.input_gaps);

  auto lin = std::make_unique<ServerThread>(so, std::make_unique<FirstOrderPlant>(0.01, 0.5, 1.0));
  uo.port = lin->server.port();
  IoPlant generic(std::make_unique<UdpBackend>(uo), 0.01, false);
  const Actuator g = generic.actuator();
  EXPECT_FALSE(g.integrating);
  EXPECT_EQ(g.output.unit, "");
  EXPECT_EQ(g.hold_name, "hold");
  EXPECT_FALSE(std::isfinite(g.u_min));
  EXPECT_TRUE(g.input_gaps.empty());
}

// A client whose period was not given takes the server's (the reply to a
// Hello at another period says it); one that gave its period is refused
// with the server's in the message. The IPA server's gaps reach the
// client's actuator.
TEST(UdpBackend, AdoptsTheServersPeriodWhenAskedAndLearnsItsGaps) {
  PlantServerOptions so;
  so.port = 0;
  auto srv = std::make_unique<ServerThread>(so, MakePlant("ipa", 1.0 / 300.0));
  UdpBackendOptions uo;
  uo.port = srv->server.port();
  {
    UdpBackend strict(uo);
    try {
      strict.Open(0.01);
      FAIL() << "Open at another period succeeded";
    } catch (const DataError& e) {
      EXPECT_THAT(e.what(), HasSubstr("its plant runs at Ts = 0.0033333"));
    }
  }
  uo.adopt_server_period = true;
  auto backend = std::make_unique<UdpBackend>(uo);
  UdpBackend* raw = backend.get();
  IoPlant plant(std::move(backend), 0.01, false);
  EXPECT_DOUBLE_EQ(plant.Ts(), 1.0 / 300.0);
  EXPECT_DOUBLE_EQ(raw->adopted_period(), 1.0 / 300.0);
  EXPECT_EQ(plant.actuator().input_gaps, PlantActuator(*MakePlant("ipa", 1.0 / 300.0)).input_gaps);
  EXPECT_TRUE(std::isfinite(plant.Measure()));
  plant.Advance(50.0);
  EXPECT_TRUE(std::isfinite(plant.Measure()));
}

TEST(IoSpec, ParsesTheThreeBackends) {
  EXPECT_EQ(ParseIoSpec("sim").kind, IoKind::kSim);
  IoSpec c = ParseIoSpec("comedi:/dev/comedi1");
  EXPECT_EQ(c.kind, IoKind::kComedi);
  EXPECT_EQ(c.device, "/dev/comedi1");
  EXPECT_EQ(ParseIoSpec("comedi").device, "/dev/comedi0");
  IoSpec u = ParseIoSpec("udp://127.0.0.1:5000");
  EXPECT_EQ(u.kind, IoKind::kUdp);
  EXPECT_EQ(u.host, "127.0.0.1");
  EXPECT_EQ(u.port, 5000);
  EXPECT_EQ(u.ToString(), "udp://127.0.0.1:5000");
  EXPECT_EQ(ParseIoSpec("udp://[::1]:7").host, "::1");
  EXPECT_THROW(ParseIoSpec("udp://host"), InvalidArgument);
  EXPECT_THROW(ParseIoSpec("udp://host:99999"), InvalidArgument);
  EXPECT_THROW(ParseIoSpec("serial"), InvalidArgument);
  EXPECT_THROW(ParseIoSpec("comedi:dev"), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
