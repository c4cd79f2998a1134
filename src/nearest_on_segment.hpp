// The point of a plane segment nearest to a given point, by its parameter. Shared by a polygon's
// reduction (padded_polygon.cpp: how far a cut-off vertex is from the rest) and the pair of a
// far polygon's vertex with the face's boundary (separated_polygons.cpp, rim_pair).
#pragma once

#include <Eigen/Core>
#include <algorithm>

namespace diffpills::detail {

// t in [0, 1] minimising |start + t (end - start) - point|: the projection
// (point - start) . (end - start) / |end - start|^2 clamped to the segment, and 0 for a segment of
// zero length (every t is then as near).
inline double nearest_on_segment(const Eigen::Vector2d& point, const Eigen::Vector2d& start,
                                 const Eigen::Vector2d& end) {
  const Eigen::Vector2d along = end - start;
  const double length_squared = along.squaredNorm();
  return length_squared > 0.0 ? std::clamp((point - start).dot(along) / length_squared, 0.0, 1.0)
                              : 0.0;
}

}  // namespace diffpills::detail
