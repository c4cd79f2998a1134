#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "convex_overlap.hpp"
#include "fast_paths.hpp"
#include "polygon_windows.hpp"
#include "separated_polygons.hpp"
#include "small_buffer.hpp"

namespace diffpills::detail {
namespace {

Eigen::Vector3d lift(const Eigen::Vector2d& y) { return {y.x(), y.y(), 0.0}; }

// Above this many vertex pairs the enumeration of every edge pair gives way to the windows of
// polygon_windows.hpp (measured in bench_proximity: the two cost the same near 32 x 32 vertices).
constexpr Eigen::Index kEnumerationLimit = Eigen::Index{32} * 32;

// A polygon's rows, and the bevels of its spikes (polygon_features.hpp), as half-planes of A's
// plane: row n . y_B <= b becomes (R n) . y_A <= b + (R n) . t, with y_A = R y_B + t. Returns the
// number written to `out`, which holds size() + 3 entries: the normals turn by 360 degrees in all,
// so at most 3 vertices turn by more than 90 and are spikes.
Eigen::Index shadow_half_planes(const PolygonView& polygon, const Eigen::Matrix2d& rotation,
                                const Eigen::Vector2d& translation, HalfPlane* out) {
  Eigen::Index count = 0;
  const auto add = [&](const Eigen::Vector2d& normal, double offset) {
    const Eigen::Vector2d turned = rotation * normal;
    out[count++] = {turned, offset + turned.dot(translation)};
  };
  for (Eigen::Index j = 0; j < polygon.size(); ++j) add(polygon.normal(j), polygon.offset(j));
  Eigen::Vector2d normal;
  double offset = 0.0;
  for (Eigen::Index i = 0; i < polygon.size(); ++i) {
    if (spike_bevel(polygon, i, normal, offset)) add(normal, offset);
  }
  return count;
}

// The common region of A and B's shadow when the planes are parallel: B's rows carried into A's
// plane by the in-plane part of B's pose in A's frame (a rotation, or a reflection when B faces
// the other way), each polygon's spikes bevelled so that the slack does not stretch them.
bool parallel_overlap(const PolygonView& a, const PolygonView& b, const PolygonPairFrame& frame,
                      double tolerance, Eigen::Vector2d& centre) {
  // On the stack up to 32 vertices and their 3 bevels (kInlineHalfPlanes, convex_overlap.hpp).
  SmallBuffer<HalfPlane, kInlineHalfPlanes> a_rows(a.size() + 3), b_rows(b.size() + 3);
  const Eigen::Index a_count =
      shadow_half_planes(a, Eigen::Matrix2d::Identity(), Eigen::Vector2d::Zero(), a_rows.data());
  const Eigen::Index b_count = shadow_half_planes(b, frame.b_in_a.topLeftCorner<2, 2>(),
                                                  frame.b_origin_in_a.head<2>(), b_rows.data());
  return overlap_centre(a_rows.data(), a_count, a.extent(), b_rows.data(), b_count, tolerance,
                        centre);
}

// The segment S = B /\ {z = 0} of crossing planes (in A's frame): its ends are the extreme points,
// along the planes' common line, of B's vertices in the plane (within the tolerance) and of the
// crossings of B's edges. Returns false if B does not reach the plane.
//
// A vertex of B counts as in the plane only if it is also within the tolerance of the common
// line: B's plane meets z = 0 at an angle delta, and a vertex at height z lies |z| cos(delta) /
// sin(delta) from the line, along A's plane. For planes a few 1e-12 from parallel the band
// |z| <= tolerance is as wide as the polygons, and its vertices would make S a skewed chord that
// misses the true intersection (found by fuzz_proximity).
bool plane_section(const CarriedPolygon<PolygonView>& W, const Eigen::Vector3d& b_normal,
                   double tolerance, Eigen::Vector2d& start, Eigen::Vector2d& end) {
  const Eigen::Vector3d line = Eigen::Vector3d::UnitZ().cross(b_normal);
  const double sin_delta = b_normal.head<2>().norm(), cos_delta = std::abs(b_normal.z());
  const auto in_plane = [&](double z) {
    return std::abs(z) <= tolerance && std::abs(z) * cos_delta <= tolerance * sin_delta;
  };
  double low = std::numeric_limits<double>::infinity(), high = -low;
  const auto add = [&](const Eigen::Vector3d& point) {
    const double along = line.dot(point);
    if (along < low) low = along, start = point.head<2>();
    if (along > high) high = along, end = point.head<2>();
  };
  for (Eigen::Index j = 0; j < W.size(); ++j) {
    const Eigen::Vector3d& s = W.start(j);
    const Eigen::Vector3d& e = W.end(j);
    if (in_plane(e.z())) add(lift(e.head<2>()));
    if ((s.z() < 0.0 && e.z() > 0.0) || (s.z() > 0.0 && e.z() < 0.0)) {
      add(s + (s.z() / (s.z() - e.z())) * (e - s));
    }
  }
  return low <= high;
}

// Level faces apart: each polygon's heights over the other's plane vary by less than the
// rounding of the coordinates, 64 ulps of their magnitude (B's origin's distance plus both
// extents; at most the tie tolerance), so that the distances of all their feature pairs tie,
// and B lies wholly on one side of A's plane beyond the intersection tolerance. (Not the whole tie
// tolerance: where the polygons are near each other its part of 2e-12 of their size would also
// take in tilts just past the 1e-12 of parallel planes, whose lowest vertex or edge is the
// documented answer; a spread of rounding there is a tilt of ~1e-14, parallel already.) Along the
// planes' mean normal m (laid_flat) every pair (x, y) is at least h = min_B m . y - max_A m . x
// apart, and the pair of a point c of the overlap of the two shadows along m, x and y right below
// and above it, at most h plus both spreads along m (each half the tilt times a width, together at
// most the tie tolerance): a tie. Where the shadows are apart, a gap L, every pair is at least
// sqrt(L^2 + h^2) apart and the shadows' closest pair at most sqrt(L^2 + (h + spread)^2): a tie
// again. Such faces are solved as coplanar ones, laid into the plane across m, which costs what
// coplanar polygons cost. Swept in 3-D they cost O(ka kb): two unit polygons 1e8 apart and 1e-8 rad
// from parallel tie in every feature pair (the tie tolerance, 64 ulps of the distance, lets pairs
// as far as sqrt(2 distance tie) ~ 17 apart along the plane tie), 1.3 s at 8,000 vertices (issue
// 9). The spreads are taken from the vertices turned into the other's frame without the
// translation, (R v).z, which the translation's rounding (ulps of the distance) does not drown.
bool level_and_apart(const PolygonView& a, const PolygonView& b, const PolygonPairFrame& frame,
                     const CarriedPolygon<PolygonView>& W, double tolerance, double tie_tolerance) {
  const auto spread = [](const PolygonView& polygon, const Eigen::Vector2d& rise) {
    double low = std::numeric_limits<double>::infinity(), high = -low;
    for (Eigen::Index i = 0; i < polygon.size(); ++i) {
      const double turned = rise.dot(polygon.vertex(i));
      low = std::min(low, turned);
      high = std::max(high, turned);
    }
    return high - low;
  };
  double lowest = std::numeric_limits<double>::infinity(), highest = -lowest;
  for (Eigen::Index j = 0; j < W.size(); ++j) {
    lowest = std::min(lowest, W[j].z());
    highest = std::max(highest, W[j].z());
  }
  const double magnitude = frame.b_origin_in_a.norm() + a.extent() + b.extent();
  const double level =
      std::min(tie_tolerance, 64 * std::numeric_limits<double>::epsilon() * magnitude);
  return (lowest > tolerance || highest < -tolerance) &&
         spread(b, frame.b_in_a.block<1, 2>(2, 0).transpose()) <= level &&
         spread(a, frame.b_in_a.block<2, 1>(0, 2)) <= level;
}

// The frame with both polygons laid into the plane across their mean normal m = (e_z + n) / |.|
// (n: B's normal in A's frame, turned to face the same way as A's e_z): the frame of A turned by
// the half tilt H, the rotation about a line in A's plane that takes e_z to m, with B's attitude
// there, H' R, replaced by the nearest one whose normal is on the z axis, and B's origin there,
// H' t, dropped into the plane. A's own in-plane block in that frame is that of a rotation about
// a line in its plane, symmetric and positive definite, whose nearest turn is the identity: A
// keeps its coordinates. B's in-plane attitude is a turn F = [c -s; s c] where B faces the same
// way as A, else a reflection F = [c s; s -c] (a half turn about an axis in the plane), nearest to
// its in-plane block M when it maximizes trace(F' M):
//   turn:        c (M00 + M11) + s (M10 - M01),   (c, s) along (M00 + M11, M10 - M01);
//   reflection:  c (M00 - M11) + s (M01 + M10),   (c, s) along (M00 - M11, M01 + M10).
// For a rotation, M's singular values are 1 and |M's normal z| and the vector's length is their
// sum, at least 1. The laid polygons differ from the shadows along m by the half tilt squared
// times their size, below the tie tolerance (level faces tilt by at most it over their width).
// The mean normal treats both polygons alike: the shadows along A's own normal put a pair 1e8
// apart and 1e-8 rad from parallel a whole unit to the side of the one along B's.
PolygonPairFrame laid_flat(const PolygonPairFrame& frame) {
  const Eigen::Vector3d normal = frame.b_in_a.col(2);
  const Eigen::Vector3d mean =
      (Eigen::Vector3d::UnitZ() + (normal.z() >= 0.0 ? normal : Eigen::Vector3d(-normal)))
          .normalized();
  const Eigen::Matrix3d half_tilt =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), mean).toRotationMatrix();
  const Eigen::Matrix3d turned = half_tilt.transpose() * frame.b_in_a;
  const Eigen::Vector3d origin = half_tilt.transpose() * frame.b_origin_in_a;
  const Eigen::Matrix2d M = turned.topLeftCorner<2, 2>();
  const bool same_way = turned(2, 2) >= 0.0;
  const Eigen::Vector2d turn = (same_way ? Eigen::Vector2d(M(0, 0) + M(1, 1), M(1, 0) - M(0, 1))
                                         : Eigen::Vector2d(M(0, 0) - M(1, 1), M(0, 1) + M(1, 0)))
                                   .normalized();
  const double c = turn.x(), s = turn.y();
  Eigen::Matrix3d flat;
  if (same_way) {
    flat << c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0;
  } else {
    flat << c, s, 0.0, s, -c, 0.0, 0.0, 0.0, -1.0;
  }
  return PolygonPairFrame(flat, {origin.x(), origin.y(), 0.0});
}

