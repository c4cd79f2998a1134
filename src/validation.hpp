// Input checks shared by the shape and pose constructors. Each throws std::invalid_argument with
// a message that starts with the field name, so that callers (the command line, the bindings) can
// pass it on unchanged or prefix it with the shape's own name.
#pragma once

#include <string>

namespace diffpills::detail {

// Throws unless value is finite and |value| <= kMaxMagnitude.
void require_finite(double value, const std::string& field);

// Throws unless value is finite and 0 <= value <= kMaxMagnitude.
void require_nonnegative(double value, const std::string& field);

// "field: problem (got value)".
[[noreturn]] void fail(const std::string& field, const std::string& problem);

}  // namespace diffpills::detail
