#pragma once

// Validators for numeric options whose messages a user can read: CLI11 2.1's PositiveNumber and
// NonNegativeNumber are ranges up to the largest double and print all of its 309 digits.

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdlib>
#include <string>

namespace uwscan::app {

namespace internal {

// "" when `text` is a whole finite number that `accept` takes, else what was expected.
template <typename Accept>
std::string CheckNumber(const std::string& text, const char* expected, Accept accept) {
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(text.c_str(), &end);
  const bool number = !text.empty() && end == text.c_str() + text.size() && errno == 0;
  if (number && accept(value)) return "";
  return std::string("expected a number ") + expected + ", got '" + text + "'";
}

}  // namespace internal

inline const CLI::Validator kPositiveNumber(
    [](std::string& text) {
      return internal::CheckNumber(text, "> 0", [](double v) { return v > 0.0; });
    },
    "POSITIVE", "POSITIVE");
inline const CLI::Validator kNonNegativeNumber(
    [](std::string& text) {
      return internal::CheckNumber(text, ">= 0", [](double v) { return v >= 0.0; });
    },
    "NONNEGATIVE", "NONNEGATIVE");

// A length in metres that an object a vehicle inspects or grasps can have: over 0.1 mm and at
// most 50 m. A size given in millimetres (--length-m 300 for a 0.3 m pipe) is refused instead of
// building an object a thousand times too large.
inline const CLI::Validator kObjectLengthMetres(
    [](std::string& text) {
      const std::string wrong = internal::CheckNumber(
          text, "of metres in (0.0001, 50]", [](double v) { return v > 1e-4 && v <= 50.0; });
      return wrong.empty() ? wrong : wrong + " (lengths are in metres)";
    },
    "METRES", "METRES");

}  // namespace uwscan::app
