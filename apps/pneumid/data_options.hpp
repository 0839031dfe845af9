// Command-line options that select the data of a measurement file, shared by
// every command that reads one (info, identify, validate, report, ...):
//
//   DATA                 data file (.csv .txt .tsv .dat or .mat)
//   --time-col C         time column: header name or 0-based index (default t)
//   --input-col C[,C..]  input column(s) (default u)
//   --output-col C[,C..] output column(s) (default y)
//   --Ts TS              sample time in s for files without a time column
//                        (alias --sample-time)
//   --delimiter D        ',' ';' 'tab' 'space' (default: detected)
//   --format F           auto, csv or mat (default: from the extension)
//
// For .mat files the columns are variable names ("u"), columns of a matrix
// variable ("data:1"), or indices into the file's only matrix variable ("1").
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "pneumid/data/dataset.hpp"
#include "pneumid/data/load.hpp"

namespace pneumid::cli {

struct DataOptions {
  std::string path;
  std::string time_col = "t";
  std::string input_col = "u";
  std::string output_col = "y";
  double sample_time = 0.0;
  std::string delimiter;  ///< empty: detect
  std::string format = "auto";
};

/// Adds the flags above to `app`, storing into `options` (which must outlive
/// the parse). With `positional` the data file is the required positional
/// argument DATA; otherwise the caller adds its own option for options.path.
void AddDataOptions(CLI::App& app, DataOptions& options, bool positional = true);

/// The library options equivalent to `options` (lists split at commas).
/// @throws InvalidArgument for an unknown delimiter or format.
LoadOptions ToLoadOptions(const DataOptions& options);

/// Loads the selected data. @throws DataError / InvalidArgument as LoadDataset.
Dataset LoadFromOptions(const DataOptions& options);

}  // namespace pneumid::cli
