#include "core_solution.hpp"

namespace diffpills::detail {

namespace {

PosedCore make_posed_core(const Pose& pose, double radius, double size) {
  return {pose.r(), UnitQuaternion(pose.q()), radius, size};
}

}  // namespace

PosedCore posed_core(const Capsule& capsule, const Pose& pose) {
  return make_posed_core(pose, capsule.radius(), capsule.length());
}

PosedCore posed_core(const PaddedPolygon& polygon, const Pose& pose) {
  return make_posed_core(pose, polygon.radius(), polygon.extent());
}

}  // namespace diffpills::detail
