// MATLAB .mat files (read through matio) <-> Dataset.
//
// Variables are selected by name, with the defaults t (time), u (inputs) and
// y (outputs):
//   "u"      a numeric vector (N x 1 or 1 x N), or an N x k matrix giving k
//            channels u:0 ... u:k-1
//   "u:1"    column 1 (0-based) of an N x k matrix variable u
//   "2"      column 2 of the file's only numeric matrix variable (for files
//            holding one N x k array, e.g. `data = [t u y]`)
// Numeric classes (double, single, integers) are converted to double; complex,
// sparse, cell, struct and char variables are rejected.
// Formats: MAT v5 (the matio default) and v7.3 (HDF5) when the matio build
// supports it (MatHasV73()); v4 files are read as well.
#pragma once

#include <string>
#include <vector>

#include "pneumid/data/dataset.hpp"

namespace pneumid {

/// MAT file format to write.
enum class MatVersion { kV5, kV73 };
std::string ToString(MatVersion v);  ///< "v5", "v7.3"
/// Parses "v5"/"5"/"v7.3"/"7.3"; @throws InvalidArgument otherwise.
MatVersion MatVersionFromString(const std::string& s);

/// True when the installed matio can read and write v7.3 (HDF5) files.
bool MatHasV73();

/// Variable selection and time base of ReadMat.
struct MatReadOptions {
  /// Time variable (seconds); ignored when sample_time > 0.
  std::string time_variable = "t";
  /// Input variables; may be empty for output-only data.
  std::vector<std::string> input_variables = {"u"};
  /// Output variables; may be empty for input-only data.
  std::vector<std::string> output_variables = {"y"};
  /// When > 0, no time variable is read and t = start_time + k * sample_time.
  double sample_time = 0.0;
  double start_time = 0.0;  ///< first time instant in s when sample_time > 0

  /// True for sample_time >= 0, a finite start_time, a time variable or sample_time > 0,
  /// at least one input or output variable and no empty name; otherwise false with
  /// the reason in *error (when not null).
  bool IsValid(std::string* error) const;
};

/// Reads the selected variables of a .mat file into a Dataset (source() = path).
/// @throws InvalidArgument for invalid options.
/// @throws DataError naming the file and the variable: file missing or not a MAT
///         file, unknown variable (lists the available ones), unsupported class
///         (complex, sparse, cell, ...), length mismatch, NaN/Inf (with the
///         sample index), time not strictly increasing, no samples.
Dataset ReadMat(const std::string& path, const MatReadOptions& options = {});

/// File version, compression and variable names of WriteMat.
struct MatWriteOptions {
  MatVersion version = MatVersion::kV5;  ///< v7.3 needs a matio with HDF5 (MatHasV73())
  /// zlib compression of the variables (v5 and v7.3).
  bool compress = false;
  /// Variable names for time, inputs (N x nu matrix) and outputs (N x ny).
  std::string time_variable = "t";
  std::string input_variable = "u";   ///< name of the N x nu input matrix
  std::string output_variable = "y";  ///< name of the N x ny output matrix

  /// True when the three names are distinct valid MATLAB names (a letter, then
  /// letters, digits or '_', at most 63); otherwise false with the reason in *error.
  bool IsValid(std::string* error) const;
};

/// Writes the dataset as three double variables (time N x 1, inputs N x nu,
/// outputs N x ny; empty channel groups are skipped).
/// @throws DataError when the file cannot be created (for v7.3: also when matio
///         lacks HDF5 support).
void WriteMat(const Dataset& data, const std::string& path, const MatWriteOptions& options = {});

}  // namespace pneumid
