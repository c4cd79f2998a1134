// Small constructors the hand-written test scenes share.
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "diffpills/shapes.hpp"

namespace diffpills::testing {

inline const Eigen::Vector4d kIdentity(1, 0, 0, 0);

// The quaternion of a rotation by `angle` about the unit axis (x, y, z).
inline Eigen::Vector4d about(double angle, double x, double y, double z) {
  return {std::cos(angle / 2), std::sin(angle / 2) * x, std::sin(angle / 2) * y,
          std::sin(angle / 2) * z};
}

// The rectangle [-half_x, half_x] x [-half_y, half_y] with padding `radius`.
inline PaddedPolygon rectangle(double half_x, double half_y, double radius) {
  Eigen::MatrixX2d C(4, 2);
  C << 1, 0, 0, 1, -1, 0, 0, -1;
  return PaddedPolygon(C, Eigen::Vector4d(half_x, half_y, half_x, half_y), radius);
}

// The square [-half, half]^2 with padding `radius`.
inline PaddedPolygon square(double half, double radius) { return rectangle(half, half, radius); }

}  // namespace diffpills::testing
