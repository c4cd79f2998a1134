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

// -1, 0 or 1 as x comes before, with or after y in lexicographic order of their entries (sizes
// equal).
template <class Derived>
int lexicographic_order(const Eigen::DenseBase<Derived>& x, const Eigen::DenseBase<Derived>& y) {
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    if (x(i) != y(i)) return x(i) < y(i) ? -1 : 1;
  }
  return 0;
}

// For two identical polygons: is B's pose in A's frame "after" A's pose in B's frame? The two
// relative poses are each other's inverses, and which comes first is decided by what a rigid
// motion of the scene and the sign of a quaternion leave unchanged: w . t for the other's origin
// t in each one's frame, then w . (R u) for a body direction u carried by the other's rotation in
// each one's frame, with weights w of irrational ratios so that no axis-aligned scene ties. Both
// are computed by the same operations in either order of the arguments, so each comparison is
// exactly antisymmetric. Where w . t ties exactly (t level with w's plane in both frames, which a
// chosen translation such as (2^(-1/2), -1/2, 0) at equal attitudes makes it: a hostile review),
// the offsets themselves decide, in lexicographic order, and likewise the carried directions.
// Where all tie (the same origin and attitude, or a relative pose that is its own inverse), the
// two roles pose the same problem.
inline bool identical_b_first(const PosedCore& pa, const PosedCore& pb) {
  const Eigen::Vector3d w(1.0, 1.4142135623730951, 1.7320508075688772);  // 1, 2^(1/2), 3^(1/2)
  const Eigen::Matrix3d& Ra = pa.attitude.matrix();
  const Eigen::Matrix3d& Rb = pb.attitude.matrix();
  const Eigen::Vector3d b_seen_from_a = Ra.transpose() * (pb.r - pa.r);
  const Eigen::Vector3d a_seen_from_b = Rb.transpose() * (pa.r - pb.r);
  if (w.dot(b_seen_from_a) != w.dot(a_seen_from_b)) {
    return w.dot(b_seen_from_a) > w.dot(a_seen_from_b);
  }
  if (const int order = lexicographic_order(b_seen_from_a, a_seen_from_b)) return order > 0;
  const Eigen::Vector3d u(1.0, 1.4142135623730951, 0.0);
  const Eigen::Vector3d b_turned_from_a = Ra.transpose() * (Rb * u);
  const Eigen::Vector3d a_turned_from_b = Rb.transpose() * (Ra * u);
  if (w.dot(b_turned_from_a) != w.dot(a_turned_from_b)) {
    return w.dot(b_turned_from_a) > w.dot(a_turned_from_b);
  }
  return lexicographic_order(b_turned_from_a, a_turned_from_b) > 0;
}

// Which of two polygons is solved as A, in whose body frame everything happens
// (polygon_polygon.cpp). Where the tolerances make the answer depend on the roles (B's section of
// A's plane clipped by A grown by the tolerance: a box's edge resting on a table within the
// tolerance and tilted 1e-12 rad came out 0.6 of its size apart in the two orders; far, nearly
// parallel faces picked tied points 6e-5 of the scene apart), both orders of the arguments must
// solve the same problem, bit for bit. The choice reads the polygons' own data, so that a rigid
// motion of the scene keeps it: the one with more vertices is A (the windows of
// polygon_windows.cpp climb A's boundary in the cheaper role: a 20,000-gon against a hexagon
// took 2.4x as long with the hexagon as A), then the larger radius, then the vertices and edge
// normals in lexicographic order. Identical polygons (rows permuted or rescaled too) are ordered
// by their relative poses (identical_b_first).
inline bool solve_b_as_a(const PaddedPolygon& a, const PosedCore& pa, const PaddedPolygon& b,
                         const PosedCore& pb) {
  if (a.vertices().rows() != b.vertices().rows()) {
    return b.vertices().rows() > a.vertices().rows();
  }
  if (a.radius() != b.radius()) return b.radius() > a.radius();
  if (const int order = lexicographic_order(b.vertices().reshaped(), a.vertices().reshaped())) {
    return order < 0;
  }
  if (const int order =
          lexicographic_order(b.edge_normals().reshaped(), a.edge_normals().reshaped())) {
    return order < 0;
  }
  return identical_b_first(pa, pb);
}

// The cores posed for solving B first: B's origin where A's is and A's at minus B's offset from
// it, exactly the frame of the other order of the arguments (x - y = -(y - x) in floating point).
struct SwappedCores {
  PosedCore first, second;  // B, then A
};
inline SwappedCores b_first(const PosedCore& pa, const PosedCore& pb) {
  SwappedCores out{pb, pa};
  out.first.r = pa.r;
  out.second.r = pa.r - (pb.r - pa.r);
  return out;
}

// Two polygons, solved with A the first of the two (solve_b_as_a).
inline Sides fast_sides(const PaddedPolygon& a, const PosedCore& pa, const PaddedPolygon& b,
                        const PosedCore& pb, const PairFrame& frame) {
  const CoreTolerances tolerances = search_tolerances(pa, pb, frame);
  const PolygonView view_a(a, frame.inverse_scale), view_b(b, frame.inverse_scale);
  if (!solve_b_as_a(a, pa, b, pb)) {
    return detail::solve_polygon_polygon(view_a, pa, view_b, pb, tolerances.intersection,
                                         tolerances.tie);
  }
  const SwappedCores swapped_cores = b_first(pa, pb);
  const Sides swapped =
      detail::solve_polygon_polygon(view_b, swapped_cores.first, view_a, swapped_cores.second,
                                    tolerances.intersection, tolerances.tie);
  return {swapped[1], swapped[0]};
}

}  // namespace diffpills::detail
