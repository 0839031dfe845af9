#include "data_options.hpp"

#include <sstream>

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

}  // namespace pneumid::cli
