// The public queries. Each builds the pair's frame (pair_frame.hpp) and its two posed cores, then
// Method::kDefault sends the pair to its exact fast solver (fast_paths.hpp) and
// Method::kInteriorPoint builds the pair's QP (pair_problem.hpp) and solves it with the paper's
// interior-point method. Both hand the two sides of the solution to the same result builder.
// proximity(), proximity_jacobian() and proximity_hessian() of two capsules in the generic case
// skip all of this for one fused pass (capsule_proximity.hpp).
#include "diffpills/proximity.hpp"

#include <type_traits>
#include <utility>
#include <variant>

#include "capsule_proximity.hpp"
#include "pair_frame.hpp"
#include "pair_problem.hpp"
#include "pair_result.hpp"
#include "pair_setup.hpp"
#include "pair_solve.hpp"
#include "parametric_core.hpp"
#include "polygon_features.hpp"
#include "posed_core.hpp"

namespace diffpills {
namespace {

using detail::PairFrame;
using detail::PolygonView;
using detail::PosedCore;
using detail::Sides;

detail::ParametricCore parametric_core(const Capsule&, const PosedCore& posed, const PairFrame&) {
  return detail::make_parametric_capsule(posed.size);
}
detail::ParametricCore parametric_core(const PaddedPolygon& polygon, const PosedCore&,
                                       const PairFrame& frame) {
  return detail::make_parametric_polygon(PolygonView(polygon, frame.inverse_scale));
}

// The interior-point method sees a polygon as its rows alone, in floating point. At a spike
// sharper than the rounding (two nearly antiparallel sides whose apex a dropped row fixed to
// below the rounding) points beyond the apex satisfy both sides to rounding: fuzz_proximity found
// a needle 5e-15 wide whose interior point lay 0.4 beyond its tip, phi 0.16 too small. Its point
// is therefore checked against the polygon with the spikes' bevels (polygon_features.hpp), to the
// method's own tolerance (1e-8 of the polygon's extent), and one outside is reported as
// SolverError rather than returned.
void check_inside(const Capsule&, const detail::ClosestFeature&, const PairFrame&) {}
void check_inside(const PaddedPolygon& polygon, const detail::ClosestFeature& side,
                  const PairFrame& frame) {
  const PolygonView view(polygon, frame.inverse_scale);
  if (!detail::contains(view, side.body_point.head<2>(), 1e-8 * view.extent())) {
    throw SolverError(
        "diffpills: the interior-point method's point lies outside a spike of the polygon "
        "(a sliver sharper than its tolerance); the default method resolves it");
  }
}

template <class ShapeA, class ShapeB>
Sides reference_sides(const ShapeA& a, const PosedCore& pa, const ShapeB& b, const PosedCore& pb,
                      const PairFrame& frame) {
  const detail::ParametricCore core_a = parametric_core(a, pa, frame);
  const detail::ParametricCore core_b = parametric_core(b, pb, frame);
  const detail::PairProblem problem = detail::make_pair_problem(core_a, pa, core_b, pb);
  Sides sides = detail::core_solutions(problem, detail::solve_pair(problem));
  check_inside(a, sides[0], frame);
  check_inside(b, sides[1], frame);
  return sides;
}

// Result is Proximity, ProximityJacobian, ProximityHessian or ProximityWithHessian; everything
// but the last step is shared.
template <class Result, class ShapeA, class ShapeB>
Result query(const ShapeA& a, const Pose& pose_a, const ShapeB& b, const Pose& pose_b,
             const ProximityOptions& options) {
  const PairFrame frame = detail::make_pair_frame(
      detail::core_size(a), a.radius(), detail::core_size(b), b.radius(), pose_a.r(), pose_b.r());
  const PosedCore posed_a = detail::posed_core(a, pose_a, pose_a.r(), frame);
  const PosedCore posed_b = detail::posed_core(b, pose_b, pose_a.r(), frame);
  const Sides sides = options.method == Method::kInteriorPoint
                          ? reference_sides(a, posed_a, b, posed_b, frame)
                          : detail::fast_sides(a, posed_a, b, posed_b, frame);
  if constexpr (std::is_same_v<Result, ProximityWithHessian>) {
    return detail::make_proximity_with_hessian(frame, pose_a, posed_a, sides[0], pose_b, posed_b,
                                               sides[1]);
  } else if constexpr (std::is_same_v<Result, ProximityHessian>) {
    return detail::make_proximity_hessian(frame, pose_a, posed_a, sides[0], pose_b, posed_b,
                                          sides[1]);
  } else if constexpr (std::is_same_v<Result, ProximityJacobian>) {
    return detail::make_proximity_jacobian(frame, pose_a, posed_a, sides[0], pose_b, posed_b,
                                           sides[1]);
  } else {
    return detail::make_proximity(frame, pose_a, posed_a, sides[0], pose_b, posed_b, sides[1]);
  }
}

// Two capsules in the generic case (capsule_proximity.hpp) go to their fused second-order pass,
// under the default method; everything else to the general pipeline.
template <class Result, auto fused>
Result fused_or_general(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                        const ProximityOptions& options) {
  const Capsule* capsule_a = std::get_if<Capsule>(&a);
  const Capsule* capsule_b = std::get_if<Capsule>(&b);
  detail::GenericCapsuleSolution solution;
  if (options.method == Method::kDefault && capsule_a != nullptr && capsule_b != nullptr &&
      detail::solve_generic_capsules(*capsule_a, pose_a, *capsule_b, pose_b, solution)) {
    return fused(solution, *capsule_a, pose_a, *capsule_b, pose_b);
  }
  return std::visit(
      [&](const auto& shape_a, const auto& shape_b) {
        return query<Result>(shape_a, pose_a, shape_b, pose_b, options);
      },
      a, b);
}

}  // namespace

// Two capsules in the generic case take one fused pass, half the general pipeline's cost
// (capsule_proximity.hpp), and so do their Jacobians and Hessian. Each result is built in place:
// prvalues returned from both branches.
Proximity proximity(const Capsule& a, const Pose& pose_a, const Capsule& b, const Pose& pose_b,
                    const ProximityOptions& options) {
  if (options.method != Method::kDefault) return query<Proximity>(a, pose_a, b, pose_b, options);
  return detail::generic_capsule_proximity(
      a, pose_a, b, pose_b,
      [](const Capsule& first, const Pose& first_pose, const Capsule& second,
         const Pose& second_pose) {
        return query<Proximity>(first, first_pose, second, second_pose, ProximityOptions{});
      });
}
Proximity proximity(const Capsule& a, const Pose& pose_a, const PaddedPolygon& b,
                    const Pose& pose_b, const ProximityOptions& options) {
  return query<Proximity>(a, pose_a, b, pose_b, options);
}
Proximity proximity(const PaddedPolygon& a, const Pose& pose_a, const Capsule& b,
                    const Pose& pose_b, const ProximityOptions& options) {
  return query<Proximity>(a, pose_a, b, pose_b, options);
}
Proximity proximity(const PaddedPolygon& a, const Pose& pose_a, const PaddedPolygon& b,
                    const Pose& pose_b, const ProximityOptions& options) {
  return query<Proximity>(a, pose_a, b, pose_b, options);
}
Proximity proximity(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                    const ProximityOptions& options) {
  return std::visit(
      [&](const auto& shape_a, const auto& shape_b) {
        return proximity(shape_a, pose_a, shape_b, pose_b, options);
      },
      a, b);
}

ProximityJacobian proximity_jacobian(const Capsule& a, const Pose& pose_a, const Capsule& b,
                                     const Pose& pose_b, const ProximityOptions& options) {
  detail::GenericCapsuleSolution solution;
  if (options.method == Method::kDefault &&
      detail::solve_generic_capsules(a, pose_a, b, pose_b, solution)) {
    return detail::generic_capsule_proximity_jacobian(solution, a, pose_a, b, pose_b);
  }
  return query<ProximityJacobian>(a, pose_a, b, pose_b, options);
}
ProximityJacobian proximity_jacobian(const Capsule& a, const Pose& pose_a, const PaddedPolygon& b,
                                     const Pose& pose_b, const ProximityOptions& options) {
  return query<ProximityJacobian>(a, pose_a, b, pose_b, options);
}
ProximityJacobian proximity_jacobian(const PaddedPolygon& a, const Pose& pose_a, const Capsule& b,
                                     const Pose& pose_b, const ProximityOptions& options) {
  return query<ProximityJacobian>(a, pose_a, b, pose_b, options);
}
ProximityJacobian proximity_jacobian(const PaddedPolygon& a, const Pose& pose_a,
                                     const PaddedPolygon& b, const Pose& pose_b,
                                     const ProximityOptions& options) {
  return query<ProximityJacobian>(a, pose_a, b, pose_b, options);
}
ProximityJacobian proximity_jacobian(const Shape& a, const Pose& pose_a, const Shape& b,
                                     const Pose& pose_b, const ProximityOptions& options) {
  return std::visit(
      [&](const auto& shape_a, const auto& shape_b) {
        return proximity_jacobian(shape_a, pose_a, shape_b, pose_b, options);
      },
      a, b);
}

ProximityHessian proximity_hessian(const Shape& a, const Pose& pose_a, const Shape& b,
                                   const Pose& pose_b, const ProximityOptions& options) {
  return fused_or_general<ProximityHessian, detail::generic_capsule_proximity_hessian>(
      a, pose_a, b, pose_b, options);
}

ProximityWithHessian proximity_with_hessian(const Shape& a, const Pose& pose_a, const Shape& b,
                                            const Pose& pose_b, const ProximityOptions& options) {
  return fused_or_general<ProximityWithHessian, detail::generic_capsule_proximity_with_hessian>(
      a, pose_a, b, pose_b, options);
}

namespace detail {

ProximityHessian general_capsule_proximity_hessian(const Capsule& a, const Pose& pose_a,
                                                   const Capsule& b, const Pose& pose_b) {
  return query<ProximityHessian>(a, pose_a, b, pose_b, ProximityOptions{});
}

}  // namespace detail

}  // namespace diffpills
