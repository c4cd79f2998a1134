#include "diffpills/rotation.hpp"

#include <Eigen/Geometry>

namespace diffpills {
namespace {

// [u]x, the cross-product matrix: [u]x v = u x v.
Eigen::Matrix3d skew(const Eigen::Vector3d& u) {
  Eigen::Matrix3d m;
  m << 0.0, -u.z(), u.y(), u.z(), 0.0, -u.x(), -u.y(), u.x(), 0.0;
  return m;
}

// d qhat / dq for qhat = q / |q|:  (I - qhat qhat^T) / |q|.
Eigen::Matrix4d normalization_jacobian(const Eigen::Vector4d& q) {
  const double norm = q.norm();
  const Eigen::Vector4d unit = q / norm;
  return (Eigen::Matrix4d::Identity() - unit * unit.transpose()) / norm;
}

// For a unit q = [w, v] and s = +1 (rotate) or s = -1 (rotate by the transpose):
//   Q(q)^(T if s<0) u = u + 2 s w (v x u) + 2 v x (v x u)
// Differentiating the polynomial in (w, v), with v x (v x u) = v (v.u) - u (v.v):
//   d/dw = 2 s (v x u)
//   d/dv = -2 s w [u]x + 2 ((v.u) I + v u^T - 2 u v^T)
// The result is then chained through the normalization q -> q / |q|.
Eigen::Matrix<double, 3, 4> rotation_jacobian_signed(const Eigen::Vector4d& q,
                                                     const Eigen::Vector3d& u, double s) {
  const Eigen::Vector4d unit = q.normalized();
  const double w = unit(0);
  const Eigen::Vector3d v = unit.tail<3>();
  Eigen::Matrix<double, 3, 4> d_unit;
  d_unit.col(0) = 2.0 * s * v.cross(u);
  d_unit.rightCols<3>() =
      -2.0 * s * w * skew(u) +
      2.0 * (v.dot(u) * Eigen::Matrix3d::Identity() + v * u.transpose() - 2.0 * u * v.transpose());
  return d_unit * normalization_jacobian(q);
}

}  // namespace

// Q = I + 2 w [v]x + 2 [v]x^2 for the unit quaternion [w, v] = q / |q|.
Eigen::Matrix3d rotation_matrix(const Eigen::Vector4d& q) {
  const Eigen::Vector4d unit = q.normalized();
  const Eigen::Matrix3d v_cross = skew(unit.tail<3>());
  return Eigen::Matrix3d::Identity() + 2.0 * unit(0) * v_cross + 2.0 * v_cross * v_cross;
}

Eigen::Matrix<double, 3, 4> rotate_jacobian(const Eigen::Vector4d& q, const Eigen::Vector3d& v) {
  return rotation_jacobian_signed(q, v, 1.0);
}

Eigen::Matrix<double, 3, 4> rotate_transpose_jacobian(const Eigen::Vector4d& q,
                                                      const Eigen::Vector3d& v) {
  return rotation_jacobian_signed(q, v, -1.0);
}

// q (x) p = [w p0 - v.pv ; w pv + p0 v + v x pv], so
// L(q) = [ w  -v^T ; v  w I + [v]x ].
Eigen::Matrix4d left_multiply_matrix(const Eigen::Vector4d& q) {
  Eigen::Matrix4d l;
  l(0, 0) = q(0);
  l.block<1, 3>(0, 1) = -q.tail<3>().transpose();
  l.block<3, 1>(1, 0) = q.tail<3>();
  l.block<3, 3>(1, 1) = q(0) * Eigen::Matrix3d::Identity() + skew(q.tail<3>());
  return l;
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
