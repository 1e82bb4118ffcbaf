#pragma once
// CLI11 checks of numeric options shared by the subcommands. CLI11's PositiveNumber,
// NonNegativeNumber and Range let NaN through (every comparison with NaN is false) and the first two
// infinity too; these refuse both, so a bad number is a usage error (exit 2) naming the option.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <cmath>
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

}  // namespace bodyfit::cli
