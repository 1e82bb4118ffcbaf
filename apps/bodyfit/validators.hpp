#pragma once
// CLI11 checks of numeric options shared by the subcommands. CLI11's PositiveNumber,
// NonNegativeNumber and Range let NaN through (every comparison with NaN is false) and the first two
// infinity too; these refuse both, so a bad number is a usage error (exit 2) naming the option.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

namespace bodyfit::cli {

/// A finite number in [low, high], or (low, high] when `low_exclusive`; an infinite bound is open.
inline CLI::Validator finite_in(double low, double high, bool low_exclusive = false) {
  std::string what = "a finite number";
  if (std::isfinite(low) && std::isfinite(high))
    what = fmt::format("a number in {}{}, {}]", low_exclusive ? '(' : '[', low, high);
  else if (std::isfinite(low))
    what = fmt::format("a finite number {} {}", low_exclusive ? ">" : "≥", low);
  return CLI::Validator(
      [=](std::string& input) -> std::string {
        double value = 0;
        if (!CLI::detail::lexical_cast(input, value) || !std::isfinite(value) ||
            (low_exclusive ? value <= low : value < low) || value > high)
          return "'" + input + "' is not " + what;
        return {};
      },
      what);
}
inline CLI::Validator finite_above(double low) {
  return finite_in(low, std::numeric_limits<double>::infinity(), true);
}
inline CLI::Validator finite_at_least(double low) { return finite_in(low, std::numeric_limits<double>::infinity()); }
inline CLI::Validator finite() {
  const double inf = std::numeric_limits<double>::infinity();
  return finite_in(-inf, inf);
}

/// A whole number in [0, high], written in decimal digits: CLI11 reads "-5" into an unsigned option
/// as 2^64 − 5 (a "no limit" or a seed TOML cannot hold), and "1e3" as an error without a reason.
inline CLI::Validator count(std::uint64_t high = std::numeric_limits<std::int64_t>::max()) {
  const std::string what = fmt::format("a whole number in [0, {}]", high);
  return CLI::Validator(
      [=](std::string& input) -> std::string {
        std::uint64_t value = 0;
        const char* first = input.data() + (input.starts_with('+') ? 1 : 0);
        const auto [end, error] = std::from_chars(first, input.data() + input.size(), value);
        if (input.empty() || error != std::errc() || end != input.data() + input.size() || value > high)
          return "'" + input + "' is not " + what;
        return {};
      },
      what);
}

}  // namespace bodyfit::cli
