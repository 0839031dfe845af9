// ARX estimation from a delimited text file too large for memory: the file is
// read block by block through the data area (ReadCsvBlocks, data/csv.hpp) and
// each block's regression rows are folded into the triangular factor of
// arx.hpp (ArxAccumulator), so memory is constant in the number of samples and
// the estimate equals the in-memory fit on the same data.
//
// File format: that of ReadCsv (a header row of column names, one sample per
// line, comments after '#', the same checks and error messages). Columns are
// chosen by header name or 0-based index.
#pragma once

#include <functional>
#include <string>

#include "pneumid/identify/parametric/arx.hpp"

namespace pneumid {

/// File columns, sample time and block size of EstimateArxFromFile.
struct StreamingArxOptions {
  ArxOptions arx;  ///< orders (SISO: one nb, one nk)
  std::string input_column = "u";   ///< input column: header name or 0-based index
  std::string output_column = "y";  ///< output column: header name or 0-based index
  /// Time column used to find the sample time when sample_time is 0.
  std::string time_column = "t";
  double sample_time = 0.0;  ///< seconds; 0 = from the first two time values
  char delimiter = '\0';     ///< '\0' = detect (CsvReadOptions::delimiter)
  /// Samples per block handed to the estimator (>= 1); memory grows with it.
  std::size_t block_rows = 1 << 16;
  /// Called after each block with the fraction of the file read (0..1].
  std::function<void(double)> progress;
  /// True when `arx` is valid and single-input, sample_time >= 0, block_rows >= 1 and the
  /// column names are not empty; otherwise false with the reason in *error (when not null).
  bool IsValid(std::string* error) const;
};

/// ARX fit of a streamed file with the amount of data read.
struct StreamingArxResult {
  ArxResult arx;  ///< model and summary, equal to the in-memory fit of the same data
  long long num_samples = 0;  ///< samples (data rows) read
  double bytes = 0.0;         ///< file size
};

/// Streams `path` through the ARX estimator.
/// @throws InvalidArgument for invalid options.
/// @throws DataError naming file, line and column for unreadable files, missing
///         columns and fields that are not numbers.
StreamingArxResult EstimateArxFromFile(const std::string& path, const StreamingArxOptions& options);

}  // namespace pneumid
