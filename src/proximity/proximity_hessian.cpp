// The Hessian of phi with respect to the poses (proximity.hpp): measure_hessian.hpp with
// w = 2 (p1 - p2), the gradient of |p1 - p2|^2, and dw = 2 d(p1 - p2)/dx from the closest points'
// Jacobians. Where the cores intersect, phi is -(R1 + R2)^2 on a neighbourhood and H = 0.
#include "diffpills/proximity.hpp"
#include "measure_hessian.hpp"

namespace diffpills {

ProximityHessian proximity_hessian(const Shape& a, const Pose& pose_a, const Shape& b,
                                   const Pose& pose_b, const ProximityOptions& options) {
  ProximityHessian out;
  static_cast<ProximityJacobian&>(out) = proximity_jacobian(a, pose_a, b, pose_b, options);
  if (out.cores_intersect) return out;
  const Eigen::Vector3d w = 2.0 * (out.core_points[0] - out.core_points[1]);
  const Eigen::Matrix<double, 3, 14> dw =
      2.0 * (out.core_points_jacobian.topRows<3>() - out.core_points_jacobian.bottomRows<3>());
  out.hessian =
      detail::measure_hessian(pose_a, pose_b, out.core_points, out.core_points_jacobian, w, dw);
  return out;
}

}  // namespace diffpills
