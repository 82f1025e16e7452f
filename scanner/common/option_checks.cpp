#include "scanner/common/option_checks.hpp"

#include <cmath>
#include <cstdio>

#include "scanner/common/error.hpp"

// Messages are appended piecewise: GCC 12 warns falsely (-Wrestrict) on "x" + std::string.
namespace uwscan {
namespace {

// `text` followed by " unit" when there is a unit.
std::string WithUnit(std::string text, std::string_view unit) {
  if (!unit.empty()) {
    text += ' ';
    text.append(unit);
  }
  return text;
}

// "> 0", "a finite value >= 0".
std::string Relation(std::string_view relation, double bound, std::string_view unit) {
  std::string text(relation);
  text += ' ';
  text += OptionValueText(bound);
  return WithUnit(std::move(text), unit);
}

}  // namespace

std::string OptionValueText(double value) {
  if (std::isnan(value)) return "nan";
  char text[32];
  std::snprintf(text, sizeof(text), "%.9g", value);
  return text;
}

std::string OptionQuotedText(std::string_view text) {
  std::string quoted = "'";
  quoted.append(text);
  quoted += '\'';
  return quoted;
}

std::string OptionPairText(double first, double second) {
  std::string text = "[";
  text += OptionValueText(first);
  text += ", ";
  text += OptionValueText(second);
  text += ']';
  return text;
}

void OptionChecks::GreaterThan(std::string_view field, double value, double bound,
                               std::string_view unit) const {
  if (!(value > bound)) Fail(field, Relation(">", bound, unit), OptionValueText(value));
}

void OptionChecks::AtLeast(std::string_view field, double value, double bound,
                           std::string_view unit) const {
  if (!(value >= bound)) Fail(field, Relation(">=", bound, unit), OptionValueText(value));
}

void OptionChecks::AtMost(std::string_view field, double value, double bound,
                          std::string_view unit) const {
  if (!(value <= bound)) Fail(field, Relation("<=", bound, unit), OptionValueText(value));
}

void OptionChecks::InRange(std::string_view field, double value, double lo, double hi,
                           Interval ends, std::string_view unit) const {
  const bool open_low = ends == Interval::kOpen || ends == Interval::kOpenLow;
  const bool open_high = ends == Interval::kOpen || ends == Interval::kOpenHigh;
  const bool above_lo = open_low ? value > lo : value >= lo;
  const bool below_hi = open_high ? value < hi : value <= hi;
  if (above_lo && below_hi) return;
  std::string expected = open_low ? "in (" : "in [";
  expected += OptionValueText(lo);
  expected += ", ";
  expected += OptionValueText(hi);
  expected += open_high ? ')' : ']';
  Fail(field, WithUnit(std::move(expected), unit), OptionValueText(value));
}

void OptionChecks::Finite(std::string_view field, double value) const {
  if (!std::isfinite(value)) Fail(field, "a finite value", OptionValueText(value));
}

void OptionChecks::Positive(std::string_view field, double value, std::string_view unit) const {
  if (!(std::isfinite(value) && value > 0.0)) {
    Fail(field, Relation("a finite value >", 0.0, unit), OptionValueText(value));
  }
}

void OptionChecks::NonNegative(std::string_view field, double value, std::string_view unit) const {
  if (!(std::isfinite(value) && value >= 0.0)) {
    Fail(field, Relation("a finite value >=", 0.0, unit), OptionValueText(value));
  }
}

void OptionChecks::Require(bool ok, std::string_view field, std::string_view expected,
                           std::string_view got) const {
  if (!ok) Fail(field, expected, got);
}

void OptionChecks::Require(bool ok, std::string_view field, std::string_view expected,
                           double got) const {
  if (!ok) Fail(field, expected, OptionValueText(got));
}

void OptionChecks::Fail(std::string_view field, std::string_view expected,
                        std::string_view got) const {
  std::string message = owner_;
  message += '.';
  message.append(field);
  message += ": expected ";
  message.append(expected);
  if (!got.empty()) {
    message += ", got ";
    message.append(got);
  }
  throw Error(message);
}

}  // namespace uwscan
