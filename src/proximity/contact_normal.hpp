// A pair's unit normal and how it moves with the poses, for both result builders (pair_result,
// signed_distance_result).
//
// Where the closest points (or a facet's witnesses) x1, x2 are apart, the normal is along
// d = x2 - x1. Computed as d / |d| its direction is only known to about eps (the scene's size) /
// |d|: the points carry absolute errors of a few ulps of the scene, so near touching (|d| of
// 1e-12 of the scene) the normal, and the signed distance's gradient, which is the normal, were
// off by up to 1e-4 (a hostile review). Where the features holding the points fix the normal,
// it is taken from them instead:
//   - a point inside a polygon's face (a side free in two directions): d is normal to the face,
//     so the normal is +-Q e_z of that polygon, exact to a few ulps;
//   - two points inside two edges (both sides free in one direction), not parallel: d is normal
//     to both, so the normal is +-(e x f) / |e x f|, known to ~eps / |sin(e, f)|; taken when that
//     is the smaller error, |sin| >= |d| / unit (unit the scene's size in the frame, rounded down
//     to a power of two: 1 but for subnormal scenes, pair_frame.hpp).
// Otherwise (a vertex or a segment's end on either side, or edges too close to parallel) d / |d|
// is what there is: the problem itself is then that ill-conditioned. The sign follows d, and a
// feature's normal is taken only if it agrees with d / |d| to d's own uncertainty: one that does
// not means the features' labels are off (a zero-length segment, a point at an edge's end
// labelled inside it by rounding).
#pragma once

#include <Eigen/Core>
#include <array>

#include "point_motion.hpp"
#include "posed_core.hpp"

namespace diffpills::detail {

// How the normal depends on the poses.
struct NormalSource {
  enum class Kind { kClosestPoints, kFace, kEdges, kFixed };
  Kind kind = Kind::kClosestPoints;
  int face_core = 0;  // kFace: normal = sign * Q_face_core e_z
  double sign = 1.0;  // kFace, kEdges
  // kEdges: the edges' unit directions in their bodies' frames; normal = sign * unit(a x b) with
  // a = Q1 edge_directions[0], b = Q2 edge_directions[1].
  std::array<Eigen::Vector3d, 2> edge_directions = {Eigen::Vector3d::Zero(),
                                                    Eigen::Vector3d::Zero()};
};

// The source of the normal of points x1 = a's side, x2 = b's side, d = x2 - x1 (nonzero), by the
// rules above; `unit` is the frame's PairFrame::unit.
NormalSource points_normal_source(const PosedCore& a, const ClosestFeature& side_a,
                                  const PosedCore& b, const ClosestFeature& side_b,
                                  const Eigen::Vector3d& d, double unit);

// The normal of a source (kClosestPoints: d / |d|; not for kFixed).
Eigen::Vector3d source_normal(const NormalSource& source, const PosedCore& a, const PosedCore& b,
                              const Eigen::Vector3d& d);

// d normal / d[r1 q1 r2 q2] of a source: kClosestPoints d(d / |d|) from the points' motion, kFace
// the face's rotation, kEdges the derivative of unit(e x f); zero for kFixed.
Matrix3x14 source_normal_motion(const NormalSource& source, const PosedCore& a, const PosedCore& b,
                                const Eigen::Vector3d& d, const PointMotion& motion);

}  // namespace diffpills::detail
