// Validators of numeric command-line flags, with messages that name the flag
// and the value ("--w-min: must be > 0, got -1"): CLI11's own ranges print
// their numeric limits instead (2.22507e-308 to 1.79769e+308).
//
//   app.add_option("--duration", o.duration, "...")->check(Positive());
#pragma once

#include <functional>
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
/// A name `parse` accepts (an enum's FromString, shared with the library
/// and the bindings); its InvalidArgument message, listing the valid names,
/// is the error.
CLI::Validator NameOf(std::function<void(const std::string&)> parse);

/// The sample time (loop period) in s of a command that runs or designs a
/// sampled loop: `--Ts` and `--sample-time` (and `--period` with
/// `period_alias`), a finite number > 0 (or in [lo, hi] when hi > 0), its
/// default shown in --help. Every such command declares it here, so the
/// names and checks agree. Returns the option (e.g. to make it required).
CLI::Option* AddSampleTimeOption(CLI::App& app, double& Ts, const std::string& help,
                                 bool period_alias = false, double lo = 0.0, double hi = 0.0);

}  // namespace pneumid::cli
