#pragma once
// Checks of numeric options whose messages say what a value must be. CLI11's PositiveNumber and
// NonNegativeNumber are ranges up to the largest double, which their messages print in full.
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include <cmath>
#include <string>

namespace iesrgs::cli {

// A number greater than `bound`, or at least `bound` when `inclusive`.
inline CLI::Validator number_above(double bound, bool inclusive, const std::string& name) {
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        double value = 0;
        if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value))
          return "must be a number, got " + text;
        if (inclusive ? value >= bound : value > bound) return {};
        return fmt::format("must be {} {}, got {}", inclusive ? "at least" : "greater than", bound,
                           text);
      },
      name);
}

// A number in [0, 1]; unlike CLI::Range, which lets NaN through.
inline const CLI::Validator kUnitInterval(
    [](std::string& text) -> std::string {
      double value = 0;
      if (CLI::detail::lexical_cast(text, value) && value >= 0 && value <= 1) return {};
      return "must be a number in [0, 1], got " + text;
    },
    "IN [0, 1]");

// A path that names something: an empty one would put the outputs in the working folder.
inline const CLI::Validator kNonEmptyPath(
    [](std::string& text) -> std::string { return text.empty() ? "must not be empty" : ""; },
    "PATH");

inline const CLI::Validator kPositive = number_above(0, false, "POSITIVE");
inline const CLI::Validator kNonNegative = number_above(0, true, "NONNEGATIVE");

}  // namespace iesrgs::cli
