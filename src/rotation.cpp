#include "diffpills/rotation.hpp"

#include <Eigen/Geometry>

#include "unit_quaternion.hpp"

namespace diffpills {

// The same bits as UnitQuaternion(q).matrix(), without its derivative map.
Eigen::Matrix3d rotation_matrix(const Eigen::Vector4d& q) {
  return detail::unit_rotation_matrix(q * (1.0 / q.norm()));
}

Eigen::Matrix<double, 3, 4> rotate_jacobian(const Eigen::Vector4d& q, const Eigen::Vector3d& v) {
  return detail::UnitQuaternion(q).rotate_jacobian(v);
}

Eigen::Vector4d rotate_gradient(const Eigen::Vector4d& q, const Eigen::Vector3d& v,
                                const Eigen::Vector3d& w) {
  return detail::UnitQuaternion(q).rotate_gradient(v, w);
}

Eigen::Matrix4d rotate_hessian(const Eigen::Vector4d& q, const Eigen::Vector3d& v,
                               const Eigen::Vector3d& w) {
  return detail::UnitQuaternion(q).rotate_hessian(v, w);
}

Eigen::Matrix<double, 3, 4> rotate_transpose_jacobian(const Eigen::Vector4d& q,
                                                      const Eigen::Vector3d& v) {
  return detail::UnitQuaternion(q).rotate_transpose_jacobian(v);
}

// q (x) p = [w p0 - v.pv ; w pv + p0 v + v x pv], so
// L(q) = [ w  -v^T ; v  w I + [v]x ].
Eigen::Matrix4d left_multiply_matrix(const Eigen::Vector4d& q) {
  Eigen::Matrix4d l;
  l(0, 0) = q(0);
  l.block<1, 3>(0, 1) = -q.tail<3>().transpose();
  l.block<3, 1>(1, 0) = q.tail<3>();
  l.block<3, 3>(1, 1) = q(0) * Eigen::Matrix3d::Identity() + detail::skew(q.tail<3>());
  return l;
}

// p (x) q = [p0 w - pv.v ; p0 v + w pv + pv x v] = [w p0 - v.pv ; w pv + p0 v - v x pv], so
// R(q) = [ w  -v^T ; v  w I - [v]x ].
Eigen::Matrix4d right_multiply_matrix(const Eigen::Vector4d& q) {
  Eigen::Matrix4d r;
  r(0, 0) = q(0);
  r.block<1, 3>(0, 1) = -q.tail<3>().transpose();
  r.block<3, 1>(1, 0) = q.tail<3>();
  r.block<3, 3>(1, 1) = q(0) * Eigen::Matrix3d::Identity() - detail::skew(q.tail<3>());
  return r;
}

Eigen::Matrix<double, 4, 3> attitude_jacobian(const Eigen::Vector4d& q) {
  return left_multiply_matrix(q).rightCols<3>();
}

Eigen::Vector3d attitude_gradient(const Eigen::Vector4d& q, const Eigen::Vector4d& dphi_dq) {
  return 0.5 * attitude_jacobian(q).transpose() * dphi_dq;
}

Eigen::Matrix<double, 12, 1> reduce_pose_gradient(const Eigen::Vector4d& q1,
                                                  const Eigen::Vector4d& q2,
                                                  const Eigen::Matrix<double, 14, 1>& gradient) {
  Eigen::Matrix<double, 12, 1> reduced;
  reduced.segment<3>(0) = gradient.segment<3>(0);
  reduced.segment<3>(3) = attitude_gradient(q1, gradient.segment<4>(3));
  reduced.segment<3>(6) = gradient.segment<3>(7);
  reduced.segment<3>(9) = attitude_gradient(q2, gradient.segment<4>(10));
  return reduced;
}

Eigen::Vector3d quaternion_to_mrp(const Eigen::Vector4d& q) {
  Eigen::Vector4d unit = q.normalized();
  if (unit(0) < 0.0) {
    unit = -unit;  // the shadow set: same attitude, |p| <= 1, and 1 + w >= 1 never vanishes
  }
  return unit.tail<3>() / (1.0 + unit(0));
}

Eigen::Vector4d mrp_to_quaternion(const Eigen::Vector3d& p) {
  const double n = p.squaredNorm();
  Eigen::Vector4d q;
  q << 1.0 - n, 2.0 * p;
  return q / (1.0 + n);
}

// With n = p'p and m = 1 + n:  w = (1 - n) / m  ->  dw/dp = -4 p^T / m^2
//                              v = 2 p / m      ->  dv/dp = 2 I / m - 4 p p^T / m^2
Eigen::Matrix<double, 4, 3> mrp_to_quaternion_jacobian(const Eigen::Vector3d& p) {
  const double m = 1.0 + p.squaredNorm();
  Eigen::Matrix<double, 4, 3> jacobian;
  jacobian.row(0) = -4.0 * p.transpose() / (m * m);
  jacobian.bottomRows<3>() =
      2.0 * Eigen::Matrix3d::Identity() / m - 4.0 * p * p.transpose() / (m * m);
  return jacobian;
}

}  // namespace diffpills
