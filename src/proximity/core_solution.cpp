#include "core_solution.hpp"

#include "diffpills/rotation.hpp"

namespace diffpills::detail {

PosedCore posed_core(const Capsule& capsule, const Pose& pose) {
  return {pose.r(), pose.q(), rotation_matrix(pose.q()), capsule.radius(), capsule.length()};
}

PosedCore posed_core(const PaddedPolygon& polygon, const Pose& pose) {
  return {pose.r(), pose.q(), rotation_matrix(pose.q()), polygon.radius(), polygon.extent()};
}

}  // namespace diffpills::detail
