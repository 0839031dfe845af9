// Structural check of a MAT v5 file before matio reads it.
//
// matio trusts the sizes written in a file: a corrupt header that claims a
// variable of 10^9 elements makes it allocate (and loop over) that many before
// any data is read, and a truncated file shows up only as a missing variable.
// ScanMatV5 walks the element tags of a level-5 MAT file [1] and checks each
// size against the bytes that can hold it, so that both are reported as what
// they are, in time proportional to the file size.
//
// [1] The MathWorks, "MAT-File Format", Level 5 MAT-files, ch. 1
//     (data element tags, miMATRIX / miCOMPRESSED, array flags, dimensions).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace pneumid::internal {

/// Checks the structure of the MAT file `bytes` (the whole file) read from
/// `path`. Files that are not MAT v5 (v4, v7.3/HDF5) are left to matio.
/// @throws DataError naming the file and the variable (index and name when
///         known): the file ends inside a variable (truncated), an element is
///         larger than its container, a variable claims more elements than its
///         bytes can hold, or arrays are nested more than 32 deep.
void ScanMatV5(const std::string& path, std::string_view bytes);

}  // namespace pneumid::internal
