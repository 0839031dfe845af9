// pneumid experiment: the paper's data-collection step (open-loop step, PRBS or
// staircase input) run in real time on any I/O backend, written as a data set
// that `pneumid identify` reads directly (columns t,u,y).
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "validators.hpp"
#include "realtime_options.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/data/dataset.hpp"
#include "pneumid/data/load.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/plant/signal.hpp"
#include "pneumid/realtime/io_factory.hpp"
#include "pneumid/realtime/realtime_config.hpp"
#include "pneumid/realtime/realtime_session.hpp"
#include "pneumid/workflow/run_workflow.hpp"

namespace pneumid::cli {
namespace {

struct ExperimentArgs {
  std::string kind;
  std::string input;  // --input SPEC overrides the kind's parameters
  // step
  double from = 0.61, to = 82.0, at = 1.0;
  // prbs
  double low = 20.0, high = 60.0, clock = 0.05;
  int order = 7;
  // staircase
  std::string levels = "0 20 40 60 40 20";
  double dwell = 1.5;
  // run: --io, --config, --plant, --Ts, --duration, --log, --json, ...
  RealtimeOptions rt;
  std::string output;
};

std::string InputSpec(const ExperimentArgs& o) {
  if (!o.input.empty()) return o.input;
  if (o.kind == "step") return fmt::format("step:from={:g},to={:g},at={:g}", o.from, o.to, o.at);
  if (o.kind == "prbs")
    return fmt::format("prbs:low={:g},high={:g},order={},clock={:g},seed={}", o.low, o.high,
                       o.order, o.clock, o.rt.seed);
  if (o.kind == "staircase")
    return fmt::format("staircase:levels={},dwell={:g}", o.levels, o.dwell);
  throw InvalidArgument(fmt::format(
      "experiment kind must be step, prbs or staircase (or give --input), got '{}'", o.kind));
}

void Run(const ExperimentArgs& o, CLI::App& app) {
  const RealtimeConfig config = ResolveRealtimeConfig(o.rt, app);
  PNEUMID_CHECK(!o.output.empty(), "-o/--output is required");
  const IoSpec spec = ParseIoSpec(config.io);
  const std::string input_spec = InputSpec(o);
  const auto signal = ParseSignal(input_spec);
  const std::int64_t n = config.loop.Samples();
  const Eigen::VectorXd u = signal->Sample(config.loop.period, n);
  std::vector<double> input(u.data(), u.data() + u.size());
  OpenLoopInput controller(input, "open loop: " + signal->ToString());

  auto io = MakeIoBackend(spec, config, SimulatedPlantOptions(o.rt));

  const bool to_mat = IsMatPath(o.output);
  SessionOptions so;
  so.loop = config.loop;
  // The plant's own input range, none for a simulated linear plant (its
  // input was clipped to the safety default 0..100 %: a step from -5 to -2
  // was recorded as u = 0, y = 0 with "success").
  so.safety = DefaultSessionSafety(config, spec, *io);
  so.log = config.log;
  // CSV: the data set is streamed (t,u,y); .mat: the records are kept and written at the
  // end, with --log streaming the full log meanwhile.
  so.log.format = to_mat ? LogFormat::kCsv : LogFormat::kDataset;
  so.log_path = to_mat ? o.rt.log : o.output;
  so.keep_records = to_mat || !o.rt.log.empty();
  so.header.emplace_back("experiment", input_spec);
  so.live_status = StderrIsTerminal() && !o.rt.json;
  const SessionResult r = RunSession(so, *io, controller, {});
  const LoopSummary& s = r.summary;

  if (so.keep_records) {
    // What is left to write, from the records kept in memory.
    if (to_mat) {
      Eigen::VectorXd t(static_cast<Eigen::Index>(r.records.size())), uu(t.size()), yy(t.size());
      for (Eigen::Index i = 0; i < t.size(); ++i) {
        t[i] = r.records[i].t;
        uu[i] = r.records[i].u;
        yy[i] = r.records[i].y;
      }
      PNEUMID_CHECK(t.size() >= 2, "the run ended after {} samples: nothing to write to {}",
                    t.size(), o.output);
      SaveDataset(Dataset(t, uu, yy, {io->actuator().input}, {io->actuator().output}), o.output);
    } else {
      LogWriter full(o.rt.log, {{"experiment", input_spec}, {"io", io->Describe()}});
      for (const auto& rec : r.records) full.Push(rec);
      full.Close(s.timing.BriefReport(), std::string(ToString(s.termination)) + ": " + s.message);
    }
  }

  if (o.rt.json) {
    nlohmann::json j = s.ToJson();
    j["output"] = o.output;
    j["rows"] = to_mat ? static_cast<std::int64_t>(r.records.size()) : r.log_rows;
    j["input"] = input_spec;
    j["io"] = io->Describe();
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << fmt::format("{}: {} rows ({}), input {}\n", o.output,
                             to_mat ? static_cast<std::int64_t>(r.records.size()) : r.log_rows,
                             io->Describe(), input_spec);
    std::cout << fmt::format("{}\n{}\n{}\n", s.message, s.timing.BriefReport(), s.scheduling);
  }
  FinishSession("experiment", s);
}

}  // namespace

static Registrar reg(
    "experiment",
    "Run an open-loop identification experiment (step, prbs, staircase) in real time on the "
    "simulator, a comedi card or a plant server, and write t,u,y for `pneumid identify`",
    [](CLI::App& app) {
      auto o = std::make_shared<ExperimentArgs>();
      app.add_option("kind", o->kind, "step, prbs or staircase (optional with --input)")
          ->check(CLI::IsMember({"step", "prbs", "staircase"}));
      app.add_option("--input", o->input,
                     "input signal spec (overrides the kind's flags)\n" + SignalSyntaxHelp());
      app.add_option("--from", o->from, "step: initial duty (%)")->capture_default_str();
      app.add_option("--to", o->to, "step: final duty (%)")->capture_default_str();
      app.add_option("--at", o->at, "step: time of the step (s)")
          ->capture_default_str()
          ->check(NonNegative());
      app.add_option("--low", o->low, "prbs: low level (%)")->capture_default_str();
      app.add_option("--high", o->high, "prbs: high level (%)")->capture_default_str();
      app.add_option("--order", o->order, "prbs: shift-register order")->capture_default_str();
      app.add_option("--clock", o->clock, "prbs: clock period (s)")
          ->capture_default_str()
          ->check(Positive());
      app.add_option("--levels", o->levels, "staircase: levels (%), space separated")
          ->capture_default_str();
      app.add_option("--dwell", o->dwell, "staircase: time per level (s)")
          ->capture_default_str()
          ->check(Positive());
      o->rt.duration = 4.0;
      RealtimeHelp help;
      help.plant = "plant of the sim backend (default ipa)\n" + PlantSpecHelp();
      help.seed = "noise seed of the simulated plant and PRBS";
      help.log = "also write the full real-time log (CSV) here";
      AddRealtimeOptions(app, o->rt, help);
      app.add_option("-o,--output", o->output, "data set to write (.csv streamed, or .mat)")
          ->required();
      app.callback([o, &app] { Run(*o, app); });
    });

}  // namespace pneumid::cli
