// Structural check of a MAT file (v5, v4) before matio reads it.
//
// matio trusts the sizes written in a file: a corrupt header that claims a
// variable of 10^9 elements makes it allocate (and loop over) that many before
// any data is read, and a truncated file shows up only as a missing variable.
// ScanMatFile walks the element tags of a level-5 MAT file [1] (and the
// variable headers of a level-4 file) and checks each
// size against the bytes that can hold it, so that both are reported as what
// they are, in time proportional to the file size.
//
// [1] The MathWorks, "MAT-File Format", Level 5 MAT-files, ch. 1
//     (data element tags, miMATRIX / miCOMPRESSED, array flags, dimensions).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace pneumid::internal {

/// One top-level element of a MAT v5 file, as the scan found it.
struct MatScanVariable {
  std::size_t offset = 0;  ///< of its tag, from the start of the file
  std::size_t size = 0;    ///< bytes on disk: tag, data and padding
  /// Array class (MAT-File Format table 1-3: 1 cell, 2 struct, 3 object,
  /// 4 char, 5 sparse, 6-15 numeric, 16 function, 17 opaque); 0 when the
  /// element is not an array or its flags could not be read.
  std::uint32_t array_class = 0;
  bool complex = false;
  std::string name;
  std::vector<std::size_t> dims;
};

/// What ScanMatFile found.
struct MatScan {
  bool v5 = false;  ///< a level-5 file, whose variables are listed below
  std::vector<MatScanVariable> variables;
};

/// Checks the structure of the MAT file `bytes` (the whole file) read from
/// `path`: MAT v5 element by element, MAT v4 variable by variable. v7.3
/// (HDF5) files and files that are not MAT files are left to matio.
/// @return for a v5 file, its top-level elements in file order.
/// @throws DataError naming the file and the variable (index and name when
///         known): the file ends inside a variable (truncated), an element is
///         larger than its container, a variable claims more elements than its
///         bytes can hold, or arrays are nested more than 32 deep.
MatScan ScanMatFile(const std::string& path, std::string_view bytes);

}  // namespace pneumid::internal
