// Validators of numeric command-line flags, with messages that name the flag
// and the value ("--w-min: must be > 0, got -1"): CLI11's own ranges print
// their numeric limits instead (2.22507e-308 to 1.79769e+308).
//
//   app.add_option("--duration", o.duration, "...")->check(Positive());
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace pneumid::cli {

/// A finite number > 0.
CLI::Validator Positive();
/// A finite number >= 0.
CLI::Validator NonNegative();
/// A number in [lo, hi].
CLI::Validator InRange(double lo, double hi);
/// An integer >= `min`.
CLI::Validator AtLeast(long long min);

}  // namespace pneumid::cli
