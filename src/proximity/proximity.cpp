// The public queries. Method::kDefault sends each pair to its exact fast solver (fast_paths.hpp);
// Method::kInteriorPoint builds the pair's QP (pair_problem.hpp) and solves it with the paper's
// interior-point method. Both hand the two sides of the solution to the same result builder.
#include "diffpills/proximity.hpp"

#include <type_traits>
#include <utility>
#include <variant>

#include "core.hpp"
#include "core_solution.hpp"
#include "fast_paths.hpp"
#include "pair_problem.hpp"
#include "pair_result.hpp"
#include "pair_solve.hpp"

namespace diffpills {
namespace {

using detail::CoreSolution;
using detail::PosedCore;
using Sides = std::array<CoreSolution, 2>;

Sides fast_sides(const Capsule& a, const PosedCore& pa, const Capsule& b, const PosedCore& pb) {
  return detail::solve_capsule_capsule(a, pa, b, pb);
}
Sides fast_sides(const Capsule& a, const PosedCore& pa, const PaddedPolygon& b,
                 const PosedCore& pb) {
  return detail::solve_capsule_polygon(a, pa, b, pb);
}
Sides fast_sides(const PaddedPolygon& a, const PosedCore& pa, const Capsule& b,
                 const PosedCore& pb) {
  const Sides swapped = detail::solve_capsule_polygon(b, pb, a, pa);
  return {swapped[1], swapped[0]};
}
Sides fast_sides(const PaddedPolygon& a, const PosedCore& pa, const PaddedPolygon& b,
                 const PosedCore& pb) {
  return detail::solve_polygon_polygon(a, pa, b, pb);
}

Sides reference_sides(const detail::Core& core_a, const Pose& pose_a, const detail::Core& core_b,
                      const Pose& pose_b) {
  const detail::PairProblem problem = detail::make_pair_problem(core_a, pose_a, core_b, pose_b);
  return detail::core_solutions(problem, detail::solve_pair(problem));
}

// Result is Proximity or ProximityJacobian; everything but the last step is shared.
template <class Result, class ShapeA, class ShapeB>
Result query(const ShapeA& a, const Pose& pose_a, const ShapeB& b, const Pose& pose_b,
             const ProximityOptions& options) {
  const PosedCore posed_a = detail::posed_core(a, pose_a);
  const PosedCore posed_b = detail::posed_core(b, pose_b);
  const Sides sides =
      options.method == Method::kInteriorPoint
          ? reference_sides(detail::make_core(a), pose_a, detail::make_core(b), pose_b)
          : fast_sides(a, posed_a, b, posed_b);
  if constexpr (std::is_same_v<Result, ProximityJacobian>) {
    return detail::make_proximity_jacobian(posed_a, sides[0], posed_b, sides[1]);
  } else {
    return detail::make_proximity(posed_a, sides[0], posed_b, sides[1]);
  }
}

}  // namespace

Proximity proximity(const Capsule& a, const Pose& pose_a, const Capsule& b, const Pose& pose_b,
                    const ProximityOptions& options) {
  return query<Proximity>(a, pose_a, b, pose_b, options);
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
        return query<Proximity>(shape_a, pose_a, shape_b, pose_b, options);
      },
      a, b);
}

ProximityJacobian proximity_jacobian(const Capsule& a, const Pose& pose_a, const Capsule& b,
                                     const Pose& pose_b, const ProximityOptions& options) {
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
        return query<ProximityJacobian>(shape_a, pose_a, shape_b, pose_b, options);
      },
      a, b);
}

}  // namespace diffpills
