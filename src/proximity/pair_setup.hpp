// What every query of a pair does first, shared by the proximity and the signed distance: the
// cores posed in the pair's frame (pair_frame.hpp) and the exact fast solvers (fast_paths.hpp)
// chosen by the shapes' types.
#pragma once

#include <array>

#include "diffpills/shapes.hpp"
#include "fast_paths.hpp"
#include "pair_frame.hpp"
#include "polygon_features.hpp"
#include "posed_core.hpp"

namespace diffpills::detail {

using Sides = std::array<ClosestFeature, 2>;

inline double core_size(const Capsule& capsule) { return capsule.length(); }
inline double core_size(const PaddedPolygon& polygon) { return polygon.extent(); }

// The shape's core in the frame: origin moved to `origin`, lengths divided by the frame's scale
// (multiplied by its exact inverse).
template <class Shape>
PosedCore posed_core(const Shape& shape, const Pose& pose, const Eigen::Vector3d& origin,
                     const PairFrame& frame) {
  return {(pose.r() - origin) * frame.inverse_scale, detail::UnitQuaternion(pose.q()),
          shape.radius() * frame.inverse_scale, core_size(shape) * frame.inverse_scale,
          shape.radius()};
}

inline Sides fast_sides(const Capsule&, const PosedCore& pa, const Capsule&, const PosedCore& pb,
                        const PairFrame&) {
  return detail::solve_capsule_capsule(pa, pb);
}
inline Sides fast_sides(const Capsule&, const PosedCore& pa, const PaddedPolygon& b,
                        const PosedCore& pb, const PairFrame& frame) {
  return detail::solve_capsule_polygon(pa, PolygonView(b, frame.inverse_scale), pb, frame.tolerance,
                                       frame.tie_tolerance);
}
inline Sides fast_sides(const PaddedPolygon& a, const PosedCore& pa, const Capsule&,
                        const PosedCore& pb, const PairFrame& frame) {
  const Sides swapped = detail::solve_capsule_polygon(pb, PolygonView(a, frame.inverse_scale), pa,
                                                      frame.tolerance, frame.tie_tolerance);
  return {swapped[1], swapped[0]};
}

// The tolerances a pair's cores are searched with: the frame's, except for two polygons, which
// are searched at the bare cores' own (core_tolerances, pair_frame.hpp). Capsule pairs are solved
// in closed form and a capsule against a k-gon in O(k) whatever the tolerance; two polygons are
// searched in windows and hierarchies whose pruning is only as fine as it.
template <class ShapeA, class ShapeB>
CoreTolerances search_tolerances(const ShapeA&, const PosedCore&, const ShapeB&, const PosedCore&,
                                 const PairFrame& frame) {
  return {frame.tolerance, frame.tie_tolerance};
}
inline CoreTolerances search_tolerances(const PaddedPolygon&, const PosedCore& pa,
                                        const PaddedPolygon&, const PosedCore& pb,
                                        const PairFrame& frame) {
  return core_tolerances(frame, pa.size, pb.size, (pb.r - pa.r).norm());
}

inline Sides fast_sides(const PaddedPolygon& a, const PosedCore& pa, const PaddedPolygon& b,
                        const PosedCore& pb, const PairFrame& frame) {
  const CoreTolerances tolerances = search_tolerances(a, pa, b, pb, frame);
  return detail::solve_polygon_polygon(PolygonView(a, frame.inverse_scale), pa,
                                       PolygonView(b, frame.inverse_scale), pb,
                                       tolerances.intersection, tolerances.tie);
}

}  // namespace diffpills::detail
