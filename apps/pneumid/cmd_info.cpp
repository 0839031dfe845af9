// pneumid info DATA: validate a data file and print its summary.
#include <cmath>
#include <iostream>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "data_options.hpp"
#include "validators.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/strings.hpp"
#include "pneumid/data/load.hpp"
#include "pneumid/data/preprocess.hpp"

namespace pneumid::cli {
namespace {

struct InfoArgs {
  DataOptions data;
  bool json = false;
  bool strict = false;
  double tolerance = 1e-3;
  std::vector<std::string> window;  // T0,T1 (or T0 T1), or T0:T1 as the other commands
  double resample = -1.0;  // < 0: off; 0: at the median interval
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

void Run(const InfoArgs& o) {
  PNEUMID_CHECK(o.tolerance >= 0, "--tolerance must be >= 0, got {}", o.tolerance);
  PNEUMID_CHECK(o.decimate >= 1, "--decimate must be >= 1, got {}", o.decimate);
  std::optional<TimeWindow> window;
  if (o.window.size() == 1 && o.window[0].find(':') != std::string::npos) {
    try {
      window = TimeWindow::Parse(o.window[0]);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(fmt::format("--window: {}", e.what()));
    }
  } else if (!o.window.empty()) {
    PNEUMID_CHECK(o.window.size() == 2,
                  "--window takes two times T0,T1 (or T0:T1) in seconds, got {} value(s)",
                  o.window.size());
    TimeWindow w;
    auto time = [](const std::string& text, const char* which) {
      const std::optional<double> v = ParseDouble(text);
      PNEUMID_CHECK(v.has_value(), "--window: {} must be a time in seconds, got '{}'", which,
                    text);
      return *v;
    };
    w.start = time(o.window[0], "T0");
    w.end = time(o.window[1], "T1");
    std::string why;
    PNEUMID_CHECK(w.IsValid(&why), "--window: {}", why);
    window = w;
  }
  PNEUMID_CHECK(o.save.empty() || !o.window.empty() || o.resample >= 0 || o.decimate > 1,
                "-o/--output (--save) writes preprocessed data: give --window, --resample or --decimate");

  const LoadOptions load = ToLoadOptions(o.data);
  Dataset data = LoadDataset(o.data.path, load);
  const DataFormat format =
      load.format == DataFormat::kAuto ? DataFormatFromPath(o.data.path) : load.format;

  std::vector<std::string> steps;  // preprocessing applied, in order
  if (window) {
    data = SelectWindow(data, window->start, window->end);
    steps.push_back(fmt::format("window [{:g}, {:g}] s", window->start, window->end));
  }
  if (o.resample >= 0) {
    data.RequireSamples(2, "resampling");
    const double Ts = o.resample > 0 ? o.resample : data.MedianSampleInterval();
    data = Resample(data, Ts);
    steps.push_back(fmt::format("resampled to Ts = {:g} s (linear interpolation)", Ts));
  }
  if (o.decimate > 1) {
    DecimateOptions d;
    d.uniform_tolerance = o.tolerance;
    data = Decimate(data, o.decimate, d);
    steps.push_back(fmt::format("decimated by {} (zero-phase Butterworth order {} anti-alias)",
                                o.decimate, d.order));
  }
  if (!o.save.empty()) SaveDataset(data, o.save);

  const Eigen::Index n = data.size();
  const bool enough = n >= 2;
  const double Ts = enough ? data.SampleTime() : 0.0;
  const double Tnom = enough ? data.MedianSampleInterval() : 0.0;
  const bool uniform = data.IsUniform(o.tolerance);
  std::string uniform_error;  // the first irregular interval, "file:line: ..."
  if (!uniform) {
    try {
      data.RequireUniform(o.tolerance);
    } catch (const DataError& e) {
      uniform_error = e.what();
    }
    if (o.strict) throw DataError(uniform_error);
  }
  std::string first_gap;
  if (!uniform) {
    for (Eigen::Index i = 1; i < n; ++i) {
      const double dt = data.time()[i] - data.time()[i - 1];
      if (std::abs(dt - Tnom) > o.tolerance * Tnom) {
        first_gap = fmt::format("{}: interval {:g} s between t = {:g} and {:g} s", data.Where(i),
                                dt, data.time()[i - 1], data.time()[i]);
        break;
      }
    }
  }
  double min_dt = 0.0, max_dt = 0.0;
  if (enough) {
    const Eigen::VectorXd dt = data.time().tail(n - 1) - data.time().head(n - 1);
    min_dt = dt.minCoeff();
    max_dt = dt.maxCoeff();
  }
  const std::string resample_hint =
      fmt::format("pneumid info {} --resample {:g} -o {}", o.data.path, Tnom,
                  o.data.path.substr(0, o.data.path.find_last_of('.')) + "_uniform.csv");

  std::vector<ChannelStats> stats;
  stats.push_back(Stats(data.time_channel(), "time", data.time()));
  for (int i = 0; i < data.num_inputs(); ++i) {
    stats.push_back(Stats(data.input_channels()[static_cast<std::size_t>(i)], "input", data.u(i)));
  }
  for (int i = 0; i < data.num_outputs(); ++i) {
    stats.push_back(
        Stats(data.output_channels()[static_cast<std::size_t>(i)], "output", data.y(i)));
  }

  bool has_step = false;
  StepEvent step;
  std::string step_error;
  if (data.num_inputs() == 0) {
    step_error = "no input channel";
  } else {
    try {
      step = DetectStep(data);
      has_step = true;
    } catch (const DataError& e) {
      step_error = e.what();
    }
  }

  if (o.json) {
    nlohmann::json j;
    j["file"] = o.data.path;
    j["format"] = ToString(format);
    j["samples"] = n;
    j["start_time"] = data.time()[0];
    j["end_time"] = data.time()[n - 1];
    j["sample_time"] = Ts;
    j["median_sample_interval"] = Tnom;
    j["min_sample_interval"] = min_dt;
    j["max_sample_interval"] = max_dt;
    j["uniform"] = uniform;
    j["uniform_tolerance"] = o.tolerance;
    if (!uniform) {
      j["first_irregular_interval"] = first_gap;
      j["resample_hint"] = resample_hint;
    }
    j["preprocessing"] = steps;
    if (!o.save.empty()) j["saved"] = o.save;
    j["channels"] = nlohmann::json::array();
    for (const auto& s : stats) {
      j["channels"].push_back({{"name", s.channel.name},
                               {"unit", s.channel.unit},
                               {"role", s.role},
                               {"min", s.min},
                               {"max", s.max},
                               {"mean", s.mean},
                               {"std", s.std}});
    }
    if (has_step) {
      const std::string& name = data.input_channels()[static_cast<std::size_t>(step.input)].name;
      nlohmann::json js = {{"input", name},
                           {"index", step.index},
                           {"time", step.time},
                           {"size", step.size},
                           {"baseline_before", step.baseline_before},
                           {"level_after", step.level_after}};
      if (const long line = data.SourceLine(step.index); line > 0) js["line"] = line;
      js["outputs_before"] = std::vector<double>(
          step.outputs_before.data(), step.outputs_before.data() + step.outputs_before.size());
      js["significance"] =
          std::isfinite(step.significance) ? nlohmann::json(step.significance) : nlohmann::json();
      j["step"] = js;
    } else {
      j["step"] = nullptr;
      j["step_error"] = step_error;
    }
    std::cout << j.dump(2) << "\n";
  } else {
    std::ostringstream out;
    out << fmt::format("file:          {} ({})\n", o.data.path, ToString(format));
    for (const auto& s : steps) out << fmt::format("preprocessed:  {}\n", s);
    if (!o.save.empty()) out << fmt::format("saved:         {}\n", o.save);
    out << fmt::format("samples:       {}\n", n);
    out << fmt::format("time:          {:g} .. {:g} s (duration {:g} s)\n", data.time()[0],
                       data.time()[n - 1], data.time()[n - 1] - data.time()[0]);
    if (enough) {
      out << fmt::format(
          "sample time:   {:g} s (mean interval; median {:g} s, range {:g} .. {:g} s)\n", Ts, Tnom,
          min_dt, max_dt);
    }
    out << fmt::format("uniform:       {} (tolerance {:g} %)\n", uniform ? "yes" : "no",
                       100.0 * o.tolerance);
    if (!uniform) {
      out << fmt::format("               first irregular interval: {}\n", first_gap);
      out << fmt::format("               resample to a uniform grid with:\n                 {}\n",
                         resample_hint);
    }
    out << fmt::format("\n{:<20} {:<7} {:>12} {:>12} {:>12} {:>12}\n", "column", "role", "min",
                       "max", "mean", "std");
    for (const auto& s : stats) {
      out << fmt::format("{:<20} {:<7} {:>12.6g} {:>12.6g} {:>12.6g} {:>12.6g}\n", Label(s.channel),
                         s.role, s.min, s.max, s.mean, s.std);
    }
    out << "\n";
    if (has_step) {
      const std::string& name = data.input_channels()[static_cast<std::size_t>(step.input)].name;
      out << fmt::format(
          "step:          input '{}' at t = {:g} s ({}, sample {}): {:g} -> {:g} "
          "(size {:g})\n",
          name, step.time, data.Where(step.index), step.index, step.baseline_before,
          step.level_after, step.size);
      for (int i = 0; i < data.num_outputs(); ++i) {
        out << fmt::format("               output '{}' before the step: {:g}\n",
                           data.output_channels()[static_cast<std::size_t>(i)].name,
                           step.outputs_before[i]);
      }
    } else {
      out << fmt::format("step:          none ({})\n", step_error);
    }
    std::cout << out.str();
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
