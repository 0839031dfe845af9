#include "data_options.hpp"

#include <sstream>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/strings.hpp"
#include "validators.hpp"

namespace pneumid::cli {
namespace {

std::vector<std::string> SplitList(const std::string& s) { return Split(s, ','); }

}  // namespace

void AddDataOptions(CLI::App& app, DataOptions& options, bool positional) {
  if (positional) {
    app.add_option("DATA", options.path, "Data file: .csv .txt .tsv .dat or .mat")
        ->required()
        ->check(CLI::ExistingFile);
  }
  app.add_option("--time-col", options.time_col,
                 "Time column (s): header name or 0-based index; for .mat a variable")
      ->capture_default_str();
  app.add_option("--input-col", options.input_col,
                 "Input column(s), comma-separated names or 0-based indices ('' for none)")
      ->capture_default_str();
  app.add_option("--output-col", options.output_col,
                 "Output column(s), comma-separated names or 0-based indices ('' for none)")
      ->capture_default_str();
  app.add_option("--Ts,--sample-time", options.sample_time,
                 "Sample time in s for data without a time column (the time column is then "
                 "not read)")
      ->check(NonNegative());
  app.add_option("--delimiter", options.delimiter,
                 "CSV delimiter: ',' ';' tab or space (default: detected from the header)");
  app.add_option("--format", options.format, "Data format: auto (from extension), csv or mat")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "csv", "mat"}));
}

LoadOptions ToLoadOptions(const DataOptions& options) {
  LoadOptions o;
  o.format = DataFormatFromString(options.format);
  o.time_column = options.time_col;
  o.input_columns = SplitList(options.input_col);
  o.output_columns = SplitList(options.output_col);
  o.sample_time = options.sample_time;
  const std::string& d = options.delimiter;
  if (d.empty()) {
    o.delimiter = '\0';
  } else if (d == "," || d == "comma") {
    o.delimiter = ',';
  } else if (d == ";" || d == "semicolon") {
    o.delimiter = ';';
  } else if (d == "tab" || d == "\\t" || d == "\t") {
    o.delimiter = '\t';
  } else if (d == "space" || d == " ") {
    o.delimiter = ' ';
  } else {
    PNEUMID_CHECK(false, "--delimiter must be ',', ';', tab or space, got '{}'", d);
  }
  return o;
}

Dataset LoadFromOptions(const DataOptions& options) {
  return LoadDataset(options.path, ToLoadOptions(options));
}

namespace {

std::string Names(const std::vector<Channel>& channels) {
  std::string out;
  for (const Channel& c : channels) out += (out.empty() ? "" : ", ") + c.name;
  return out;
}

}  // namespace

void RequireSingleInputOutput(const Dataset& data, const DataOptions& options,
                              const std::string& command) {
  const std::size_t nu = data.input_channels().size();
  const std::size_t ny = data.output_channels().size();
  PNEUMID_CHECK(nu != 0,
                "{} selects no input column (--input-col '{}'): time-series models (no input) "
                "are not available; name the input with --input-col",
                options.path, options.input_col);
  PNEUMID_CHECK(ny != 0,
                "{} selects no output column (--output-col '{}'); name the output with "
                "--output-col",
                options.path, options.output_col);
  PNEUMID_CHECK(nu == 1,
                "{} selects {} input columns ({}): pneumid {} fits and scores single-input "
                "single-output models and would use only the first; choose one input with "
                "--input-col",
                options.path, nu, Names(data.input_channels()), command);
  PNEUMID_CHECK(ny == 1,
                "{} selects {} output columns ({}): pneumid {} fits and scores "
                "single-input single-output models and would use only the first; choose one "
                "output with --output-col (one model per output)",
                options.path, ny, Names(data.output_channels()), command);
}

void AddPreprocessOptions(CLI::App& app, PreprocessArgs& args) {
  const std::string group = "Preprocessing (in this order)";
  app.add_option("--window", args.window,
                 "Keep the samples with T0 <= t <= T1 seconds, written T0:T1 (5:, :9 for one side)")
      ->group(group);
  app.add_option("--resample", args.resample,
                 "Resample onto a uniform grid of this sample time (s), linear interpolation")
      ->check(NonNegative())
      ->group(group);
  app.add_flag("--remove-initial", args.remove_initial,
               "Subtract each channel's level before the step (the operating point); the "
               "model file records it")
      ->group(group);
  app.add_option("--detrend", args.detrend,
                 "Subtract each channel's mean (constant) or least-squares line (linear)")
      ->capture_default_str()
      ->check(CLI::IsMember({"none", "constant", "mean", "linear"}))
      ->group(group);
  app.add_option("--filter", args.filter,
                 "Zero-phase Butterworth filter: lowpass:F or bandpass:F1,F2 (Hz), "
                 "optionally ,order=N (default 5)")
      ->group(group);
  app.add_option("--decimate", args.decimate,
                 "Keep every N-th sample after a zero-phase anti-alias low-pass (N >= 1)")
      ->capture_default_str()
      ->group(group);
}

PreprocessOptions ToPreprocessOptions(const PreprocessArgs& args) { return args.ToOptions(); }

}  // namespace pneumid::cli
