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
// The tolerances a pair's cores are searched with: the bare cores' own (core_tolerances,
// pair_frame.hpp), which are the frame's unless the radii make the scene. The radii play no part
// in which core points are closest, and searches whose pruning is only as fine as the tolerance
// (two polygons' windows and hierarchies, pair_frame.hpp) would otherwise stall on cores far
// smaller than their radii; the penetration search's allowances follow its tolerance
// (penetration.hpp), and at the scene's a capsule 4e-13 above a needle beside radii of 1 got a
// signed gap of -4e-13 in one order of the shapes and +4e-13 in the other.
inline CoreTolerances search_tolerances(const PosedCore& pa, const PosedCore& pb,
                                        const PairFrame& frame) {
  return core_tolerances(frame, pa.size, pb.size, (pb.r - pa.r).norm());
}

inline Sides fast_sides(const Capsule&, const PosedCore& pa, const PaddedPolygon& b,
                        const PosedCore& pb, const PairFrame& frame) {
  const CoreTolerances tolerances = search_tolerances(pa, pb, frame);
  return detail::solve_capsule_polygon(pa, PolygonView(b, frame.inverse_scale), pb,
                                       tolerances.intersection, tolerances.tie);
}
inline Sides fast_sides(const PaddedPolygon& a, const PosedCore& pa, const Capsule&,
                        const PosedCore& pb, const PairFrame& frame) {
  const CoreTolerances tolerances = search_tolerances(pa, pb, frame);
  const Sides swapped = detail::solve_capsule_polygon(pb, PolygonView(a, frame.inverse_scale), pa,
                                                      tolerances.intersection, tolerances.tie);
  return {swapped[1], swapped[0]};
}
inline Sides fast_sides(const PaddedPolygon& a, const PosedCore& pa, const PaddedPolygon& b,
                        const PosedCore& pb, const PairFrame& frame) {
  const CoreTolerances tolerances = search_tolerances(pa, pb, frame);
  return detail::solve_polygon_polygon(PolygonView(a, frame.inverse_scale), pa,
                                       PolygonView(b, frame.inverse_scale), pb,
                                       tolerances.intersection, tolerances.tie);
}

}  // namespace diffpills::detail
