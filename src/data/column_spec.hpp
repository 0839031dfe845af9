// Column names and column selection shared by the CSV and MAT readers.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace pneumid::internal {

/// A header cell: the text as written ("F [N]"), the name ("F") and unit ("N").
struct ColumnName {
  std::string label;
  std::string name;
  std::string unit;
};

/// Splits "F [N]" or "F (N)" into name and unit; other labels have no unit.
ColumnName ParseColumnName(const std::string& label);

/// True when `s` is a non-negative decimal integer ("0", "12").
bool IsIndex(const std::string& s, std::size_t* value);

/// The 0-based column selected by `spec`: a label, a name, or an index written
/// as a string. Throws DataError "`where`: unknown <role> column 'x'; available
/// columns: ..." when nothing matches.
std::size_t ResolveColumn(const std::string& spec, const std::vector<ColumnName>& columns,
                          const std::string& where, const std::string& role);

/// At most this many columns are named in an error message.
inline constexpr std::size_t kMaxListedColumns = 20;

/// "'t', 'u', 'y'" (quoted names, each cut to a short excerpt, unnamed columns
/// as their index); after kMaxListedColumns names, "... (N columns in all)".
std::string ListColumns(const std::vector<ColumnName>& columns);

}  // namespace pneumid::internal
