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
#include "pneumid/data/preprocess.hpp"
#include "pneumid/workflow/identify_workflow.hpp"

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

/// Checks that `data` (loaded with `options`) hold exactly one input and one
/// output column: `command` (identify, orders, validate, report, calibrate)
/// fits and scores single-input single-output models, and would otherwise
/// use the first column of each and drop the others without a word.
/// @throws InvalidArgument naming the file, the columns selected and the flag
/// that selects one.
void RequireSingleInputOutput(const Dataset& data, const DataOptions& options,
                              const std::string& command);

// Preprocessing of the loaded data (identify, validate, orders, report), in
// the order of PreprocessOptions (data/preprocess.hpp):
//   --window T0:T1       keep T0 <= t <= T1 (s; either side may be empty)
//   --resample TS        linear interpolation onto a uniform grid of TS s
//   --remove-initial     subtract the levels before the step (operating point)
//   --detrend constant|linear   subtract the mean or the least-squares line
//   --filter lowpass:F | bandpass:F1,F2   zero-phase Butterworth, Hz
//   --decimate N         keep every N-th sample after an anti-alias filter
/// The preprocessing flags as the library takes them (workflow/identify_workflow.hpp).
using PreprocessArgs = PreprocessSettings;

/// Adds the flags above to `app`.
void AddPreprocessOptions(CLI::App& app, PreprocessArgs& args);

/// The library options of `args`.
/// @throws InvalidArgument naming the flag for a malformed value.
PreprocessOptions ToPreprocessOptions(const PreprocessArgs& args);

}  // namespace pneumid::cli
