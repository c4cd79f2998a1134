#include "unit_quaternion.hpp"

#include <Eigen/Geometry>

namespace diffpills::detail {

Eigen::Matrix3d skew(const Eigen::Vector3d& u) {
  Eigen::Matrix3d m;
  m << 0.0, -u.z(), u.y(), u.z(), 0.0, -u.x(), -u.y(), u.x(), 0.0;
  return m;
}

// Q = I + 2 w [v]x + 2 [v]x^2 for the unit quaternion [w, v], written out entry by entry
// (e.g. Q00 = 1 - 2 (y^2 + z^2), Q01 = 2 (x y - w z)); G = L(q) [0; I3] with
// L(q) = [w -v'; v w I + [v]x].
UnitQuaternion::UnitQuaternion(const Eigen::Vector4d& q) {
  const double inverse_norm = 1.0 / q.norm();  // one square root, one division
  unit_ = q * inverse_norm;
  const double w = unit_(0), x = unit_(1), y = unit_(2), z = unit_(3);
  // Element by element: this runs twice per query, and Eigen's comma initializer costs more.
  matrix_(0, 0) = 1.0 - 2.0 * (y * y + z * z);
  matrix_(0, 1) = 2.0 * (x * y - w * z);
  matrix_(0, 2) = 2.0 * (x * z + w * y);
  matrix_(1, 0) = 2.0 * (x * y + w * z);
  matrix_(1, 1) = 1.0 - 2.0 * (x * x + z * z);
  matrix_(1, 2) = 2.0 * (y * z - w * x);
  matrix_(2, 0) = 2.0 * (x * z - w * y);
  matrix_(2, 1) = 2.0 * (y * z + w * x);
  matrix_(2, 2) = 1.0 - 2.0 * (x * x + y * y);
  const double g = 2.0 * inverse_norm;
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

}  // namespace diffpills::detail
