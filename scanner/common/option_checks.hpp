#pragma once
// The one way an options struct's Check() reports a bad field (Ceres' OPTION_GE, COLMAP's
// THROW_CHECK_GE): each check throws uwscan::Error with the message
//
//   <Owner>.<field>: expected <expectation>, got <value>
//
// e.g. "StripeDetectorOptions.threshold: expected >= 1, got 0". The optional `unit` follows the
// expectation: a unit, a reason in brackets, or both ("MapperOptions.max_navigation_gap_s:
// expected a finite value > 0 s, got nan"; "... expected >= 0 (0 = OpenMP's default), got -1").
// Numbers print as integers when they are whole, else to 9 significant digits.
//
// NaN fails every numeric check. GreaterThan, AtLeast, AtMost and InRange take a
// bound as they are told (x > 0 admits +inf); Finite, Positive and NonNegative also reject
// the infinities. Integer fields convert to double exactly (below 2^53).
//
// Include this only in the .cpp files that define Check()s.

#include <string>
#include <string_view>
#include <utility>

namespace uwscan {

// Which ends of InRange's interval belong to it.
enum class Interval {
  kClosed,    // [lo, hi]
  kOpen,      // (lo, hi)
  kOpenLow,   // (lo, hi]
  kOpenHigh,  // [lo, hi)
};

class OptionChecks {
 public:
  // `owner` names the struct ("StripeDetectorOptions"); fields are named relative to it,
  // nested ones with a dot ("image.peak_level") and elements with an index ("poses[3]").
  explicit OptionChecks(std::string owner) : owner_(std::move(owner)) {}

  void GreaterThan(std::string_view field, double value, double bound,
                   std::string_view unit = {}) const;  // value > bound
  void AtLeast(std::string_view field, double value, double bound,
               std::string_view unit = {}) const;  // value >= bound
  void AtMost(std::string_view field, double value, double bound,
              std::string_view unit = {}) const;  // value <= bound
  void InRange(std::string_view field, double value, double lo, double hi,
               Interval ends = Interval::kClosed, std::string_view unit = {}) const;
  void Finite(std::string_view field, double value) const;
  void Positive(std::string_view field, double value,
                std::string_view unit = {}) const;  // finite and > 0
  void NonNegative(std::string_view field, double value,
                   std::string_view unit = {}) const;  // finite and >= 0

  // The odd cases (enums, cross-field conditions, vectors, names): throws unless `ok`, with
  // the expectation in words and, when given, what was found.
  void Require(bool ok, std::string_view field, std::string_view expected,
               std::string_view got = {}) const;
  void Require(bool ok, std::string_view field, std::string_view expected, double got) const;

  [[noreturn]] void Fail(std::string_view field, std::string_view expected,
                         std::string_view got = {}) const;

 private:
  std::string owner_;
};

// A number as the messages print it: "3", "0.25", "1e-09", "inf", "nan".
std::string OptionValueText(double value);
// Text as the messages quote it: 'Line0', '' for none.
std::string OptionQuotedText(std::string_view text);
// Two numbers as the messages print them: "[0.5, 1.2]".
std::string OptionPairText(double first, double second);

}  // namespace uwscan
