#include "validation.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace diffpills::detail {

// The shortest %g form that reads back as the same double: -1e-10 prints as "-1e-10", not as
// "-0.000000" (std::to_string) or "-1.0000000000000000e-10" (17 digits).
std::string format_number(double value) {
  char text[32];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, value);
    if (std::strtod(text, nullptr) == value || std::isnan(value)) break;
  }
  return text;
}

void fail(const std::string& field, const std::string& problem) {
  throw std::invalid_argument(field + ": " + problem);
}

void fail_finite(double value, const std::string& field) {
  if (!std::isfinite(value)) {
    fail(field, "must be finite (got " + format_number(value) + ")");
  }
  fail(field, "magnitude must be <= 1e100 (got " + format_number(value) + ")");
}

void fail_negative(double value, const std::string& field) {
  fail(field, "must be >= 0 (got " + format_number(value) + ")");
}

std::string printable(const std::string& name) {
  std::string text;
  text.reserve(name.size());
  for (const char c : name) {
    if (c == '\0') {
      text += "\\u0000";
    } else {
      text += c;
    }
  }
  return text;
}

}  // namespace diffpills::detail
