#include "validators.hpp"

#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"

namespace pneumid::cli {
namespace {

// The number in `text`, or NaN when it is not one.
double Number(const std::string& text) {
  double v = 0.0;
  return CLI::detail::lexical_cast(text, v) ? v : std::nan("");
}

}  // namespace

CLI::Validator Positive() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const double v = Number(text);
        return std::isfinite(v) && v > 0.0 ? "" : fmt::format("must be > 0, got {}", text);
      },
      "POSITIVE");
}

CLI::Validator NonNegative() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const double v = Number(text);
        return std::isfinite(v) && v >= 0.0 ? "" : fmt::format("must be >= 0, got {}", text);
      },
      "NONNEGATIVE");
}

CLI::Validator InRange(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        const double v = Number(text);
        return v >= lo && v <= hi ? ""
                                  : fmt::format("must be in [{:g}, {:g}], got {}", lo, hi, text);
      },
      fmt::format("{:g}..{:g}", lo, hi));
}

CLI::Validator AtLeast(long long min) {
  return CLI::Validator(
      [min](std::string& text) -> std::string {
        long long v = 0;
        return CLI::detail::lexical_cast(text, v) && v >= min
                   ? ""
                   : fmt::format("must be an integer >= {}, got {}", min, text);
      },
      fmt::format(">={}", min));
}

CLI::Validator NameOf(std::function<void(const std::string&)> parse) {
  return CLI::Validator(
      [parse = std::move(parse)](std::string& text) -> std::string {
        try {
          parse(text);
          return "";
        } catch (const InvalidArgument& e) {
          return e.what();
        }
      },
      "NAME");
}

CLI::Option* AddSampleTimeOption(CLI::App& app, double& Ts, const std::string& help,
                                 bool period_alias, double lo, double hi) {
  return app
      .add_option(period_alias ? "--Ts,--period,--sample-time" : "--Ts,--sample-time", Ts, help)
      ->capture_default_str()
      ->check(hi > 0.0 ? InRange(lo, hi) : Positive());
}

}  // namespace pneumid::cli
