#include "pneumid/workflow/run_workflow.hpp"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/control/controller.hpp"
#include "pneumid/models/model_file_scope.hpp"
#include "pneumid/plant/signal.hpp"
#include "pneumid/realtime/controller_adapter.hpp"
#include "pneumid/realtime/io_factory.hpp"
#include "pneumid/realtime/realtime_session.hpp"
#include "pneumid/realtime/sim_backend.hpp"
#include "pneumid/workflow/control_scenario.hpp"

namespace pneumid {

void RunSafetyOverrides::ApplyTo(SafetyOptions& s) const {
  if (u_min) s.u_min = *u_min;
  if (u_max) s.u_max = *u_max;
  if (rate_max) s.rate_max = *rate_max;
  if (y_min) s.y_min = *y_min;
  if (y_max) s.y_max = *y_max;
  if (frozen_samples) s.frozen_samples = *frozen_samples;
}

bool RunSafetyOverrides::IsValid(std::string* error) const {
  auto fail = [error](std::string message) {
    if (error != nullptr) *error = std::move(message);
    return false;
  };
  const std::pair<const char*, const std::optional<double>*> limits[] = {
      {"--u-min", &u_min}, {"--u-max", &u_max}, {"--y-min", &y_min}, {"--y-max", &y_max}};
  for (const auto& [flag, value] : limits)
    if (*value && !std::isfinite(**value))
      return fail(fmt::format("{} must be finite, got {}", flag, **value));
  if (u_min && u_max && !(*u_min < *u_max))
    return fail(fmt::format("--u-min {} must be below --u-max {}", *u_min, *u_max));
  if (y_min && y_max && !(*y_min < *y_max))
    return fail(fmt::format("--y-min {} must be below --y-max {}", *y_min, *y_max));
  if (rate_max && (std::isnan(*rate_max) || *rate_max < 0.0))
    return fail(fmt::format("--rate-max must be >= 0 (0 = no limit), got {}", *rate_max));
  if (frozen_samples && *frozen_samples < 0)
    return fail(fmt::format("--frozen-samples must be >= 0 (0 = off), got {}", *frozen_samples));
  return true;
}

bool RunWorkflowOptions::IsValid(std::string* error) const {
  auto fail = [error](std::string message) {
    if (error != nullptr) *error = std::move(message);
    return false;
  };
  if (model.empty()) return fail("--model must name a model (a spec, a file or a document)");
  if (setpoint.empty()) return fail("--setpoint must give a set-point signal");
  for (const LoadStep& l : load_steps)
    if (!std::isfinite(l.at) || l.at < 0.0 || !std::isfinite(l.size))
      return fail(fmt::format(
          "--load-step at={},size={}: need a finite time at >= 0 and a finite size", l.at, l.size));
  if (!safety.IsValid(error)) return false;
  std::string why;
  if (!plant_options.IsValid(&why)) return fail(fmt::format("--noise: {}", why));
  return true;
}

nlohmann::json RunWorkflowResult::ToJson() const {
  nlohmann::json j = summary.ToJson();
  j["controller"] = controller;
  j["io"] = io;
  j["log"] = log;
  j["log_rows"] = log_rows;
  j["metrics"] = metrics;
  if (!offline.is_null()) j["offline_metrics"] = offline;
  return j;
}

namespace {

// The clamp of an unbounded input (finite, as SafetyOptions needs).
constexpr double kUnboundedInput = 1e300;

bool IsMatPath(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".mat";
}

// The controller specification of the run: clamped to the safety layer's
// output range, with the input gaps "plant" of the backend's plant and the
// model's input map.
ControllerSpec RunControllerSpec(const RunWorkflowOptions& o, const InputLimits& limits,
                                 const IoBackend& io) {
  ControllerSettings c = o.controller;
  c.limits = limits;
  ResolvePlantInputGaps(io.actuator(), io.Describe(), c.input_gaps);
  return WithModelInputMap(ToControllerSpec(c), o.model);
}

// Without a clamp from the options or the configuration: the plant's input
// range where it is finite (the position twin's -100..100 %); a simulated
// linear plant (a model spec, whose input is unbounded, as `control` takes
// it) gets no clamp (+-1e300); a plant server or a rig the safety defaults.
SafetyOptions RunSafety(const RunWorkflowOptions& o, const RealtimeConfig& config,
                        const IoSpec& spec, const IoBackend& io) {
  return o.safety.GivesClamp() ? config.safety : DefaultSessionSafety(config, spec, io);
}

// The closed-loop metrics of the records of a completed run (control area's
// definitions); null when the loop did not complete or logged too little.
nlohmann::json RunMetrics(const SessionResult& res, double r0, const ClosedLoopOptions& clo) {
  const auto m = static_cast<Eigen::Index>(res.records.size());
  if (m < 2 || res.summary.termination != Termination::kSuccess) return nullptr;
  Eigen::VectorXd t(m), r(m), y(m), u(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    t[i] = res.records[i].t;
    r[i] = res.records[i].r;
    y[i] = res.records[i].y;
    u[i] = res.records[i].u;
  }
  return ComputeClosedLoopMetrics(t, r, y, u, r0, 0.0, clo).ToJson();
}

void CheckValid(const RunWorkflowOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) throw InvalidArgument(why);
}

}  // namespace

