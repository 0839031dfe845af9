// Small string helpers shared by the parsers of every area (specs, CSV, TOML
// values, command-line lists).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pneumid {

/// `s` without leading and trailing blanks (space, tab, CR, LF). The result
/// views `s`: keep the argument alive while the view is used.
constexpr std::string_view Trim(std::string_view s) {
  constexpr std::string_view kBlank = " \t\r\n";
  while (!s.empty() && kBlank.find(s.front()) != std::string_view::npos) s.remove_prefix(1);
  while (!s.empty() && kBlank.find(s.back()) != std::string_view::npos) s.remove_suffix(1);
  return s;
}

/// ASCII lower case of `s`.
std::string ToLower(std::string_view s);

/// Items of `s` separated by `separator`, each trimmed; "a, b,,c" -> {a, b, "", c}.
/// An empty `s` gives no items.
std::vector<std::string> Split(std::string_view s, char separator);

/// The number written in `text` (surrounding blanks and a leading '+' allowed,
/// the whole text must be the number; "inf" and "nan" are accepted: check
/// finiteness where it matters). std::nullopt when `text` is not a number.
std::optional<double> ParseDouble(std::string_view text);

/// `s` as one word of a POSIX shell command line: unchanged when it holds only
/// letters, digits and _-./=,:+ (and '#' after its first character, where the
/// shell does not read it as a comment), else in single quotes with each ' as
/// '\''. "" -> ''.
std::string ShellQuote(std::string_view s);

}  // namespace pneumid
