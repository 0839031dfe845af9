// One table of names per enum, serving ToString, FromString, the CLI and the
// Python bindings (after Ceres' include/ceres/types.h converters):
//
//   inline constexpr EnumName<IpaMode> kIpaModeNames[] = {
//       {IpaMode::kForce, "force"}, {IpaMode::kPosition, "position"}};
//   std::string ToString(IpaMode m) { return std::string(EnumToString(kIpaModeNames, m)); }
//   IpaMode IpaModeFromString(const std::string& s) {
//     return EnumFromString(kIpaModeNames, s, "IPA mode");
//   }
//
// A value may appear more than once: the first name is the one written, the
// others are accepted aliases.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"

namespace pneumid {

/// One entry of an enum's name table: a value and one of its names.
template <typename E>
struct EnumName {
  E value;                ///< the enumerator
  std::string_view name;  ///< its spelling in files, the CLI and Python (first entry = written)
};

/// The first name of `value` in `table`, or "unknown" for a value not listed.
template <typename E, std::size_t N>
constexpr std::string_view EnumToString(const EnumName<E> (&table)[N], E value) {
  for (const EnumName<E>& e : table) {
    if (e.value == value) return e.name;
  }
  return "unknown";
}

/// The names of `table` separated by ", " (aliases included), for messages and --help.
template <typename E, std::size_t N>
std::string EnumNameList(const EnumName<E> (&table)[N]) {
  std::string out;
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) out += ", ";
    out += table[i].name;
  }
  return out;
}

/// The value named `name` (exact match, or ASCII case-insensitive when
/// `ignore_case`), or std::nullopt.
template <typename E, std::size_t N>
constexpr std::optional<E> EnumLookup(const EnumName<E> (&table)[N], std::string_view name,
                                      bool ignore_case = false) {
  const auto lower = [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c + 32) : c; };
  for (const EnumName<E>& e : table) {
    if (e.name.size() != name.size()) continue;
    bool same = true;
    for (std::size_t i = 0; same && i < name.size(); ++i) {
      same = ignore_case ? lower(e.name[i]) == lower(name[i]) : e.name[i] == name[i];
    }
    if (same) return e.value;
  }
  return std::nullopt;
}

/// As EnumLookup. @throws InvalidArgument "unknown <what> 'name' (valid: ...)".
template <typename E, std::size_t N>
E EnumFromString(const EnumName<E> (&table)[N], std::string_view name, std::string_view what,
                 bool ignore_case = false) {
  if (const std::optional<E> e = EnumLookup(table, name, ignore_case)) return *e;
  const std::string_view shown = name.size() > 64 ? name.substr(0, 64) : name;
  throw InvalidArgument(fmt::format("unknown {} '{}{}' (valid: {})", what, shown,
                                    shown.size() < name.size() ? "..." : "", EnumNameList(table)));
}

}  // namespace pneumid
