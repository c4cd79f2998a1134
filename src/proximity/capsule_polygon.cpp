#include <cmath>
#include <limits>

#include "fast_paths.hpp"
#include "polygon_features.hpp"
#include "segment_segment.hpp"

namespace diffpills::detail {

// In the polygon's body frame the core is {(y, 0) : y in polygon} and the segment is
// x(s) = p + s u, s in [0, 1]. The closest pair is one of
//   - a crossing of the plane z = 0 inside the polygon (distance zero, a single point unless the
//     segment lies in the plane);
//   - an end point over the face (distance |z|);
//   - the segment against an edge (segment_segment.hpp).
// A segment parallel to the plane, |u_z| <= 1e-12 |u|, whose shadow overlaps the polygon has a
// whole interval of closest points; its middle is returned. The threshold is on the sine, not its
// square: the height varies linearly with a tilt, and the middle of the interval is then within
// 1e-12 |u| of the optimal distance.
std::array<CoreSolution, 2> solve_capsule_polygon(const Capsule& capsule,
                                                  const PosedCore& posed_capsule,
                                                  const PaddedPolygon& polygon,
                                                  const PosedCore& posed_polygon) {
  const double length = capsule.length();
  const Eigen::Matrix3d& R = posed_polygon.attitude.matrix();
  const Eigen::Vector3d axis = length * posed_capsule.attitude.matrix().col(0);
  const Eigen::Vector3d p = R.transpose() * (posed_capsule.r - 0.5 * axis - posed_polygon.r);
  const Eigen::Vector3d u = R.transpose() * axis;

  const double u_norm = u.norm();
  if (u_norm > 0.0 && std::abs(u.z()) <= 1e-12 * u_norm) {
    const auto [low, high] = clip_line(polygon, p.head<2>(), u.head<2>());
    if (low <= high) {
      const double s = 0.5 * (low + high);
      return {segment_point(length, s), face_point((p + s * u).head<2>())};
    }
  }
  const double z0 = p.z(), z1 = p.z() + u.z();
  if ((z0 < 0.0 && z1 > 0.0) || (z0 > 0.0 && z1 < 0.0)) {
    const double s = z0 / (z0 - z1);
    const Eigen::Vector2d crossing = (p + s * u).head<2>();
    if (contains(polygon, crossing)) {
      return {segment_point(length, s), face_point(crossing)};
    }
  }

  double best = std::numeric_limits<double>::infinity();
  std::array<CoreSolution, 2> sides;
  for (const double s : {0.0, 1.0}) {
    const Eigen::Vector3d end = p + s * u;
    if (end.z() * end.z() < best && contains(polygon, end.head<2>())) {
      best = end.z() * end.z();
      sides = {segment_point(length, s), face_point(end.head<2>())};
    }
  }
  for (Eigen::Index j = 0; j < polygon.vertices().rows(); ++j) {
    Eigen::Vector3d start = Eigen::Vector3d::Zero(), edge = Eigen::Vector3d::Zero();
    start.head<2>() = edge_start(polygon, j);
    edge.head<2>() = edge_end(polygon, j) - start.head<2>();
    const SegmentParameters closest = closest_segment_parameters(p, u, start, edge);
    const double distance2 = (p + closest.s * u - start - closest.t * edge).squaredNorm();
    if (distance2 < best) {
      best = distance2;
      sides = {segment_point(length, closest.s), edge_point(polygon, j, closest.t)};
    }
  }
  return sides;
}

}  // namespace diffpills::detail
