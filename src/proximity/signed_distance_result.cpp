#include "signed_distance_result.hpp"

#include <Eigen/Geometry>

#include "point_motion.hpp"

namespace diffpills::detail {
SignedDistance make_signed_distance(const PairFrame& frame, const Pose& pose_a, const PosedCore& a,
                                    const Pose& pose_b, const PosedCore& b,
                                    const SignedSolution& solution) {
  SignedDistance result;
  const double s = frame.scale;
  const Eigen::Vector3d& n = solution.normal;
  const Eigen::Vector3d& u1 = solution.sides[0].body_point;
  const Eigen::Vector3d& u2 = solution.sides[1].body_point;
  // The radius term in the inputs' units (posed_core.hpp): exact, also for radii that are
  // subnormal in the frame; gap * s is exact too, so scaling by 2^k stays exact.
  result.distance = solution.gap * s - (a.input_radius + b.input_radius);
  result.penetrating = solution.penetrating;
  result.normal = n;
  // Envelope theorem (see the header): d distance = n . (dx2 - dx1), body points fixed.
  result.gradient.segment<3>(0) = -n;
  result.gradient.segment<4>(3) = -a.attitude.rotate_gradient(u1, n) * s;
  result.gradient.segment<3>(7) = n;
  result.gradient.segment<4>(10) = b.attitude.rotate_gradient(u2, n) * s;
  result.core_points = {pose_a.r() + s * (a.attitude.matrix() * u1),
                        pose_b.r() + s * (b.attitude.matrix() * u2)};
  result.points = {result.core_points[0] + a.input_radius * n,
                   result.core_points[1] - b.input_radius * n};
  return result;
}

SignedDistanceJacobian make_signed_distance_jacobian(
    const PairFrame& frame, const Pose& pose_a, const PosedCore& a, const Pose& pose_b,
    const PosedCore& b, const SignedSolution& solution,
    Eigen::Matrix<double, 3, 14>* normal_jacobian) {
  SignedDistanceJacobian result;
  static_cast<SignedDistance&>(result) =
      make_signed_distance(frame, pose_a, a, pose_b, b, solution);
  const auto& [side_a, side_b] = solution.sides;
  const Eigen::Vector3d x1 = a.r + a.attitude.matrix() * side_a.body_point;
  const Eigen::Vector3d x2 = b.r + b.attitude.matrix() * side_b.body_point;
  const PointMotion motion = core_point_motion(a, side_a, b, side_b);

  const Matrix3x14 dnormal = source_normal_motion(solution.source, a, b, x2 - x1, motion);
  point_jacobians(frame.scale, a, b, motion, dnormal, result.core_points_jacobian,
                  result.points_jacobian);
  if (normal_jacobian != nullptr) {
    // The frame's lengths are the inputs' over the scale: d/dr gains 1 / scale; the normal and
    // the quaternions are unitless.
    *normal_jacobian = dnormal;
    for (const int column : {0, 7}) normal_jacobian->middleCols<3>(column) /= frame.scale;
  }
  return result;
}

}  // namespace diffpills::detail
