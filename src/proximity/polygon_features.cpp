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

ClosestFeature segment_point(double length, double s) {
  ClosestFeature side;
  side.body_point.x() = (s - 0.5) * length;
  if (length > 0.0 && s > 0.0 && s < 1.0) {
    side.free_dimensions = 1;
    side.free_directions.col(0) = Eigen::Vector3d::UnitX();
  }
  return side;
}

}  // namespace diffpills::detail