SafetyOptions DefaultSessionSafety(const RealtimeConfig& config, const IoSpec& spec,
                                   const IoBackend& io) {
  SafetyOptions safety = config.safety;
  if (config.safety_range_given) return safety;
  const Actuator a = io.actuator();
  if (std::isfinite(a.u_min) && std::isfinite(a.u_max) && a.u_min < a.u_max) {
    safety.u_min = a.u_min;
    safety.u_max = a.u_max;
  } else if (spec.kind == IoKind::kSim && std::isinf(a.u_min) && std::isinf(a.u_max)) {
    safety.u_min = -kUnboundedInput;
    safety.u_max = kUnboundedInput;
  }
  return safety;
}

RunWorkflowResult RunRealtimeWorkflow(const RunWorkflowOptions& o, const RealtimeConfig& given,
                                      SpscRingBuffer<LogRecord>* live) {
  CheckValid(o);
  RealtimeConfig config = given;
  o.safety.ApplyTo(config.safety);
  std::string error;
  PNEUMID_CHECK(config.safety.IsValid(&error), "invalid safety settings: {}", error);
  // The run reads its model files once, and a model document from memory.
  const ModelFileScope model_files;
  if (o.model_document) ModelFileScope::Provide(o.model, *o.model_document);

  const IoSpec spec = ParseIoSpec(config.io);
  const double Ts = config.loop.period;
  const TransferFunction model = ParseControllerModel(o.model);
  auto io = MakeIoBackend(spec, config, o.plant_options);
  const SafetyOptions safety = RunSafety(o, config, spec, *io);
  InputLimits limits;
  limits.u_min = safety.u_min;
  limits.u_max = safety.u_max;
  const ControllerSpec controller_spec = RunControllerSpec(o, limits, *io);
  BuiltController built = MakeController(model, Ts, controller_spec);
  RunWorkflowResult out;
  out.controller = built.controller->Describe();
  out.io = io->Describe();
  out.log = o.log;
  const std::string tuning = built.Summary();
  ControllerAdapter controller(std::move(built.controller));

  const auto sp = ParseSignal(o.setpoint);
  const Eigen::VectorXd r = sp->Sample(Ts, config.loop.Samples());
  if (o.warn)
    if (std::optional<std::string> w =
            UnreachableSetpointWarning(r, model, controller_spec, limits.u_min, limits.u_max))
      o.warn(*w);
  const std::vector<double> setpoint(r.data(), r.data() + r.size());
  if (auto* sim = dynamic_cast<SimBackend*>(io.get())) sim->SetLoadSteps(o.load_steps);

  SessionOptions so;
  so.loop = config.loop;
  so.safety = safety;
  so.log = config.log;
  so.log.live = live;
  so.log_path = o.log;
  if (IsMatPath(o.log)) so.log.format = LogFormat::kMat;
  so.keep_records = true;
  so.header.emplace_back("model", o.model);
  so.header.emplace_back("tuning", tuning);
  so.header.emplace_back("setpoint", sp->ToString());
  so.live_status = o.live_status;
  const SessionResult res = RunSession(so, *io, controller, setpoint);
  out.summary = res.summary;
  out.log_rows = res.log_rows;

  ClosedLoopOptions clo;
  clo.duration = config.loop.duration;
  clo.actuator = limits;
  clo.load_steps = o.load_steps;
  out.metrics = RunMetrics(res, (*sp)(-Ts), clo);
  if (o.offline) {
    // The same scenario simulated offline (no real time, no I/O) for comparison.
    auto plant = MakePlant(config.plant, Ts, o.plant_options);
    BuiltController again = MakeController(model, Ts, controller_spec);
    out.offline = SimulateClosedLoop(*again.controller, *plant, *sp, clo).metrics.ToJson();
  }
  return out;
}

}  // namespace pneumid
