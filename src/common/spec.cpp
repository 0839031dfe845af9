#include "pneumid/common/spec.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/strings.hpp"

namespace pneumid {
namespace {

// Tokens of a list value: separated by blanks, ';' or ','.
std::vector<std::string_view> ListTokens(std::string_view value) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  const auto separator = [](char c) {
    return c == ' ' || c == '\t' || c == ';' || c == ',' || c == '\r' || c == '\n';
  };
  while (i < value.size()) {
    while (i < value.size() && separator(value[i])) ++i;
    std::size_t j = i;
    while (j < value.size() && !separator(value[j])) ++j;
    if (j > i) out.push_back(value.substr(i, j - i));
    i = j;
  }
  return out;
}

bool IsNumberList(std::string_view item) {
  const auto tokens = ListTokens(item);
  if (tokens.empty()) return false;
  return std::all_of(tokens.begin(), tokens.end(),
                     [](std::string_view t) { return ParseDouble(t).has_value(); });
}

}  // namespace

std::vector<double> ParseNumberList(std::string_view what, std::string_view text) {
  std::vector<double> out;
  for (std::string_view token : ListTokens(text)) {
    const auto v = ParseDouble(token);
    PNEUMID_CHECK(v && std::isfinite(*v), "{}: value {} is not a finite number: '{}' (in '{}')",
                  what, out.size() + 1, token, Trim(text));
    out.push_back(*v);
  }
  PNEUMID_CHECK(!out.empty(), "{}: no values", what);
  return out;
}

Spec::Spec(std::string what, std::string_view text_in, Options options)
    : what_(std::move(what)), text_(Trim(text_in)) {
  std::string_view body = text_;
  if (options.has_kind) {
    const std::size_t colon = body.find(':');
    kind_ = ToLower(Trim(body.substr(0, colon)));
    body = colon == std::string_view::npos ? std::string_view() : body.substr(colon + 1);
  }
  std::vector<std::string> items = Split(body, ',');
  std::size_t first = 0;
  if (options.has_head && !items.empty()) {
    head_ = items[0];
    first = 1;
  }
  for (std::size_t i = first; i < items.size(); ++i) {
    const std::string& item = items[i];
    if (item.empty()) continue;
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos) {
      PNEUMID_CHECK(!fields_.empty() && IsNumberList(item), "{}: expected key=value, got '{}'{}",
                    Context(), item,
                    fields_.empty() ? ""
                                    : " (values of a list may follow its key=: 'levels=0,1,2' "
                                      "or 'levels=0 1 2')");
      fields_.back().value += "," + item;
      fields_.back().continued = true;
      continue;
    }
    Field f{std::string(Trim(std::string_view(item).substr(0, eq))),
            std::string(Trim(std::string_view(item).substr(eq + 1))), false};
    PNEUMID_CHECK(!f.key.empty(), "{}: empty key in '{}'", Context(), item);
    PNEUMID_CHECK(Find(f.key) == nullptr, "{}: key '{}' given twice", Context(), f.key);
    fields_.push_back(std::move(f));
  }
}

std::string Spec::Context() const { return fmt::format("{} '{}'", what_, text_); }

Spec::Field* Spec::Find(const std::string& key) {
  for (Field& f : fields_) {
    if (f.key == key) return &f;
  }
  return nullptr;
}

bool Spec::Has(const std::string& key) {
  if (std::find(read_.begin(), read_.end(), key) == read_.end()) read_.push_back(key);
  return Find(key) != nullptr;
}

const std::string& Spec::Take(const std::string& key) {
  const Field* f = Has(key) ? Find(key) : nullptr;
  PNEUMID_CHECK(f != nullptr, "{}: missing key '{}' ({}needs '{}=')", Context(), key,
                kind_.empty() ? "" : kind_ + " ", key);
  if (std::find(used_.begin(), used_.end(), key) == used_.end()) used_.push_back(key);
  return f->value;
}

double Spec::ParseScalar(const Field& f, bool allow_infinite) const {
  PNEUMID_CHECK(!f.continued && ListTokens(f.value).size() <= 1,
                "{}: key '{}' takes one number, got '{}' (separate keys with ',': "
                "'{}=VALUE,KEY=VALUE')",
                Context(), f.key, f.value, f.key);
  const auto v = ParseDouble(f.value);
  PNEUMID_CHECK(v && (allow_infinite ? !std::isnan(*v) : std::isfinite(*v)),
                "{}: key '{}': not a finite number: '{}'", Context(), f.key, f.value);
  return *v;
}

double Spec::Number(const std::string& key) {
  Take(key);
  return ParseScalar(*Find(key), false);
}

double Spec::Number(const std::string& key, double fallback) {
  return Has(key) ? Number(key) : fallback;
}

double Spec::Bound(const std::string& key, double fallback) {
  if (!Has(key)) return fallback;
  Take(key);
  return ParseScalar(*Find(key), true);
}

std::vector<double> Spec::List(const std::string& key) {
  const std::string& value = Take(key);
  PNEUMID_CHECK(!ListTokens(value).empty(), "{}: key '{}' has no values", Context(), key);
  return ParseNumberList(fmt::format("{}: key '{}'", Context(), key), value);
}

std::string Spec::Text(const std::string& key) { return Take(key); }

std::string Spec::Text(const std::string& key, const std::string& fallback) {
  return Has(key) ? Text(key) : fallback;
}

void Spec::Finish() const {
  for (const Field& f : fields_) {
    if (std::find(used_.begin(), used_.end(), f.key) != used_.end()) continue;
    PNEUMID_CHECK(false, "{}: unknown key '{}'{} (valid: {})", Context(), f.key,
                  kind_.empty() ? "" : " for " + kind_, fmt::join(read_, ", "));
  }
}

}  // namespace pneumid