std::array<ClosestFeature, 2> solve_in_frame(const PolygonView& a, const PolygonView& b,
                                             const PolygonPairFrame& frame, double tolerance,
                                             double tie_tolerance) {
  const CarriedPolygon<PolygonView> W(b, frame.b_in_a, frame.b_origin_in_a);
  const Eigen::Vector3d b_normal = frame.b_in_a.col(2);

  if (b_normal.head<2>().norm() <= 1e-12) {
    Eigen::Vector2d centre;
    if (parallel_overlap(a, b, frame, tolerance, centre)) {
      return {face_point(centre), face_point(frame.in_b(lift(centre)))};
    }
  } else {
    Eigen::Vector2d start = Eigen::Vector2d::Zero(), end = Eigen::Vector2d::Zero();
    if (plane_section(W, b_normal, tolerance, start, end)) {
      const auto [t0, t1] = clip_line(a, start, end - start, tolerance);
      if (t0 <= t1) {
        const Eigen::Vector2d middle = start + (0.5 * (t0 + t1)) * (end - start);
        return {face_point(middle), face_point(frame.in_b(lift(middle)))};
      }
    }
  }
  if (level_and_apart(a, b, frame, W, tolerance, tie_tolerance)) {
    return solve_in_frame(a, b, laid_flat(frame), tolerance, tie_tolerance);
  }
  if (a.size() * b.size() > kEnumerationLimit) {
    return closest_separated_by_windows(a, b, frame, W, tolerance, tie_tolerance);
  }
  const CarriedPolygon<PolygonView> X(a, frame.b_in_a.transpose(), frame.a_origin_in_b);
  return closest_separated(a, b, frame, W, X, tolerance, tie_tolerance);
}

}  // namespace

