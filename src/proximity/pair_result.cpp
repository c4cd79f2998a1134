#include "pair_result.hpp"

#include "contact_normal.hpp"
#include "phi_hessian.hpp"
#include "point_motion.hpp"

namespace diffpills::detail {
namespace {

enum class NormalRule { kClosestPoints, kOrigins, kBodyAxis };

// The normal's rule (see proximity.hpp): the closest-point direction while the cores are apart by
// more than the frame's tolerance (1e-12 of the scene's size); otherwise the direction between the
// body origins, or shape 1's body z axis if those coincide too. Compared squared, to spare square
// roots on the hot path; in the frame's units no square under- or overflows.
NormalRule normal_rule(const PairFrame& frame, const PosedCore& a, const PosedCore& b,
                       const Eigen::Vector3d& p1, const Eigen::Vector3d& p2) {
  const double tolerance2 = frame.tolerance * frame.tolerance;
  if ((p2 - p1).squaredNorm() > tolerance2) return NormalRule::kClosestPoints;
  if ((b.r - a.r).squaredNorm() > tolerance2) return NormalRule::kOrigins;
  return NormalRule::kBodyAxis;
}

// The frame's results (see the header) in the inputs' units.
void restore_units(const PairFrame& frame, Proximity& result) {
  const double s = frame.scale;
  result.phi = result.phi * s * s;  // two products: s * s alone may underflow where phi does not
  result.gradient.segment<3>(0) *= s;
  // The quaternion parts by two products too: s * s goes subnormal below 2^-511 and is zero
  // below 2^-537, where they are neither (a hostile review: a scene of 2^-538 with |q| = 2e-40
  // lost its quaternion gradient).
  result.gradient.segment<4>(3) = result.gradient.segment<4>(3) * s * s;
  result.gradient.segment<3>(7) *= s;
  result.gradient.segment<4>(10) = result.gradient.segment<4>(10) * s * s;
}

}  // namespace

Proximity make_proximity(const PairFrame& frame, const Pose& pose_a, const PosedCore& a,
                         const ClosestFeature& side_a, const Pose& pose_b, const PosedCore& b,
                         const ClosestFeature& side_b) {
  Proximity result;
  const Eigen::Vector3d offset_a = a.attitude.matrix() * side_a.body_point;  // Q u, frame units
  const Eigen::Vector3d offset_b = b.attitude.matrix() * side_b.body_point;
  const Eigen::Vector3d p1 = a.r + offset_a;
  const Eigen::Vector3d p2 = b.r + offset_b;
  const Eigen::Vector3d difference = p1 - p2;
  // phi = |p1 - p2|^2 - (R1 + R2)^2 (eq. caps_prox): the squared distance in the frame, brought
  // to the inputs' units (restore_units), less the radius term in the inputs' units. In the frame
  // (R1 + R2)^2 may underflow to a subnormal, and lose digits, where phi's own scale does not
  // (fuzz_proximity: a radius 1e-158 of the scene gave phi below -(R1 + R2)^2).
  const double radius_sum = a.input_radius + b.input_radius;
  result.phi = difference.squaredNorm();
  // Envelope theorem: d phi = 2 (p1 - p2)' (dp1 - dp2) with the body points held fixed.
  result.gradient.segment<3>(0) = 2.0 * difference;
  result.gradient.segment<4>(3) = 2.0 * a.attitude.rotate_gradient(side_a.body_point, difference);
  result.gradient.segment<3>(7) = -2.0 * difference;
  result.gradient.segment<4>(10) = -2.0 * b.attitude.rotate_gradient(side_b.body_point, difference);

  const NormalRule rule = normal_rule(frame, a, b, p1, p2);
  switch (rule) {
    case NormalRule::kClosestPoints:  // from the features where they fix it (contact_normal.hpp)
      result.normal = source_normal(
          points_normal_source(a, side_a, b, side_b, -difference, frame.unit), a, b, -difference);
      break;
    case NormalRule::kOrigins:
      result.normal = (b.r - a.r).normalized();
      break;
    case NormalRule::kBodyAxis:
      result.normal = a.attitude.matrix().col(2);
      break;
  }
  if (rule != NormalRule::kClosestPoints) {
    // Cores within the tolerance of each other intersect, as documented: phi is -(R1 + R2)^2 and
    // flat. (|p1 - p2|^2, at most the tolerance squared, 1e-24 of the scene's size squared, is
    // dropped: a phi above -(R1 + R2)^2, even positive for bare cores, would say "apart".)
    result.cores_intersect = true;
    result.phi = 0.0;
    result.gradient.setZero();
  }
  restore_units(frame, result);
  result.phi -= radius_sum * radius_sum;
  result.core_points = {pose_a.r() + frame.scale * offset_a, pose_b.r() + frame.scale * offset_b};
  result.points = {
      result.core_points[0] + a.input_radius * result.normal,
      result.core_points[1] - b.input_radius * result.normal};  // eqs. caps_c_1, caps_c_2
  return result;
}

namespace {

// Adds the points' Jacobians to `result`, which holds make_proximity's answer, and returns the
// points' motion they came from.
PointMotion add_point_jacobians(const PairFrame& frame, const PosedCore& a,
                                const ClosestFeature& side_a, const PosedCore& b,
                                const ClosestFeature& side_b, ProximityJacobian& result) {
  const Eigen::Vector3d p1 = a.r + a.attitude.matrix() * side_a.body_point;
  const Eigen::Vector3d p2 = b.r + b.attitude.matrix() * side_b.body_point;

  PointMotion motion = core_point_motion(a, side_a, b, side_b);

  Matrix3x14 dnormal = Matrix3x14::Zero();
  switch (normal_rule(frame, a, b, p1, p2)) {
    case NormalRule::kClosestPoints:
      dnormal = source_normal_motion(
          points_normal_source(a, side_a, b, side_b, p2 - p1, frame.unit), a, b, p2 - p1, motion);
      break;
    case NormalRule::kOrigins: {
      Matrix3x14 d_origins = Matrix3x14::Zero();  // d(r2 - r1)
      d_origins.block<3, 3>(0, 0) = -Eigen::Matrix3d::Identity();
      d_origins.block<3, 3>(0, 7) = Eigen::Matrix3d::Identity();
      dnormal = unit_vector_motion(b.r - a.r, d_origins);
      break;
    }
    case NormalRule::kBodyAxis:
      dnormal.block<3, 4>(0, 3) = a.attitude.rotate_jacobian(Eigen::Vector3d::UnitZ());
      break;
  }
  point_jacobians(frame.scale, a, b, motion, dnormal, result.core_points_jacobian,
                  result.points_jacobian);
  return motion;
}

}  // namespace

ProximityJacobian make_proximity_jacobian(const PairFrame& frame, const Pose& pose_a,
                                          const PosedCore& a, const ClosestFeature& side_a,
                                          const Pose& pose_b, const PosedCore& b,
                                          const ClosestFeature& side_b) {
  ProximityJacobian result;
  static_cast<Proximity&>(result) = make_proximity(frame, pose_a, a, side_a, pose_b, b, side_b);
  add_point_jacobians(frame, a, side_a, b, side_b, result);
  return result;
}

ProximityHessian make_proximity_hessian(const PairFrame& frame, const Pose& pose_a,
                                        const PosedCore& a, const ClosestFeature& side_a,
                                        const Pose& pose_b, const PosedCore& b,
                                        const ClosestFeature& side_b) {
  ProximityHessian result;
  static_cast<Proximity&>(result) = make_proximity(frame, pose_a, a, side_a, pose_b, b, side_b);
  const PointMotion motion = add_point_jacobians(frame, a, side_a, b, side_b, result);
  // Intersecting cores: phi is -(R1 + R2)^2 on a neighbourhood, and the Hessian stays 0.
  if (!result.cores_intersect) {
    phi_hessian(frame.scale, a, side_a, b, side_b, motion, result.hessian);
  }
  return result;
}

// make_proximity_hessian's Proximity and Hessian without the points' Jacobians: phi's Hessian
// needs only the core points' motion, not the normal's motion or the 6 x 14 matrices.
ProximityWithHessian make_proximity_with_hessian(const PairFrame& frame, const Pose& pose_a,
                                                 const PosedCore& a, const ClosestFeature& side_a,
                                                 const Pose& pose_b, const PosedCore& b,
                                                 const ClosestFeature& side_b) {
  ProximityWithHessian result;
  static_cast<Proximity&>(result) = make_proximity(frame, pose_a, a, side_a, pose_b, b, side_b);
  if (!result.cores_intersect) {
    phi_hessian(frame.scale, a, side_a, b, side_b, core_point_motion(a, side_a, b, side_b),
                result.hessian);
  }
  return result;
}

}  // namespace diffpills::detail
