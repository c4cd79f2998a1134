#include "signed_distance_result.hpp"

#include <Eigen/Geometry>

#include "penetration.hpp"
#include "point_motion.hpp"
#include "unit_quaternion.hpp"

namespace diffpills::detail {
namespace {

// d(sign * unit(a x b)) with a = Q1 u, b = Q2 v: d(a x b) = da x b + a x db = -[b]x da + [a]x db.
Matrix3x14 edge_normal_motion(const PosedCore& a, const PosedCore& b, const NormalSource& source) {
  const Eigen::Vector3d edge_a = a.attitude.matrix() * source.edge_directions[0];
  const Eigen::Vector3d edge_b = b.attitude.matrix() * source.edge_directions[1];
  Matrix3x14 d_cross = Matrix3x14::Zero();
  d_cross.middleCols<4>(3) = -skew(edge_b) * a.attitude.rotate_jacobian(source.edge_directions[0]);
  d_cross.middleCols<4>(10) = skew(edge_a) * b.attitude.rotate_jacobian(source.edge_directions[1]);
  return source.sign * unit_vector_motion(stable_cross(edge_a, edge_b), d_cross);
}

}  // namespace

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

SignedDistanceJacobian make_signed_distance_jacobian(const PairFrame& frame, const Pose& pose_a,
                                                     const PosedCore& a, const Pose& pose_b,
                                                     const PosedCore& b,
                                                     const SignedSolution& solution) {
  SignedDistanceJacobian result;
  static_cast<SignedDistance&>(result) =
      make_signed_distance(frame, pose_a, a, pose_b, b, solution);
  const auto& [side_a, side_b] = solution.sides;
  const Eigen::Vector3d x1 = a.r + a.attitude.matrix() * side_a.body_point;
  const Eigen::Vector3d x2 = b.r + b.attitude.matrix() * side_b.body_point;
  const PointMotion motion = core_point_motion(a, side_a, b, side_b);

  Matrix3x14 dnormal = Matrix3x14::Zero();
  switch (solution.source.kind) {
    case NormalSource::Kind::kClosestPoints:
      dnormal = unit_vector_motion(x2 - x1, motion.dp2 - motion.dp1);
      break;
    case NormalSource::Kind::kFace: {
      const PosedCore& face = solution.source.face_core == 0 ? a : b;
      dnormal.middleCols<4>(solution.source.face_core == 0 ? 3 : 10) =
          solution.source.sign * face.attitude.rotate_jacobian(Eigen::Vector3d::UnitZ());
      break;
    }
    case NormalSource::Kind::kEdges:
      dnormal = edge_normal_motion(a, b, solution.source);
      break;
    case NormalSource::Kind::kFixed:
      break;
  }
  point_jacobians(frame.scale, a, b, motion, dnormal, result.core_points_jacobian,
                  result.points_jacobian);
  return result;
}

}  // namespace diffpills::detail
