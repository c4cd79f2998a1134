// The public queries: every ordering of the two shapes goes through the same pipeline,
// core parameterization -> pair QP -> solve -> results (see pair_problem.hpp).
#include "diffpills/proximity.hpp"

#include <type_traits>
#include <variant>

#include "core.hpp"
#include "pair_problem.hpp"
#include "pair_result.hpp"
#include "pair_solve.hpp"

namespace diffpills {
namespace {

// Result is Proximity or ProximityJacobian; the pipeline is the same up to the last step.
template <class Result, class ShapeA, class ShapeB>
Result query(const ShapeA& a, const Pose& pose_a, const ShapeB& b, const Pose& pose_b,
             const ProximityOptions& options) {
  const detail::Core core_a = detail::make_core(a);
  const detail::Core core_b = detail::make_core(b);
  const detail::PairProblem problem = detail::make_pair_problem(core_a, pose_a, core_b, pose_b);
  const detail::PairSolution solution = detail::solve_pair(problem, options.method);
  if constexpr (std::is_same_v<Result, ProximityJacobian>) {
    return detail::make_proximity_jacobian(problem, solution);
  } else {
    return detail::make_proximity(problem, solution);
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
