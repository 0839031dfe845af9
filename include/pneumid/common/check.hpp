// Argument checks at the API boundary, after Drake's common/drake_throw.h.
//
// A bad argument throws pneumid::InvalidArgument with a message that states
// the violated condition and the offending values; numerical failure is never
// thrown but reported in a Summary (see the Options/Summary structs of each
// area). Errors in input files throw pneumid::DataError, whose message names
// the file, line and column.
#pragma once

#include <stdexcept>
#include <string>

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

namespace internal {
[[noreturn]] void ThrowInvalidArgument(const char* condition, const char* file, int line,
                                       const std::string& message);
}  // namespace internal

}  // namespace pneumid

/// Throws pneumid::InvalidArgument unless `condition` holds. The remaining
/// arguments are an fmt format string and its values, e.g.
///   PNEUMID_CHECK(Ts > 0, "sample time must be positive, got Ts = {}", Ts);
#define PNEUMID_CHECK(condition, ...)                                                  \
  do {                                                                                 \
    if (!(condition)) {                                                                \
      ::pneumid::internal::ThrowInvalidArgument(#condition, __FILE__, __LINE__,        \
                                                ::fmt::format(__VA_ARGS__));           \
    }                                                                                  \
  } while (0)
