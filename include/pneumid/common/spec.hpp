// One parser for the `kind:key=value,key=value` specs of every area: model
// specs (lti/model_io.hpp, models/model_file.hpp), signals (plant/signal.hpp), plants
// (plant/plant_factory.hpp) and command-line values such as --load-step.
//
// Grammar:
//   spec   = [kind ":"] [head ","] item {"," item}
//   item   = key "=" value | number-list
// Values of list keys are separated by spaces, ';' or ','. A bare list of
// numbers after key=value continues the previous key's list, so
// `tf:num=1,den=1,-1` reads den = [1, -1] like `tf:num=1,den=1 -1`. Where that
// is ambiguous (a bare value after a key that takes one number, or a bare
// word), the error says how to write it. `head` is a positional first item
// (the path of `file:PATH,col=u`) for kinds that take one.
//
// Fields are consumed by Number/List/Text; Finish() then rejects the keys no
// one asked for, listing the keys the kind reads. Every error is an
// InvalidArgument that starts with `what 'spec':`, e.g.
//   signal 'step:to=x': key 'to': not a finite number: 'x'
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace pneumid {

/// The numbers of a list separated by spaces, ';' or ',' ("1 -0.8", "1,-0.8").
/// @throws InvalidArgument "<what>: value 2 is not a finite number: 'x' (in '1,x')"
///         or "<what>: no values" for an empty list.
std::vector<double> ParseNumberList(std::string_view what, std::string_view text);

/// A parsed `kind:key=value,...` spec whose fields are consumed by Number, List, Text
/// and checked by Finish (grammar above).
class Spec {
 public:
  /// How the text is split into kind, head and items.
  struct Options {
    /// Text before the first ':' is the kind (lower-cased); without ':' the
    /// whole text is the kind. When false the whole text is the body.
    bool has_kind = true;
    /// The first item of the body is a positional value (no '=' needed).
    bool has_head = false;
  };

  /// `what` names the spec in messages ("signal", "model spec", "--load-step").
  /// @throws InvalidArgument for an item that is not key=value, a key given
  ///         twice or an empty key.
  Spec(std::string what, std::string_view text, Options options);
  /// As above with the default Options (a kind before ':', no head).
  Spec(std::string what, std::string_view text) : Spec(std::move(what), text, Options{}) {}

  const std::string& text() const { return text_; }  ///< the whole spec, trimmed
  /// Text before the first ':', trimmed and lower-cased (empty without has_kind).
  const std::string& kind() const { return kind_; }
  /// The positional first item (has_head), e.g. the path of `file:PATH`; else empty.
  const std::string& head() const { return head_; }
  /// "what 'text'", the prefix of every message about this spec.
  std::string Context() const;

  /// True when `key` was given; records the key as one the kind reads (for Finish's list).
  bool Has(const std::string& key);
  /// A finite number. @throws InvalidArgument when missing or not a number.
  double Number(const std::string& key);
  /// The finite number of `key`, or `fallback` when the key is absent.
  /// @throws InvalidArgument when present but not a finite number.
  double Number(const std::string& key, double fallback);
  /// Like Number but accepting +-inf (bounds such as min=, max=).
  double Bound(const std::string& key, double fallback);
  /// A list of finite numbers (at least one). @throws when missing or empty.
  std::vector<double> List(const std::string& key);
  /// The raw text of a value (trimmed).
  std::string Text(const std::string& key);
  /// The raw text of `key` (trimmed), or `fallback` when the key is absent.
  std::string Text(const std::string& key, const std::string& fallback);
  /// @throws InvalidArgument naming the first key that was given but never
  ///         read, and listing the keys that were read.
  void Finish() const;

 private:
  struct Field {
    std::string key;
    std::string value;
    bool continued = false;  ///< bare values were appended after a comma
  };
  Field* Find(const std::string& key);
  const std::string& Take(const std::string& key);
  double ParseScalar(const Field& f, bool allow_infinite) const;

  std::string what_;
  std::string text_;
  std::string kind_;
  std::string head_;
  std::vector<Field> fields_;
  std::vector<std::string> read_;  ///< keys asked for, in order
  std::vector<std::string> used_;  ///< keys given and consumed
};

}  // namespace pneumid
