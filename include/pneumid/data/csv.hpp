// Delimited text files (CSV, TSV, whitespace-separated .dat) <-> Dataset.
//
// File layout read by ReadCsv:
//   # comment lines (and trailing "# ..." comments) are ignored, as are blank lines
//   t,u,y                  <- header row (required): one name per column,
//   0.00,0.61,0.0             optionally with a unit as "F [N]" or "F (N)"
//   0.01,82,0.3
// The delimiter is detected from the header row (the most frequent of ',' ';'
// '\t'; runs of blanks when none of them occurs) unless set. Cells are parsed
// with std::from_chars (C locale, '.' as decimal point); surrounding blanks and
// double quotes are stripped.
//
// Validation (each a pneumid::DataError whose message starts with "file:line:"
// and names the column; quoted cells and names are cut to a short excerpt):
// UTF-16/UTF-32 or binary file (byte order mark, NUL bytes), header row too long
// or with too many columns (see the limits below), empty file, header row
// without data rows, unknown
// column name (the message lists the available ones), ragged row (cell count
// differs from the header), missing (empty) cell, non-numeric cell, NaN or Inf,
// time not strictly increasing. Non-uniform sampling is not an error here;
// check it with Dataset::RequireUniform where a method needs it.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pneumid/data/dataset.hpp"

namespace pneumid {

/// Limits that keep a malformed file from taking unbounded time or memory:
/// a header row longer than kCsvMaxHeaderBytes or with more than kCsvMaxColumns
/// columns is rejected with a DataError.
inline constexpr std::size_t kCsvMaxHeaderBytes = 1 << 20;
inline constexpr std::size_t kCsvMaxColumns = 10000;  ///< columns of a header row, at most

/// How ReadCsv and ReadCsvBlocks parse a delimited text file and pick its columns.
struct CsvReadOptions {
  /// Cell delimiter; `'\0'` detects it from the header row among comma, semicolon and tab
  /// (and runs of blanks when none of them occurs). ' ' means runs of blanks.
  char delimiter = '\0';
  /// Text from this character to the end of a line is ignored; '\0' disables.
  char comment = '#';
  /// Column holding time in seconds, by header name or by 0-based index written
  /// as a string ("0"). Ignored when sample_time > 0.
  std::string time_column = "t";
  /// Input columns (by name or index); may be empty for output-only data.
  std::vector<std::string> input_columns = {"u"};
  /// Output columns (by name or index); may be empty for input-only data.
  std::vector<std::string> output_columns = {"y"};
  /// Sample time in seconds for files without a time column: when > 0 the time
  /// column is not read and time is start_time + k * sample_time. Default 0.
  double sample_time = 0.0;
  /// First time instant in seconds when sample_time > 0. Default 0.
  double start_time = 0.0;

  /// True when the options are usable; otherwise *error (if not null) says why.
  bool IsValid(std::string* error) const;
};

/// Reads a delimited text file into a Dataset whose source() is `path` and whose
/// SourceLine() maps samples to file lines. Channel names and units come from
/// the header.
/// @throws InvalidArgument when `options` is not valid.
/// @throws DataError when the file cannot be read or its content is invalid
///         (see the list at the top of this header); the message names file,
///         line and column.
Dataset ReadCsv(const std::string& path, const CsvReadOptions& options = {});

/// Consecutive samples of a file read by ReadCsvBlocks.
struct CsvBlock {
  Eigen::Index first_sample = 0;  ///< index of the block's first sample in the file
  Eigen::VectorXd time;           ///< seconds (time column, or start_time + k sample_time)
  Eigen::MatrixXd inputs;         ///< one column per CsvReadOptions::input_columns
  Eigen::MatrixXd outputs;        ///< one column per CsvReadOptions::output_columns
  double fraction_read = 0.0;     ///< fraction of the file's bytes parsed so far, (0, 1]
};

/// Reads the file of ReadCsv (same format, same checks, same messages) and
/// hands its samples to `on_block` in blocks of at most `block_rows` samples
/// (the last block may be shorter), keeping one block in memory at a time:
/// memory does not grow with the number of rows, for files larger than memory
/// (the file is memory-mapped and read once, front to back). Returns the
/// number of samples.
/// @throws InvalidArgument when `options` is not valid or block_rows is 0.
/// @throws DataError as ReadCsv (a bad row is found when its block is read:
///         earlier blocks have been handed over by then); whatever on_block throws.
Eigen::Index ReadCsvBlocks(const std::string& path, const CsvReadOptions& options,
                           std::size_t block_rows,
                           const std::function<void(const CsvBlock&)>& on_block);

/// One extra column written by WriteCsv beside the dataset's own columns.
struct CsvColumn {
  Channel channel;         ///< header name and unit of the column ("name [unit]")
  Eigen::VectorXd values;  ///< one value per sample of the dataset
};

/// How WriteCsv formats the file.
struct CsvWriteOptions {
  /// Cell delimiter: ',' (default), ';', a tab or ' '.
  char delimiter = ',';
  /// Optional comment lines written before the header, each prefixed by "# ".
  std::vector<std::string> comments;

  /// True for a delimiter of ',', ';', tab or ' ' and comments without a newline;
  /// otherwise false with the reason in *error (when not null).
  bool IsValid(std::string* error) const;
};

/// Writes time, inputs, outputs and `extra` columns with a header row
/// ("name" or "name [unit]"). Numbers are written in the shortest form that
/// reads back to the same double, so WriteCsv + ReadCsv round-trips exactly.
/// @throws InvalidArgument when an extra column has the wrong length or the
///         options are invalid.
/// @throws DataError when the file cannot be written.
void WriteCsv(const Dataset& data, const std::string& path,
              const std::vector<CsvColumn>& extra = {}, const CsvWriteOptions& options = {});

}  // namespace pneumid
