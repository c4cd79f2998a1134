#include <algorithm>
#include <cmath>
#include <limits>

#include "fast_paths.hpp"
#include "segment_segment.hpp"

namespace diffpills::detail {

// In the polygon's body frame the core is {(y, 0) : y in polygon} and the segment is
// x(s) = m + s u, |s| <= L / 2, |u| = 1, m its middle. The closest pair is one of
//   - a crossing of the plane z = 0 inside the polygon (distance zero, a single point unless the
//     segment lies in the plane);
//   - an end point over the face (distance |z|);
//   - the segment against an edge (segment_segment.hpp).
// Where the closest points are not unique the optimal set is an interval, of two kinds:
//   - the segment parallel to the plane, |u_z| <= 1e-12 (the height varies linearly with a tilt,
//     so the threshold is on the sine), over the face: its part over the face (also when it lies
//     in the plane);
//   - the segment parallel to an edge and beside it: the overlap of the two, which the edge's
//     segment-segment solution reports (SegmentParameters::overlap). Its distance ties with the
//     neighbouring edges' at the shared vertex; the overlap wins ties within the tie tolerance
//     that include the best point.
// Both are found with the polygon grown by the tolerance, so that a segment touching the boundary
// is not decided by rounding.
std::array<ClosestFeature, 2> solve_capsule_polygon(const PosedCore& capsule,
                                                    const PolygonView& polygon,
                                                    const PosedCore& posed_polygon,
                                                    double tolerance, double tie_tolerance) {
  const double length = capsule.size, half = 0.5 * capsule.size;
  const Eigen::Matrix3d& R = posed_polygon.attitude.matrix();
  const Eigen::Vector3d axis = capsule.attitude.matrix().col(0);
  // The segment from its middle m (segment_segment.hpp: a point near the middle of a long capsule
  // keeps the digits of its own offset), its start p only for clipping its line.
  const Eigen::Vector3d m = R.transpose() * (capsule.r - posed_polygon.r);
  const Eigen::Vector3d u = R.transpose() * axis;
  const Segment segment{m, u, length};

  if (length > 0.0 && std::abs(u.z()) <= 1e-12) {
    const Eigen::Vector3d p = segment.at(-half);
    const auto [low, high] = clip_line(polygon, p.head<2>(), length * u.head<2>(), tolerance);
    if (low <= high) {
      const double offset = (0.5 * (low + high) - 0.5) * length;
      return {segment_point_at(length, offset), face_point(segment.at(offset).head<2>())};
    }
  }
  const double z0 = m.z() - half * u.z(), z1 = m.z() + half * u.z();
  if ((z0 < 0.0 && z1 > 0.0) || (z0 > 0.0 && z1 < 0.0)) {
    const double offset = std::clamp(-m.z() / u.z(), -half, half);
    const Eigen::Vector2d crossing = segment.at(offset).head<2>();
    if (contains(polygon, crossing, tolerance)) {
      return {segment_point_at(length, offset), face_point(crossing)};
    }
  }

  struct Candidate {
    double distance2 = std::numeric_limits<double>::infinity();
    std::array<ClosestFeature, 2> sides;
    double half_width = 0.0;  // an overlap's: half its length (the same on the segment and edge)
  } best, best_overlap;
  for (const double offset : {-half, half}) {
    const Eigen::Vector3d end = segment.at(offset);
    if (end.z() * end.z() < best.distance2 && contains(polygon, end.head<2>(), 0.0)) {
      best = {end.z() * end.z(), {segment_point_at(length, offset), face_point(end.head<2>())}};
    }
  }
  for (Eigen::Index j = 0; j < polygon.size(); ++j) {
    const Segment edge = polygon.edge(j);
    const SegmentParameters closest = closest_segment_parameters(segment, edge);
    const double distance2 =
        (segment.at(closest.s_offset) - edge.at(closest.t_offset)).squaredNorm();
    Candidate& kept = closest.overlap ? best_overlap : best;
    if (distance2 < kept.distance2) {
      kept = {distance2,
              {segment_point_at(length, closest.s_offset), edge_point(polygon, j, closest.t)},
              closest.half_overlap * length};
    }
  }
  // The overlap wins if it is as close, and a tie within the tie tolerance if the best pair lies
  // on it, give or take sqrt(2 |d| tie_tolerance) (as in separated_polygons.cpp's Best::choice): a
  // tie in distance alone may be another edge's overlap when the shapes are far apart compared to
  // their size.
  if (best_overlap.distance2 <= best.distance2) return best_overlap.sides;
  const double reach = std::sqrt(best.distance2) + tie_tolerance;
  if (best_overlap.distance2 > reach * reach) return best.sides;
  const double reach_of_overlap = best_overlap.half_width + tolerance +
                                  std::sqrt(2.0 * std::sqrt(best.distance2) * tie_tolerance);
  const bool on_overlap =
      (best.sides[0].body_point - best_overlap.sides[0].body_point).norm() <= reach_of_overlap &&
      (best.sides[1].body_point - best_overlap.sides[1].body_point).norm() <= reach_of_overlap;
  return on_overlap ? best_overlap.sides : best.sides;
}

}  // namespace diffpills::detail
