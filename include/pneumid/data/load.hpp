// Loading and saving datasets by file extension.
//
//   .csv .txt .tsv .dat  -> ReadCsv / WriteCsv (pneumid/data/csv.hpp)
//   .mat                 -> ReadMat / WriteMat (pneumid/data/matfile.hpp)
// One set of selection options serves both: `time_column`, `input_columns`,
// `output_columns` are header names / column indices for text files and
// variable names ("u", "u:1", "1") for MAT files.
#pragma once

#include <string>
#include <vector>

#include "pneumid/data/csv.hpp"
#include "pneumid/data/dataset.hpp"
#include "pneumid/data/matfile.hpp"

namespace pneumid {

/// File format of a dataset: by extension (kAuto), delimited text or MATLAB .mat.
enum class DataFormat { kAuto, kCsv, kMat };
std::string ToString(DataFormat f);  ///< "auto", "csv", "mat"
/// Parses "auto", "csv" (also "txt", "tsv", "dat") or "mat"; @throws InvalidArgument.
DataFormat DataFormatFromString(const std::string& s);
/// The format implied by the extension of `path` (case-insensitive).
/// @throws DataError naming the file when the extension is not recognized.
DataFormat DataFormatFromPath(const std::string& path);

/// Reader and column selection of LoadDataset, common to text and MAT files.
struct LoadOptions {
  /// kAuto picks the reader from the file extension.
  DataFormat format = DataFormat::kAuto;
  /// Time column / variable; not read when sample_time > 0.
  std::string time_column = "t";
  /// Input columns / variables (header names, indices or MAT names); may be empty.
  std::vector<std::string> input_columns = {"u"};
  /// Output columns / variables (header names, indices or MAT names); may be empty.
  std::vector<std::string> output_columns = {"y"};
  /// Sample time in seconds for data without a time column (0: read time).
  double sample_time = 0.0;
  double start_time = 0.0;  ///< first time instant in s when sample_time > 0
  /// CSV only: delimiter ('\0' detects it) and comment character.
  char delimiter = '\0';
  char comment = '#';  ///< CSV only: starts a comment to the end of the line ('\0': none)

  /// True when the options are valid for the reader `format` selects (for kAuto, for
  /// both readers); otherwise false with the reason in *error (when not null).
  bool IsValid(std::string* error) const;
  CsvReadOptions ToCsv() const;  ///< the same selection as ReadCsv options
  MatReadOptions ToMat() const;  ///< the same selection as ReadMat options (no CSV fields)
};

/// Reads a dataset with the reader chosen by options.format or the extension.
/// @throws InvalidArgument for invalid options; DataError for file problems
///         (the message names file, line or variable, and column).
Dataset LoadDataset(const std::string& path, const LoadOptions& options = {});

/// Writer and its options for SaveDataset.
struct SaveOptions {
  DataFormat format = DataFormat::kAuto;  ///< kAuto picks the writer from the extension
  /// Text options; with kAuto a .tsv file gets a tab when the delimiter is ','.
  CsvWriteOptions csv;
  MatWriteOptions mat;  ///< MAT options (version, compression, variable names)
};

/// Writes a dataset with the writer chosen by options.format or the extension.
/// @throws DataError when the file cannot be written or the extension is unknown.
void SaveDataset(const Dataset& data, const std::string& path, const SaveOptions& options = {});

}  // namespace pneumid
