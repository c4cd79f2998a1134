#include "unit_quaternion.hpp"

#include <Eigen/Geometry>

namespace diffpills::detail {

Eigen::Matrix3d skew(const Eigen::Vector3d& u) {
  Eigen::Matrix3d m;
  m << 0.0, -u.z(), u.y(), u.z(), 0.0, -u.x(), -u.y(), u.x(), 0.0;
  return m;
}

// Q = I + 2 w [v]x + 2 [v]x^2, written out entry by entry (e.g. Q00 = 1 - 2 (y^2 + z^2),
// Q01 = 2 (x y - w z)): it runs for every body of a scene query, and Eigen's comma initializer
// costs more.
Eigen::Matrix3d unit_rotation_matrix(const Eigen::Vector4d& u) {
  const double w = u(0), x = u(1), y = u(2), z = u(3);
  Eigen::Matrix3d Q;
  Q(0, 0) = 1.0 - 2.0 * (y * y + z * z);
  Q(0, 1) = 2.0 * (x * y - w * z);
  Q(0, 2) = 2.0 * (x * z + w * y);
  Q(1, 0) = 2.0 * (x * y + w * z);
  Q(1, 1) = 1.0 - 2.0 * (x * x + z * z);
  Q(1, 2) = 2.0 * (y * z - w * x);
  Q(2, 0) = 2.0 * (x * z - w * y);
  Q(2, 1) = 2.0 * (y * z + w * x);
  Q(2, 2) = 1.0 - 2.0 * (x * x + y * y);
  return Q;
}

// G = L(q) [0; I3] with L(q) = [w -v'; v w I + [v]x], the unit quaternion's.
UnitQuaternion::UnitQuaternion(const Eigen::Vector4d& q)
    : inverse_norm_(1.0 / q.norm()) {  // one square root, one division
  unit_ = q * inverse_norm_;
  matrix_ = unit_rotation_matrix(unit_);
  const double w = unit_(0), x = unit_(1), y = unit_(2), z = unit_(3);
  const double g = 2.0 * inverse_norm_;
  theta_to_q_(0, 0) = -g * x, theta_to_q_(0, 1) = -g * y, theta_to_q_(0, 2) = -g * z;
  theta_to_q_(1, 0) = g * w, theta_to_q_(1, 1) = -g * z, theta_to_q_(1, 2) = g * y;
  theta_to_q_(2, 0) = g * z, theta_to_q_(2, 1) = g * w, theta_to_q_(2, 2) = -g * x;
  theta_to_q_(3, 0) = -g * y, theta_to_q_(3, 1) = g * x, theta_to_q_(3, 2) = g * w;
}

Eigen::Matrix<double, 3, 4> UnitQuaternion::rotate_jacobian(const Eigen::Vector3d& u) const {
  return -(matrix_ * skew(u)) * theta_to_q_.transpose();
}

Eigen::Matrix<double, 3, 4> UnitQuaternion::rotate_transpose_jacobian(
    const Eigen::Vector3d& v) const {
  return skew(matrix_.transpose() * v) * theta_to_q_.transpose();
}

Eigen::Vector4d UnitQuaternion::rotate_gradient(const Eigen::Vector3d& u,
                                                const Eigen::Vector3d& w) const {
  return theta_to_q_ * u.cross(matrix_.transpose() * w);
}

// For unit q = (s, v), Q(q) u = (s^2 - |v|^2) u + 2 (v . u) v + 2 s (v x u), so w . Q(q) u is the
// quadratic form q' M q with
//   M = [ w . u      (u x w)'                  ]
//       [ u x w      u w' + w u' - (w . u) I3  ],
// and for any nonzero q, G(q) = w . Q(q / |q|) u = q' M q / q' q (degree 0). Its derivatives:
//   grad G = 2 (M q - G q) / |q|^2,
//   hess G = (2 M - 2 G I4 - 2 q grad' - 2 grad q') / |q|^2.
// Written with the unit n = q / |q| and g = 2 (M n - G n) (= |q| grad G):
//   hess G = (2 M - 2 G I4 - 2 n g' - 2 g n') / |q|^2.
// Forming q' M q itself would overflow: |q| may reach ~1e100 and M ~1e200 in an accepted scene
// (fuzz_proximity: a quaternion of norm 1e70 gave NaN); with n every product stays within M's
// size, and only the final factor carries |q| (1 / |q|^2 within [2.5e-201, 1e80], as Pose keeps
// |q| within [1e-40, 2e100]). A caller's unit^2 goes into that factor too, as (unit / |q|)^2:
// applied afterwards, a tiny product in a scaled frame (|q| = 1e100, u a length of 1e-15 in a scene
// of 1e99, M ~ 1e-114) had gone through 2e-200 * M, subnormal, and come back with a few digits.
// Only the lower triangle is computed, then mirrored: exactly symmetric.
Eigen::Matrix4d UnitQuaternion::rotate_hessian(const Eigen::Vector3d& u, const Eigen::Vector3d& w,
                                               double unit) const {
  const double u_dot_w = u.dot(w);
  const Eigen::Vector3d u_cross_w = u.cross(w);
  Eigen::Matrix4d M;
  M(0, 0) = u_dot_w;
  for (int i = 0; i < 3; ++i) {
    M(i + 1, 0) = M(0, i + 1) = u_cross_w(i);
    for (int j = 0; j <= i; ++j) M(i + 1, j + 1) = M(j + 1, i + 1) = u(i) * w(j) + w(i) * u(j);
    M(i + 1, i + 1) -= u_dot_w;
  }
  const Eigen::Vector4d M_unit = M * unit_;
  const double value = unit_.dot(M_unit);
  const Eigen::Vector4d g = 2.0 * (M_unit - value * unit_);
  const double unit_per_norm = unit * inverse_norm_;
  const double factor = 2.0 * unit_per_norm * unit_per_norm;
  Eigen::Matrix4d hessian;
  for (int j = 0; j < 4; ++j) {
    for (int i = j; i < 4; ++i) {
      hessian(i, j) = hessian(j, i) = factor * (M(i, j) - unit_(i) * g(j) - g(i) * unit_(j));
    }
    hessian(j, j) -= factor * value;
  }
  return hessian;
}

}  // namespace diffpills::detail
