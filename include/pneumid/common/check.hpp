// Argument checks at the API boundary, after Drake's common/drake_throw.h.
//
// A bad argument throws pneumid::InvalidArgument with a message that states
// the violated condition and the offending values; numerical failure is never
// thrown but reported in a Summary (see the Options/Summary structs of each
// area). Errors in input files throw pneumid::DataError, whose message names
// the file, line and column.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

#include <fmt/format.h>

namespace pneumid {

/// A function argument or option violates its documented precondition.
class InvalidArgument : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Input data (a file, a column, a sample) cannot be used. The message names
/// where the problem is: "data.csv:12: column 'y': not a number: 'abc'".
class DataError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Work stopped on request (a stop flag an options struct carries, e.g. a
/// server whose client went away); nothing is wrong with the arguments.
class Cancelled : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// User data quoted in an error message, bounded in length: `text` itself when
/// it has at most `max_chars` bytes, otherwise its first `max_chars` bytes (cut
/// at a character boundary) followed by "... (N bytes)". Control characters and
/// bytes that are not valid UTF-8 are written as `\\xHH` so that a binary file
/// cannot garble the terminal. Use it wherever a cell, a line, a name or a value
/// from a file or the command line is echoed into an exception.
std::string Excerpt(std::string_view text, std::size_t max_chars = 40);

/// Length in bytes of the valid UTF-8 sequence starting at text[i] (1 to 4), or
/// 0 when the bytes there are not valid UTF-8 (overlong forms, surrogates and
/// code points above U+10FFFF are invalid).
std::size_t Utf8SequenceLength(std::string_view text, std::size_t i);

/// True when `text` is valid UTF-8; otherwise *first_bad (if not null) is the
/// offset of the first invalid byte.
bool IsValidUtf8(std::string_view text, std::size_t* first_bad = nullptr);

namespace internal {
[[noreturn]] void ThrowInvalidArgument(const char* condition, const char* file, int line,
                                       const std::string& message);
}  // namespace internal

}  // namespace pneumid

/// Throws pneumid::InvalidArgument unless `condition` holds. The remaining
/// arguments are an fmt format string and its values, e.g.
///   PNEUMID_CHECK(Ts > 0, "sample time must be positive, got Ts = {}", Ts);
#define PNEUMID_CHECK(condition, ...)                                           \
  do {                                                                          \
    if (!(condition)) {                                                         \
      ::pneumid::internal::ThrowInvalidArgument(#condition, __FILE__, __LINE__, \
                                                ::fmt::format(__VA_ARGS__));    \
    }                                                                           \
  } while (0)
