#include "validation.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "diffpills/shapes.hpp"

namespace diffpills::detail {
namespace {

std::string describe(double value) {
  std::ostringstream stream;
  stream.precision(17);
  stream << value;
  return stream.str();
}

}  // namespace

void fail(const std::string& field, const std::string& problem) {
  throw std::invalid_argument(field + ": " + problem);
}

void require_finite(double value, const std::string& field) {
  if (!std::isfinite(value)) {
    fail(field, "must be finite (got " + describe(value) + ")");
  }
  if (std::abs(value) > kMaxMagnitude) {
    fail(field, "magnitude must be <= 1e100 (got " + describe(value) + ")");
  }
}

void require_nonnegative(double value, const std::string& field) {
  require_finite(value, field);
  if (value < 0.0) {
    fail(field, "must be >= 0 (got " + describe(value) + ")");
  }
}

}  // namespace diffpills::detail
