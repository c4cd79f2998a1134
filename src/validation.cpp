#include "validation.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

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

void fail_finite(double value, const std::string& field) {
  if (!std::isfinite(value)) {
    fail(field, "must be finite (got " + describe(value) + ")");
  }
  fail(field, "magnitude must be <= 1e100 (got " + describe(value) + ")");
}

void fail_negative(double value, const std::string& field) {
  fail(field, "must be >= 0 (got " + describe(value) + ")");
}

}  // namespace diffpills::detail
