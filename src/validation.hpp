// Input checks shared by the shape and pose constructors. Each throws std::invalid_argument with
// a message that starts with the field name, so that callers (the command line, the bindings) can
// pass it on unchanged or prefix it with the shape's own name.
#pragma once

#include <cmath>
#include <string>

#include "diffpills/shapes.hpp"

namespace diffpills::detail {

// Throws unless value is finite and |value| <= kMaxMagnitude. The field's name is built only on
// failure: `field` is called then, so valid input costs no string work (the batch API validates
// every pose).
template <class FieldName>
void require_finite(double value, const FieldName& field);

// Throws unless value is finite and 0 <= value <= kMaxMagnitude.
template <class FieldName>
void require_nonnegative(double value, const FieldName& field);

// The failure paths, out of line.
[[noreturn]] void fail_finite(double value, const std::string& field);
[[noreturn]] void fail_negative(double value, const std::string& field);

// The shortest decimal text that reads back as `value` ("-1e-10", "0.1", "nan").
std::string format_number(double value);

// "field: problem (got value)".
[[noreturn]] void fail(const std::string& field, const std::string& problem);

// A caller's name (a body's, one in an exclusion) as it goes into a message, with each NUL byte
// written \u0000: a message is read back through what(), a C string, and ended at the first NUL
// (a hostile review: a body named "a\0b" made errors read "... body 'a"). Other bytes stay as
// given; the command line escapes them in its JSON answers.
std::string printable(const std::string& name);

template <class FieldName>
void require_finite(double value, const FieldName& field) {
  if (!(std::abs(value) <= kMaxMagnitude)) {  // false for NaN too
    fail_finite(value, std::string(field()));
  }
}

template <class FieldName>
void require_nonnegative(double value, const FieldName& field) {
  require_finite(value, field);
  if (value < 0.0) {
    fail_negative(value, std::string(field()));
  }
}

}  // namespace diffpills::detail
