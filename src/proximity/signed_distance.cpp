// The public signed-distance queries (signed_distance.hpp). Each solves the closest-point problem
// with the proximity's exact fast path (pair_setup.hpp); cores apart by more than the tolerance
// they are searched with (the cores' own, pair_setup.hpp: search_tolerances) are done then.
// Intersecting cores go on to the nearest facet of their Minkowski difference (penetration.hpp),
// whose witnesses replace the closest points unless the facet is within the tolerance of the origin
// (touching, or a flat D), where the closest points, the middle of the cores' intersection, serve
// as they are.
#include "diffpills/signed_distance.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <optional>
#include <type_traits>
#include <variant>

#include "core_outline.hpp"
#include "measure_hessian.hpp"
#include "pair_frame.hpp"
#include "pair_setup.hpp"
#include "penetration.hpp"
#include "signed_distance_result.hpp"

namespace diffpills {
namespace {

using detail::CoreOutline;
using detail::DeepestFacet;
using detail::NormalSource;
using detail::PairFrame;
using detail::PolygonView;
using detail::PosedCore;
using detail::SignedSolution;

// The normal where D has no facet (parallel segments, spheres): see signed_distance.hpp. `axis`
// is the segments' common direction, or zero for two spheres.
Eigen::Vector3d fallback_normal(const CoreOutline& a, const CoreOutline& b, double tolerance) {
  const Eigen::Vector3d axis = a.edge_count() > 0   ? a.edge(0).direction
                               : b.edge_count() > 0 ? b.edge(0).direction
                                                    : Eigen::Vector3d::Zero();
  const auto normal_part = [&](const Eigen::Vector3d& v) -> Eigen::Vector3d {
    return v - axis * axis.dot(v);
  };
  const Eigen::Vector3d between = normal_part(b.posed().r - a.posed().r);
  if (between.norm() > tolerance) return between.normalized();
  // Q e_z is normal to its own capsule's axis; one of the two is long enough (1/2 at least when
  // the other is not, or both are the axis' normal).
  const Eigen::Vector3d z_a = normal_part(a.face_normal());
  return (z_a.norm() >= 0.5 ? z_a : normal_part(b.face_normal())).normalized();
}

NormalSource facet_source(const DeepestFacet& facet, const CoreOutline& a, const CoreOutline& b) {
  NormalSource source;
  switch (facet.kind) {
    case DeepestFacet::Kind::kFace: {
      const CoreOutline& face = facet.face_core == 0 ? a : b;
      source.kind = NormalSource::Kind::kFace;
      source.face_core = facet.face_core;
      source.sign = facet.normal.dot(face.face_normal()) > 0.0 ? 1.0 : -1.0;
      break;
    }
    case DeepestFacet::Kind::kEdges: {
      const Eigen::Vector3d e = a.edge(facet.edges[0]).direction;
      const Eigen::Vector3d f = b.edge(facet.edges[1]).direction;
      source.kind = NormalSource::Kind::kEdges;
      source.sign = facet.normal.dot(detail::stable_cross(e, f)) > 0.0 ? 1.0 : -1.0;
      source.edge_directions = {a.posed().attitude.matrix().transpose() * e,
                                b.posed().attitude.matrix().transpose() * f};
      break;
    }
    case DeepestFacet::Kind::kNone:
      source.kind = NormalSource::Kind::kFixed;
      break;
  }
  return source;
}

CoreOutline outline(const Capsule&, const PosedCore& posed, const PolygonView*) {
  return CoreOutline(posed);
}
CoreOutline outline(const PaddedPolygon&, const PosedCore& posed, const PolygonView* view) {
  return CoreOutline(*view, posed);
}

std::optional<PolygonView> polygon_view(const Capsule&, const PairFrame&) { return std::nullopt; }
std::optional<PolygonView> polygon_view(const PaddedPolygon& polygon, const PairFrame& frame) {
  return PolygonView(polygon, frame.inverse_scale);
}

// x2 - x1: the two sides' points, from the first core's to the second's, in their frame.
Eigen::Vector3d sides_difference(const SignedSolution& solution, const PosedCore& pa,
                                 const PosedCore& pb) {
  const Eigen::Vector3d x1 = pa.r + pa.attitude.matrix() * solution.sides[0].body_point;
  const Eigen::Vector3d x2 = pb.r + pb.attitude.matrix() * solution.sides[1].body_point;
  return x2 - x1;
}

// Apart: the normal's source by contact_normal.hpp's rule (d / |d| or the features' normal,
// whichever is the better conditioned in the frame whose unit is `unit`), and the normal from it.
void set_apart_normal(SignedSolution& solution, const PosedCore& pa, const PosedCore& pb,
                      const Eigen::Vector3d& difference, double unit) {
  solution.source =
      detail::points_normal_source(pa, solution.sides[0], pb, solution.sides[1], difference, unit);
  solution.normal = detail::source_normal(solution.source, pa, pb, difference);
}

template <class ShapeA, class ShapeB>
SignedSolution solve_in_order(const ShapeA& a, const PosedCore& pa, const ShapeB& b,
                              const PosedCore& pb, const PairFrame& frame) {
  SignedSolution solution;
  solution.sides = detail::fast_sides(a, pa, b, pb, frame);
  const Eigen::Vector3d difference = sides_difference(solution, pa, pb);
  const double apart = difference.norm();
  const double tolerance = detail::search_tolerances(pa, pb, frame).intersection;
  if (apart > tolerance) {
    solution.gap = apart;
    set_apart_normal(solution, pa, pb, difference, frame.unit);
    return solution;
  }
  const std::optional<PolygonView> view_a = polygon_view(a, frame);
  const std::optional<PolygonView> view_b = polygon_view(b, frame);
  const CoreOutline outline_a = outline(a, pa, view_a ? &*view_a : nullptr);
  const CoreOutline outline_b = outline(b, pb, view_b ? &*view_b : nullptr);
  solution.penetrating = true;
  // Cores within the tolerance of each other as a whole: every point of a core is within its size
  // of its origin, so every x1 - x2 and every facet of the cores' difference is within
  // size_a + size_b + |r_b - r_a| of zero. Every depth is then a tie with touching, which is the
  // answer (s = 0); the search would only visit those ties, all of them (cores below 1e-140 of
  // their radii keep the frame's tolerances, solve_at_cores_scale: crossing needles 1e-145 long
  // beside radii of 1 took 1.5 s at 8,000 vertices, growing as k^2).
  if (pa.size + pb.size + (pb.r - pa.r).norm() <= tolerance) {
    solution.source.kind = NormalSource::Kind::kFixed;
    solution.normal = fallback_normal(outline_a, outline_b, tolerance);
    return solution;
  }
  const DeepestFacet facet = detail::deepest_facet(outline_a, outline_b, tolerance);
  solution.source = facet_source(facet, outline_a, outline_b);
  if (facet.kind == DeepestFacet::Kind::kNone) {
    solution.normal = fallback_normal(outline_a, outline_b, tolerance);
    return solution;  // s = 0: the segments (or points) meet
  }
  solution.gap = -facet.depth;
  solution.normal = facet.normal;
  // An edge pair's normal from e x f where that is the better conditioned, as for the closest
  // points (contact_normal.hpp); the search took it from the witnesses (penetration.hpp).
  if (facet.kind == DeepestFacet::Kind::kEdges &&
      detail::stable_cross(outline_a.edge(facet.edges[0]).direction,
                           outline_b.edge(facet.edges[1]).direction)
              .norm() >= facet.depth) {
    const Eigen::Vector3d crossed = detail::source_normal(solution.source, pa, pb, facet.normal);
    // (Only if it agrees with the witnesses' direction to that direction's uncertainty.)
    if ((crossed - facet.normal).norm() <= 1e-12 * (1.0 + 1.0 / facet.depth)) {
      solution.normal = crossed;
    }
  }
  // Touching, or a flat D, leave the closest points as they are (the middle of the cores'
  // intersection), as does the search's fallback (penetration.hpp).
  if (facet.witnesses) solution.sides = *facet.witnesses;
  return solution;
}

template <class ShapeA, class ShapeB>
SignedSolution solve(const ShapeA& a, const PosedCore& pa, const ShapeB& b, const PosedCore& pb,
                     const PairFrame& frame) {
  return solve_in_order(a, pa, b, pb, frame);
}

// Two polygons are solved in solve_b_as_a's order (pair_setup.hpp), as their proximity is, so
// that both orders of the arguments get the same answer where the search's choice is free (the
// normal of coplanar overlapping polygons, +-z alike, was the first argument's face normal in
// both orders: a hostile review). The solution is then turned back: the sides swapped, the
// normal, from the first argument's core to the second's, negated, and its source with it. A
// face normal sign * Q_face e_z becomes -sign * Q_face e_z of the same core, and an edge pair's
// sign * unit(e x f) is sign * unit(f x e) of the swapped edges.
SignedSolution solve(const PaddedPolygon& a, const PosedCore& pa, const PaddedPolygon& b,
                     const PosedCore& pb, const PairFrame& frame) {
  if (!detail::solve_b_as_a(a, pa, b, pb)) return solve_in_order(a, pa, b, pb, frame);
  const detail::SwappedCores cores = detail::b_first(pa, pb);
  SignedSolution solution = solve_in_order(b, cores.first, a, cores.second, frame);
  std::swap(solution.sides[0], solution.sides[1]);
  solution.normal = -solution.normal;
  NormalSource& source = solution.source;
  if (source.kind == NormalSource::Kind::kFace) {
    source.face_core = 1 - source.face_core;
    source.sign = -source.sign;
  } else if (source.kind == NormalSource::Kind::kEdges) {
    std::swap(source.edge_directions[0], source.edge_directions[1]);
  }
  return solution;
}

// Cores below 1e-100 of the frame's units (their radii make the scene) keep the frame's
// tolerances (pair_frame.hpp, core_tolerances: products of two core lengths would come near
// underflow there), which are then far above the cores, and the penetration search met every
// facet: crossing needles 1e-105 long beside radii of 1 took 1.8 s at 8,000 vertices and 7.7 s at
// 16,000, growing as k^2. Such cores are solved in a frame of their own, the one make_pair_frame
// gives them without their radii, where they are of the frame's size and their own tolerances
// apply, and the solution is carried back by the ratio of the two frames' scales, a power of two,
// exactly: the gap and the points' body coordinates scale, the normal, its source and the points'
// free directions (directions) do not. The cores' scene is the larger core size and the distance
// between the body origins, as in core_tolerances. Only down to 1e-140: the result is still built
// in the radii's frame (signed_distance_result.hpp), whose derivatives take products of the gap
// with itself, and a gap that this search resolves, 1e-12 of the cores, stays above 1e-152 there,
// its square a normal double (below ~1e-160 of the radii the points' Jacobian came out infinite:
// a hostile review). Smaller cores keep the frame's tolerances, touching at any gap (solve_in_order
// answers them without a search).
template <class ShapeA, class ShapeB>
SignedSolution solve_at_cores_scale(const ShapeA& a, const Pose& pose_a, const PosedCore& pa,
                                    const ShapeB& b, const Pose& pose_b, const PosedCore& pb,
                                    const PairFrame& frame) {
  const double cores = std::max({pa.size, pb.size, (pb.r - pa.r).norm()});
  if (!(cores >= 1e-140 && cores < 1e-100)) return solve(a, pa, b, pb, frame);
  const PairFrame core_frame = detail::make_pair_frame(
      detail::core_size(a), 0.0, detail::core_size(b), 0.0, pose_a.r(), pose_b.r());
  const PosedCore core_a = detail::posed_core(a, pose_a, pose_a.r(), core_frame);
  const PosedCore core_b = detail::posed_core(b, pose_b, pose_a.r(), core_frame);
  SignedSolution solution = solve(a, core_a, b, core_b, core_frame);
  const double to_frame = core_frame.scale * frame.inverse_scale;
  solution.gap *= to_frame;
  for (detail::ClosestFeature& side : solution.sides) side.body_point *= to_frame;
  if (!solution.penetrating) {
    // The normal's source decided again where the result is built. Apart, it was chosen for the
    // cores' frame, where d = x2 - x1 is as large as the cores and d / |d| is accurate; in the
    // radii's frame the points' motion carries errors of ulps of the radii, which d / |d|'s
    // derivative divides by |d|: the normal's Jacobian came out 1e90 to 1e117 times too large
    // for cores 1e-107 to 1e-134 of their radii (a hostile review, against the same scene with
    // the cores 2^m larger). There contact_normal.hpp's rule takes the features' normal (a face's,
    // or e x f) wherever it is the better conditioned, as it does for such cores' proximity.
    set_apart_normal(solution, pa, pb, sides_difference(solution, pa, pb), frame.unit);
  }
  return solution;
}

template <class Result, class ShapeA, class ShapeB>
Result query(const ShapeA& a, const Pose& pose_a, const ShapeB& b, const Pose& pose_b) {
  const PairFrame frame = detail::make_pair_frame(
      detail::core_size(a), a.radius(), detail::core_size(b), b.radius(), pose_a.r(), pose_b.r());
  const PosedCore posed_a = detail::posed_core(a, pose_a, pose_a.r(), frame);
  const PosedCore posed_b = detail::posed_core(b, pose_b, pose_a.r(), frame);
  const SignedSolution solution =
      solve_at_cores_scale(a, pose_a, posed_a, b, pose_b, posed_b, frame);
  if constexpr (std::is_same_v<Result, SignedDistanceHessian>) {
    // measure_hessian.hpp with w = -normal (the distance's gradient is d(P_1 - P_2)/dx' w).
    SignedDistanceHessian out;
    static_cast<SignedDistanceJacobian&>(out) = detail::make_signed_distance_jacobian(
        frame, pose_a, posed_a, pose_b, posed_b, solution, &out.normal_jacobian);
    out.hessian = detail::measure_hessian(pose_a, pose_b, out.core_points, out.core_points_jacobian,
                                          -out.normal, -out.normal_jacobian);
    // A normal d / |d| turns at 1 / |d| per unit of motion, which exceeds the double range when
    // the gap is below 1 / DBL_MAX ~ 5.6e-309 (a scene of subnormal numbers: fuzz_proximity, two
    // points 5.2e-320 apart). There the normal is held fixed, as it is where the cores touch (the
    // one-sided choice at a gap of zero), rather than returning infinities.
    if (!out.normal_jacobian.allFinite() || !out.hessian.allFinite()) {
      out.normal_jacobian.setZero();
      out.hessian =
          detail::measure_hessian(pose_a, pose_b, out.core_points, out.core_points_jacobian,
                                  -out.normal, Eigen::Matrix<double, 3, 14>::Zero());
    }
    return out;
  } else if constexpr (std::is_same_v<Result, SignedDistanceJacobian>) {
    return detail::make_signed_distance_jacobian(frame, pose_a, posed_a, pose_b, posed_b, solution);
  } else {
    return detail::make_signed_distance(frame, pose_a, posed_a, pose_b, posed_b, solution);
  }
}

}  // namespace

SignedDistance signed_distance(const Capsule& a, const Pose& pose_a, const Capsule& b,
                               const Pose& pose_b) {
  return query<SignedDistance>(a, pose_a, b, pose_b);
}
SignedDistance signed_distance(const Capsule& a, const Pose& pose_a, const PaddedPolygon& b,
                               const Pose& pose_b) {
  return query<SignedDistance>(a, pose_a, b, pose_b);
}
SignedDistance signed_distance(const PaddedPolygon& a, const Pose& pose_a, const Capsule& b,
                               const Pose& pose_b) {
  return query<SignedDistance>(a, pose_a, b, pose_b);
}
SignedDistance signed_distance(const PaddedPolygon& a, const Pose& pose_a, const PaddedPolygon& b,
                               const Pose& pose_b) {
  return query<SignedDistance>(a, pose_a, b, pose_b);
}
SignedDistance signed_distance(const Shape& a, const Pose& pose_a, const Shape& b,
                               const Pose& pose_b) {
  return std::visit(
      [&](const auto& shape_a, const auto& shape_b) {
        return query<SignedDistance>(shape_a, pose_a, shape_b, pose_b);
      },
      a, b);
}

SignedDistanceJacobian signed_distance_jacobian(const Capsule& a, const Pose& pose_a,
                                                const Capsule& b, const Pose& pose_b) {
  return query<SignedDistanceJacobian>(a, pose_a, b, pose_b);
}
SignedDistanceJacobian signed_distance_jacobian(const Capsule& a, const Pose& pose_a,
                                                const PaddedPolygon& b, const Pose& pose_b) {
  return query<SignedDistanceJacobian>(a, pose_a, b, pose_b);
}
SignedDistanceJacobian signed_distance_jacobian(const PaddedPolygon& a, const Pose& pose_a,
                                                const Capsule& b, const Pose& pose_b) {
  return query<SignedDistanceJacobian>(a, pose_a, b, pose_b);
}
SignedDistanceJacobian signed_distance_jacobian(const PaddedPolygon& a, const Pose& pose_a,
                                                const PaddedPolygon& b, const Pose& pose_b) {
  return query<SignedDistanceJacobian>(a, pose_a, b, pose_b);
}
SignedDistanceJacobian signed_distance_jacobian(const Shape& a, const Pose& pose_a, const Shape& b,
                                                const Pose& pose_b) {
  return std::visit(
      [&](const auto& shape_a, const auto& shape_b) {
        return query<SignedDistanceJacobian>(shape_a, pose_a, shape_b, pose_b);
      },
      a, b);
}

SignedDistanceHessian signed_distance_hessian(const Shape& a, const Pose& pose_a, const Shape& b,
                                              const Pose& pose_b) {
  return std::visit(
      [&](const auto& shape_a, const auto& shape_b) {
        return query<SignedDistanceHessian>(shape_a, pose_a, shape_b, pose_b);
      },
      a, b);
}

}  // namespace diffpills
