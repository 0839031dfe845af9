#include "column_spec.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/strings.hpp"

namespace pneumid::internal {

ColumnName ParseColumnName(const std::string& label) {
  ColumnName c{label, label, ""};
  if (label.size() >= 3) {
    const char close = label.back();
    const char open = close == ']' ? '[' : close == ')' ? '(' : '\0';
    if (open != '\0') {
      const auto pos = label.rfind(open);
      if (pos != std::string::npos && pos > 0) {
        const std::string_view text = label;
        std::string name(Trim(text.substr(0, pos)));
        if (!name.empty()) {
          c.name = std::move(name);
          c.unit = std::string(Trim(text.substr(pos + 1, label.size() - pos - 2)));
        }
      }
    }
  }
  return c;
}

bool IsIndex(const std::string& s, std::size_t* value) {
  if (s.empty() || s.size() > 9) return false;
  std::size_t v = 0;
  for (char ch : s) {
    if (ch < '0' || ch > '9') return false;
    v = v * 10 + static_cast<std::size_t>(ch - '0');
  }
  if (value != nullptr) *value = v;
  return true;
}

std::string ListColumns(const std::vector<ColumnName>& columns) {
  std::string out;
  const std::size_t shown = std::min(columns.size(), kMaxListedColumns);
  for (std::size_t i = 0; i < shown; ++i) {
    if (i > 0) out += ", ";
    if (columns[i].label.empty()) {
      out += fmt::format("(unnamed column {})", i);
    } else {
      out += fmt::format("'{}'", Excerpt(columns[i].label));
    }
  }
  if (shown < columns.size()) out += fmt::format(", ... ({} columns in all)", columns.size());
  return out;
}

std::size_t ResolveColumn(const std::string& spec, const std::vector<ColumnName>& columns,
                          const std::string& where, const std::string& role) {
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (columns[i].label == spec) return i;
  }
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (columns[i].name == spec) return i;
  }
  std::size_t index = 0;
  if (IsIndex(spec, &index)) {
    if (index < columns.size()) return index;
    throw DataError(
        fmt::format("{}: {} column index {} out of range: the header has {} columns ({})", where,
                    role, index, columns.size(), ListColumns(columns)));
  }
  throw DataError(fmt::format(
      "{}: unknown {} column '{}'; available columns: {} (or a 0-based index 0..{})", where, role,
      Excerpt(spec), ListColumns(columns), columns.empty() ? 0 : columns.size() - 1));
}

}  // namespace pneumid::internal
