// pneumid info DATA: validate a data file and print its summary.
#include <cmath>
#include <iostream>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "data_options.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/strings.hpp"
#include "pneumid/data/load.hpp"
#include "pneumid/data/preprocess.hpp"
#include "validators.hpp"

namespace pneumid::cli {
namespace {

struct InfoArgs {
  DataOptions data;
  bool json = false;
  bool strict = false;
  double tolerance = 1e-3;
  std::vector<std::string> window;  // T0,T1 (or T0 T1), or T0:T1 as the other commands
  double resample = -1.0;           // < 0: off; 0: at the median interval
  int decimate = 1;
  std::string save;
};

struct ChannelStats {
  Channel channel;
  std::string role;
  double min, max, mean, std;
};

ChannelStats Stats(const Channel& c, const std::string& role, const Eigen::VectorXd& v) {
  const double mean = v.mean();
  const double var = v.size() > 1 ? (v.array() - mean).square().sum() / (v.size() - 1.0) : 0.0;
  return {c, role, v.minCoeff(), v.maxCoeff(), mean, std::sqrt(var)};
}

std::string Label(const Channel& c) {
  return c.unit.empty() ? c.name : fmt::format("{} [{}]", c.name, c.unit);
}

/// The --window option: T0:T1 as one value, or T0,T1 (T0 T1) as two.
std::optional<TimeWindow> ParseWindowOption(const std::vector<std::string>& values) {
  if (values.size() == 1 && values[0].find(':') != std::string::npos) {
    try {
      return TimeWindow::Parse(values[0]);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(fmt::format("--window: {}", e.what()));
    }
  }
  if (values.empty()) return std::nullopt;
  PNEUMID_CHECK(values.size() == 2,
                "--window takes two times T0,T1 (or T0:T1) in seconds, got {} value(s)",
                values.size());
  TimeWindow window;
  auto time = [](const std::string& text, const char* which) {
    const std::optional<double> seconds = ParseDouble(text);
    PNEUMID_CHECK(seconds.has_value(), "--window: {} must be a time in seconds, got '{}'", which,
                  text);
    return *seconds;
  };
  window.start = time(values[0], "T0");
  window.end = time(values[1], "T1");
  std::string why;
  PNEUMID_CHECK(window.IsValid(&why), "--window: {}", why);
  return window;
}

/// Applies the window, resampling and decimation asked for to `data`; returns
/// a description of each step, in order.
std::vector<std::string> ApplyPreprocessing(const InfoArgs& args,
                                            const std::optional<TimeWindow>& window,
                                            Dataset& data) {
  std::vector<std::string> steps;
  if (window) {
    data = SelectWindow(data, window->start, window->end);
    steps.push_back(fmt::format("window [{:g}, {:g}] s", window->start, window->end));
  }
  if (args.resample >= 0) {
    data.RequireSamples(2, "resampling");
    const double Ts = args.resample > 0 ? args.resample : data.MedianSampleInterval();
    data = Resample(data, Ts);
    steps.push_back(fmt::format("resampled to Ts = {:g} s (linear interpolation)", Ts));
  }
  if (args.decimate > 1) {
    DecimateOptions decimate;
    decimate.uniform_tolerance = args.tolerance;
    data = Decimate(data, args.decimate, decimate);
    steps.push_back(fmt::format("decimated by {} (zero-phase Butterworth order {} anti-alias)",
                                args.decimate, decimate.order));
  }
  return steps;
}

/// The sampling of a dataset: sample time, intervals and uniformity.
struct SamplingSummary {
  Eigen::Index samples = 0;
  bool enough = false;  ///< at least two samples (the intervals below are defined)
  double Ts = 0.0;      ///< mean sample interval
  double Tnom = 0.0;    ///< median sample interval
  double min_dt = 0.0, max_dt = 0.0;
  bool uniform = false;
  std::string first_gap;      ///< the first irregular interval, when not uniform
  std::string resample_hint;  ///< the command that resamples the file to a uniform grid
};

/// The sampling of `data`; throws DataError (the first irregular interval,
/// "file:line: ...") for non-uniform sampling with --strict.
SamplingSummary SummarizeSampling(const InfoArgs& args, const Dataset& data) {
  SamplingSummary sampling;
  const Eigen::Index n = data.size();
  sampling.samples = n;
  sampling.enough = n >= 2;
  sampling.Ts = sampling.enough ? data.SampleTime() : 0.0;
  sampling.Tnom = sampling.enough ? data.MedianSampleInterval() : 0.0;
  sampling.uniform = data.IsUniform(args.tolerance);
  if (!sampling.uniform) {
    std::string uniform_error;  // the first irregular interval, "file:line: ..."
    try {
      data.RequireUniform(args.tolerance);
    } catch (const DataError& e) {
      uniform_error = e.what();
    }
    if (args.strict) throw DataError(uniform_error);
    const double Tnom = sampling.Tnom;
    for (Eigen::Index i = 1; i < n; ++i) {
      const double dt = data.time()[i] - data.time()[i - 1];
      if (std::abs(dt - Tnom) > args.tolerance * Tnom) {
        sampling.first_gap = fmt::format("{}: interval {:g} s between t = {:g} and {:g} s",
                                         data.Where(i), dt, data.time()[i - 1], data.time()[i]);
        break;
      }
    }
  }
  if (sampling.enough) {
    const Eigen::VectorXd dt = data.time().tail(n - 1) - data.time().head(n - 1);
    sampling.min_dt = dt.minCoeff();
    sampling.max_dt = dt.maxCoeff();
  }
  const std::string& path = args.data.path;
  sampling.resample_hint = fmt::format("pneumid info {} --resample {:g} -o {}", path, sampling.Tnom,
                                       path.substr(0, path.find_last_of('.')) + "_uniform.csv");
  return sampling;
}

/// Statistics of the time, input and output channels, in that order.
std::vector<ChannelStats> ChannelSummaries(const Dataset& data) {
  std::vector<ChannelStats> stats;
  stats.push_back(Stats(data.time_channel(), "time", data.time()));
  for (int i = 0; i < data.num_inputs(); ++i) {
    stats.push_back(Stats(data.input_channels()[static_cast<std::size_t>(i)], "input", data.u(i)));
  }
  for (int i = 0; i < data.num_outputs(); ++i) {
    stats.push_back(
        Stats(data.output_channels()[static_cast<std::size_t>(i)], "output", data.y(i)));
  }
  return stats;
}

/// The input step of a dataset, or why none was found.
struct StepSummary {
  bool found = false;
  StepEvent step;
  std::string error;  ///< why there is no step
};

StepSummary FindStep(const Dataset& data) {
  StepSummary summary;
  if (data.num_inputs() == 0) {
    summary.error = "no input channel";
    return summary;
  }
  try {
    summary.step = DetectStep(data);
    summary.found = true;
  } catch (const DataError& e) {
    summary.error = e.what();
  }
  return summary;
}

/// What `pneumid info` prints about a (preprocessed) data file.
struct InfoSummary {
  DataFormat format;
  std::vector<std::string> steps;  ///< preprocessing applied, in order
  SamplingSummary sampling;
  std::vector<ChannelStats> stats;
  StepSummary step;
};

void PrintJson(const InfoArgs& args, const Dataset& data, const InfoSummary& info) {
  const SamplingSummary& sampling = info.sampling;
  const Eigen::Index n = sampling.samples;
  nlohmann::json j;
  j["file"] = args.data.path;
  j["format"] = ToString(info.format);
  j["samples"] = n;
  j["start_time"] = data.time()[0];
  j["end_time"] = data.time()[n - 1];
  j["sample_time"] = sampling.Ts;
  j["median_sample_interval"] = sampling.Tnom;
  j["min_sample_interval"] = sampling.min_dt;
  j["max_sample_interval"] = sampling.max_dt;
  j["uniform"] = sampling.uniform;
  j["uniform_tolerance"] = args.tolerance;
  if (!sampling.uniform) {
    j["first_irregular_interval"] = sampling.first_gap;
    j["resample_hint"] = sampling.resample_hint;
  }
  j["preprocessing"] = info.steps;
  if (!args.save.empty()) j["saved"] = args.save;
  j["channels"] = nlohmann::json::array();
  for (const auto& s : info.stats) {
    j["channels"].push_back({{"name", s.channel.name},
                             {"unit", s.channel.unit},
                             {"role", s.role},
                             {"min", s.min},
                             {"max", s.max},
                             {"mean", s.mean},
                             {"std", s.std}});
  }
  if (info.step.found) {
    const StepEvent& step = info.step.step;
    const std::string& name = data.input_channels()[static_cast<std::size_t>(step.input)].name;
    nlohmann::json step_json = {{"input", name},
                                {"index", step.index},
                                {"time", step.time},
                                {"size", step.size},
                                {"baseline_before", step.baseline_before},
                                {"level_after", step.level_after}};
    if (const long line = data.SourceLine(step.index); line > 0) step_json["line"] = line;
    step_json["outputs_before"] = std::vector<double>(
        step.outputs_before.data(), step.outputs_before.data() + step.outputs_before.size());
    step_json["significance"] =
        std::isfinite(step.significance) ? nlohmann::json(step.significance) : nlohmann::json();
    j["step"] = step_json;
  } else {
    j["step"] = nullptr;
    j["step_error"] = info.step.error;
  }
  std::cout << j.dump(2) << "\n";
}

void PrintText(const InfoArgs& args, const Dataset& data, const InfoSummary& info) {
  const SamplingSummary& sampling = info.sampling;
  const Eigen::Index n = sampling.samples;
  std::ostringstream out;
  out << fmt::format("file:          {} ({})\n", args.data.path, ToString(info.format));
  for (const auto& s : info.steps) out << fmt::format("preprocessed:  {}\n", s);
  if (!args.save.empty()) out << fmt::format("saved:         {}\n", args.save);
  out << fmt::format("samples:       {}\n", n);
  out << fmt::format("time:          {:g} .. {:g} s (duration {:g} s)\n", data.time()[0],
                     data.time()[n - 1], data.time()[n - 1] - data.time()[0]);
  if (sampling.enough) {
    out << fmt::format(
        "sample time:   {:g} s (mean interval; median {:g} s, range {:g} .. {:g} s)\n", sampling.Ts,
        sampling.Tnom, sampling.min_dt, sampling.max_dt);
  }
  out << fmt::format("uniform:       {} (tolerance {:g} %)\n", sampling.uniform ? "yes" : "no",
                     100.0 * args.tolerance);
  if (!sampling.uniform) {
    out << fmt::format("               first irregular interval: {}\n", sampling.first_gap);
    out << fmt::format("               resample to a uniform grid with:\n                 {}\n",
                       sampling.resample_hint);
  }
  out << fmt::format("\n{:<20} {:<7} {:>12} {:>12} {:>12} {:>12}\n", "column", "role", "min", "max",
                     "mean", "std");
  for (const auto& s : info.stats) {
    out << fmt::format("{:<20} {:<7} {:>12.6g} {:>12.6g} {:>12.6g} {:>12.6g}\n", Label(s.channel),
                       s.role, s.min, s.max, s.mean, s.std);
  }
  out << "\n";
  if (info.step.found) {
    const StepEvent& step = info.step.step;
    const std::string& name = data.input_channels()[static_cast<std::size_t>(step.input)].name;
    out << fmt::format(
        "step:          input '{}' at t = {:g} s ({}, sample {}): {:g} -> {:g} "
        "(size {:g})\n",
        name, step.time, data.Where(step.index), step.index, step.baseline_before, step.level_after,
        step.size);
    for (int i = 0; i < data.num_outputs(); ++i) {
      out << fmt::format("               output '{}' before the step: {:g}\n",
                         data.output_channels()[static_cast<std::size_t>(i)].name,
                         step.outputs_before[i]);
    }
  } else {
    out << fmt::format("step:          none ({})\n", info.step.error);
  }
  std::cout << out.str();
}

void Run(const InfoArgs& args) {
  PNEUMID_CHECK(args.tolerance >= 0, "--tolerance must be >= 0, got {}", args.tolerance);
  PNEUMID_CHECK(args.decimate >= 1, "--decimate must be >= 1, got {}", args.decimate);
  const std::optional<TimeWindow> window = ParseWindowOption(args.window);
  PNEUMID_CHECK(
      args.save.empty() || !args.window.empty() || args.resample >= 0 || args.decimate > 1,
      "-o/--output (--save) writes preprocessed data: give --window, --resample or --decimate");

  const LoadOptions load = ToLoadOptions(args.data);
  Dataset data = LoadDataset(args.data.path, load);
  InfoSummary info;
  info.format = load.format == DataFormat::kAuto ? DataFormatFromPath(args.data.path) : load.format;
  info.steps = ApplyPreprocessing(args, window, data);
  if (!args.save.empty()) SaveDataset(data, args.save);
  info.sampling = SummarizeSampling(args, data);
  info.stats = ChannelSummaries(data);
  info.step = FindStep(data);
  if (args.json) {
    PrintJson(args, data, info);
  } else {
    PrintText(args, data, info);
  }
}

static Registrar reg(
    "info", "Validate a data file and print its summary (samples, sample time, ranges, step)",
    [](CLI::App& app) {
      auto o = std::make_shared<InfoArgs>();
      AddDataOptions(app, o->data);
      app.add_flag("--json", o->json, "Print the summary as JSON");
      app.add_option("--tolerance", o->tolerance,
                     "Relative tolerance of uniform sampling (fraction of the median interval)")
          ->capture_default_str()
          ->check(NonNegative());
      app.add_flag("--strict", o->strict, "Exit with an error when the sampling is not uniform");
      app.add_option("--window", o->window,
                     "Keep only samples with T0 <= t <= T1 (seconds), written T0,T1 or T0:T1")
          ->delimiter(',')
          ->expected(1, 2);
      app.add_option("--resample", o->resample,
                     "Resample to a uniform grid with this sample time in s (0: the median "
                     "interval), by linear interpolation")
          ->check(NonNegative());
      app.add_option("--decimate", o->decimate,
                     "Keep every Q-th sample after a zero-phase anti-alias low-pass")
          ->check(AtLeast(1));
      app.add_option("-o,--output,--save", o->save,
                     "Write the preprocessed data to this file (.csv .tsv .txt .dat or .mat)");
      app.footer(
          "Errors (NaN/Inf, non-numeric cells, ragged rows, time not increasing, unknown\n"
          "columns, empty files) end with a message naming file, line and column, exit 1.");
      app.callback([o] { Run(*o); });
    });

}  // namespace
}  // namespace pneumid::cli
