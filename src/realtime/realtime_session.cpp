#include "pneumid/realtime/realtime_session.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <thread>

#include <fmt/format.h>

#include "pneumid/common/version.hpp"

namespace pneumid {

std::string DescribeSafety(const SafetyOptions& s, const Actuator& actuator) {
  const std::string unit = actuator.input.unit.empty() ? "" : " " + actuator.input.unit;
  return fmt::format(
      "u in [{:g}, {:g}]{}, rate {}, y in [{:g}, {:g}], frozen {}, max overruns {}, safe state {}",
      s.u_min, s.u_max, unit,
      s.rate_max > 0 ? fmt::format("<= {:g}{}/s", s.rate_max, unit) : "unlimited", s.y_min, s.y_max,
      s.frozen_samples > 0
          ? fmt::format("after {} samples within {:g}", s.frozen_samples, s.frozen_tolerance)
          : "off",
      s.max_overruns < 0 ? std::string("unlimited") : std::to_string(s.max_overruns),
      SafeStateName(actuator, s.safe_state));
}

SessionResult RunSession(const SessionOptions& options, IoBackend& io, LoopController& controller,
                         const std::vector<double>& setpoint) {
  std::string error;
  PNEUMID_CHECK(options.loop.IsValid(&error), "invalid loop options: {}", error);
  CheckSetpointsInOutputRange(io.actuator(), setpoint.data(), setpoint.size(), options.loop.period);
  SafetyMonitor safety(options.safety);
  std::unique_ptr<LogWriter> log;
  if (!options.log_path.empty() || options.keep_records) {
    std::vector<std::pair<std::string, std::string>> header;
    const std::time_t now = std::time(nullptr);
    char date[64];
    std::strftime(date, sizeof(date), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
    header.emplace_back("pneumid", std::string(Version()));
    header.emplace_back("date", date);
    header.emplace_back("io", io.Describe());
    header.emplace_back("controller", controller.Describe());
    header.emplace_back("period", fmt::format("{:g} s", options.loop.period));
    header.emplace_back("duration", fmt::format("{:g} s ({} samples)", options.loop.duration,
                                                options.loop.Samples()));
    header.emplace_back("safety", DescribeSafety(options.safety, io.actuator()));
    for (const auto& h : options.header) header.push_back(h);
    LogWriterOptions lo = options.log;
    lo.keep_in_memory = lo.keep_in_memory || options.keep_records;
    log = std::make_unique<LogWriter>(options.log_path, std::move(header), lo);
  }
  InstallStopSignalHandlers();
  ClearStopRequest();

  LoopStatus status;
  std::atomic<bool> done{false};
  std::thread printer;
  if (options.live_status) {
    const Actuator actuator = io.actuator();
    printer = std::thread([&, actuator] {
      while (!done.load()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        const auto k = status.k.load();
        if (k < 0) continue;
        const std::string line = fmt::format(
            "\r  t {:8.2f} s  set point {:8.2f}  {} {:8.2f}  {} {:6.2f} {}  jitter {:6.0f} us  "
            "overruns {}   ",
            static_cast<double>(k) * options.loop.period, status.r.load(), actuator.output_label,
            status.y.load(), actuator.input_label, status.u.load(), actuator.input.unit,
            status.jitter_us.load(), static_cast<long long>(status.overruns.load()));
        std::fputs(line.c_str(), stderr);
        std::fflush(stderr);
      }
      std::fputs("\n", stderr);
    });
  }
  SessionResult result;
  try {
    result.summary = RunLoop(options.loop, io, controller, setpoint, safety, log.get(), &status);
  } catch (...) {
    done = true;
    if (printer.joinable()) printer.join();
    throw;
  }
  done = true;
  if (printer.joinable()) printer.join();
  if (log) {
    log->Close(result.summary.timing.BriefReport() + "; " + result.summary.scheduling,
               std::string(ToString(result.summary.termination)) + ": " + result.summary.message);
    result.log_rows = log->written();
    result.summary.log_dropped = log->dropped();
    if (options.keep_records) result.records = log->records();
  }
  return result;
}

}  // namespace pneumid