// Everything happens in A's body frame, where A is {(y, 0) : y in A}, with B carried over.
//
// Parallel planes (B's normal within |sin| <= 1e-12 of A's: heights vary linearly with a tilt, so
// the threshold is on the sine) whose shadows overlap: every point of the overlap is closest,
// and its centre is returned (convex_overlap.hpp).
//
// Crossing planes: A meets B exactly where A meets the segment S = B /\ {z = 0}; S clipped by A
// (grown by the tolerance) is the intersection, a segment or a point, and its midpoint is
// returned. O(ka + kb).
//
// Level faces apart (each polygon's heights over the other's plane within the tie tolerance of
// each other, level_and_apart): solved as coplanar polygons, both laid into the plane across their
// mean normal (laid_flat): the centre of the overlap of their shadows along it, or the middle of
// the shadows' closest set, each polygon's point over it.
//
// Otherwise the polygons are apart, and the closest pair is one of
//   - a vertex of one over the face of the other (only a support vertex), or, for an edge
//     parallel to the other's plane, the middle of its part over the face;
//   - an edge of each (segment_segment.hpp), the middle of their overlap when parallel;
// found by enumeration (separated_polygons.hpp) or, for many vertices, in windows
// (polygon_windows.hpp). Candidates for a whole interval win ties within the tie tolerance.
std::array<ClosestFeature, 2> solve_polygon_polygon(const PolygonView& a, const PosedCore& posed_a,
                                                    const PolygonView& b, const PosedCore& posed_b,
                                                    double tolerance, double tie_tolerance) {
  return solve_in_frame(a, b, PolygonPairFrame(posed_a, posed_b), tolerance, tie_tolerance);
}

}  // namespace diffpills::detail
