#include "polygon_features.hpp"

#include <algorithm>
#include <cmath>

namespace diffpills::detail {

ClosestFeature face_point(const Eigen::Vector2d& y) {
  ClosestFeature side;
  side.body_point << y, 0.0;
  side.free_dimensions = 2;
  side.free_directions.col(0) = Eigen::Vector3d::UnitX();
  side.free_directions.col(1) = Eigen::Vector3d::UnitY();
  return side;
}

ClosestFeature segment_point_at(double length, double offset) {
  ClosestFeature side;
  side.body_point.x() = offset;
  if (length > 0.0 && std::abs(offset) < 0.5 * length) {
    side.free_dimensions = 1;
    side.free_directions.col(0) = Eigen::Vector3d::UnitX();
  }
  return side;
}

}  // namespace diffpills::detail
