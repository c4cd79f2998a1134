// The Hessian of phi with respect to the poses (proximity.hpp).
//
// With the closest points written through their body coordinates, p_i = P_i(x, xi_i) = r_i +
// Q(q_i) xi_i for x = [r1 q1 r2 q2], the envelope theorem gives the gradient as a function of x and
// of the optimal xi = xi(x):
//
//   g(x) = G(x, xi(x)),   G(x, xi) = 2 J_f' e,   e = P_1 - P_2,   J_f = d(P_1 - P_2)/dx at fixed
//   xi.
//
// Differentiating once more, with J = de/dx the total Jacobian of e (the closest points'
// Jacobians of proximity_jacobian, by the implicit function theorem) and dxi_i/dx =
// Q_i' (J_i - J_f,i) (from dp_i = J_f,i dx + Q_i dxi_i):
//
//   H = 2 J_f' J                                        (J_f' J_f + J_f' (J - J_f))
//     + 2 blockdiag_q( hess_q1 [e . Q(q1) xi_1], -hess_q2 [e . Q(q2) xi_2] )
//                                                       (e's second derivatives at fixed xi)
//     + 2 rows q1: A_1' dxi_1/dx,  - 2 rows q2: A_2' dxi_2/dx
//                                                       (the q-gradient's motion with xi)
//
// with A_i = d(Q(q_i)' e)/dq_i (3 x 4), since e . Q(q) xi = (Q(q)' e) . xi. The second term uses
// rotate_hessian (rotation.hpp). H is symmetric where phi is twice differentiable; the computed
// one is symmetrized, (H + H') / 2, which removes rounding only. Where the cores intersect, phi
// is -(R1 + R2)^2 on a neighbourhood and H = 0.
#include <Eigen/Core>

#include "diffpills/proximity.hpp"
#include "diffpills/rotation.hpp"
#include "unit_quaternion.hpp"

namespace diffpills {

ProximityHessian proximity_hessian(const Shape& a, const Pose& pose_a, const Shape& b,
                                   const Pose& pose_b, const ProximityOptions& options) {
  ProximityHessian out;
  static_cast<ProximityJacobian&>(out) = proximity_jacobian(a, pose_a, b, pose_b, options);
  if (out.cores_intersect) return out;
  const Eigen::Vector3d e = out.core_points[0] - out.core_points[1];
  const std::array<const Pose*, 2> poses = {&pose_a, &pose_b};
  // Per side: the point's body coordinates, its Jacobian at fixed xi, and its xi's Jacobian.
  Eigen::Matrix<double, 3, 14> fixed_difference = Eigen::Matrix<double, 3, 14>::Zero();
  std::array<Eigen::Matrix<double, 3, 14>, 2> xi_jacobian;
  std::array<Eigen::Vector3d, 2> xi;
  const std::array<detail::UnitQuaternion, 2> attitudes = {detail::UnitQuaternion(pose_a.q()),
                                                           detail::UnitQuaternion(pose_b.q())};
  for (int side = 0; side < 2; ++side) {
    const auto index = static_cast<std::size_t>(side);
    const Eigen::Matrix3d& rotation = attitudes[index].matrix();
    xi[index] = rotation.transpose() * (out.core_points[index] - poses[index]->r());
    Eigen::Matrix<double, 3, 14> fixed = Eigen::Matrix<double, 3, 14>::Zero();
    fixed.block<3, 3>(0, 7 * side) = Eigen::Matrix3d::Identity();
    fixed.block<3, 4>(0, 7 * side + 3) = attitudes[index].rotate_jacobian(xi[index]);
    xi_jacobian[index] =
        rotation.transpose() * (out.core_points_jacobian.middleRows<3>(3 * side) - fixed);
    fixed_difference += side == 0 ? fixed : Eigen::Matrix<double, 3, 14>(-fixed);
  }
  const Eigen::Matrix<double, 3, 14> total =
      out.core_points_jacobian.topRows<3>() - out.core_points_jacobian.bottomRows<3>();
  Eigen::Matrix<double, 14, 14> H = 2.0 * fixed_difference.transpose() * total;
  for (int side = 0; side < 2; ++side) {
    const Pose& pose = *poses[static_cast<std::size_t>(side)];
    const double sign = side == 0 ? 2.0 : -2.0;
    const int q = 7 * side + 3;
    H.block<4, 4>(q, q) += sign * rotate_hessian(pose.q(), xi[static_cast<std::size_t>(side)], e);
    H.middleRows<4>(q) +=
        sign * attitudes[static_cast<std::size_t>(side)].rotate_transpose_jacobian(e).transpose() *
        xi_jacobian[static_cast<std::size_t>(side)];
  }
  out.hessian = 0.5 * (H + H.transpose());
  return out;
}

}  // namespace diffpills
