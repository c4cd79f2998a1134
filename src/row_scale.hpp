// A polygon row C_i = (c0, c1) scaled exactly by a power of two to entries of order one, for the
// quantities of degree -1 or 0 in the row (its unit normal, its offset d_i / |C_i|, the gradient's
// 1 / |C_i|): taken from the scaled row, they come out the same to the bit for a row and the same
// row times 2^k, subnormal rows included, whose norm by hypot as given keeps only the bits above
// 2^-1074 (~14 bits for entries near 2^-1060; fuzz_proximity).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace diffpills::detail {

// The shift s with the row's largest |entry| times 2^s in [1, 2); the row must not be zero.
inline int row_scale_shift(double c0, double c1) {
  int exponent = 0;
  std::frexp(std::max(std::abs(c0), std::abs(c1)), &exponent);  // largest = f 2^exponent
  return 1 - exponent;
}

// The row times 2^shift, each entry scaled apart: not times that power formed first, which for a
// subnormal row (shift above 1023) is infinite (a hostile review: [1e-308, 0] y <= 5e-309 was
// dropped as constraining nothing, and a point beyond it reported touching).
inline Eigen::Vector2d scaled_row(double c0, double c1, int shift) {
  return {std::ldexp(c0, shift), std::ldexp(c1, shift)};
}

// |row times 2^shift|, in [1, 2 sqrt(2)] for row_scale_shift's shift.
inline double scaled_row_norm(const Eigen::Vector2d& scaled) {
  return std::hypot(scaled.x(), scaled.y());
}

}  // namespace diffpills::detail
