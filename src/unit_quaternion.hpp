// A quaternion normalized once, for code that rotates and differentiates with the same attitude
// several times per query. The rotating functions of rotation.hpp are thin wrappers around it.
#pragma once

#include <Eigen/Core>

namespace diffpills::detail {

// [u]x, the cross-product matrix: [u]x v = u x v.
Eigen::Matrix3d skew(const Eigen::Vector3d& u);

// Q(u) for a unit quaternion u (not normalized again): Q = I + 2 w [v]x + 2 [v]x^2 for u = [w, v].
Eigen::Matrix3d unit_rotation_matrix(const Eigen::Vector4d& u);

// Derivatives go through the body-frame rotation vector theta of the perturbation
// q (x) exp(theta). For unit q, dq = 1/2 G(q) dtheta with G = L(q) [0; I3] (4x3) and G'G = I, so
// a derivative with respect to theta turns into one with respect to q (normalization included)
// as d/dq = 2 G(qhat) d/dtheta / |q|, which already has no component along q:
//   w . Q exp(theta) u  ~  w . Q (u + theta x u)  ->  d/dtheta = u x (Q' w)
//   Q exp(theta) u      ~  Q u - Q [u]x theta      ->  d/dtheta = -Q [u]x
//   (Q exp(theta))' v   ~  Q'v + (Q'v) x theta     ->  d/dtheta = [Q'v]x
class UnitQuaternion {
 public:
  // q must be nonzero and finite (Pose validates that).
  explicit UnitQuaternion(const Eigen::Vector4d& q);

  const Eigen::Vector4d& unit() const { return unit_; }
  // 1 / |q| of the q given.
  double inverse_norm() const { return inverse_norm_; }
  // Q(q / |q|).
  const Eigen::Matrix3d& matrix() const { return matrix_; }
  // d/dq [ Q(q / |q|) u ] (3x4), and d/dq [ Q(q / |q|)' v ].
  Eigen::Matrix<double, 3, 4> rotate_jacobian(const Eigen::Vector3d& u) const;
  Eigen::Matrix<double, 3, 4> rotate_transpose_jacobian(const Eigen::Vector3d& v) const;
  // d/dq [ w . Q(q / |q|) u ]: w' rotate_jacobian(u), without forming the Jacobian.
  Eigen::Vector4d rotate_gradient(const Eigen::Vector3d& u, const Eigen::Vector3d& w) const;
  // d^2/dq^2 [ w . Q(q / |q|) u ] (4x4, exactly symmetric), times unit^2: a caller working in a
  // frame whose lengths are `unit` times smaller gets the Hessian in its callers' units with the
  // factor folded in before the one power of 1 / |q|^2 (see the definition).
  Eigen::Matrix4d rotate_hessian(const Eigen::Vector3d& u, const Eigen::Vector3d& w,
                                 double unit = 1.0) const;

 private:
  // 2 G(qhat) / |q|, the map from d/dtheta to d/dq.
  Eigen::Matrix<double, 4, 3> theta_to_q_;
  Eigen::Vector4d unit_;
  double inverse_norm_ = 1.0;  // 1 / |q|
  Eigen::Matrix3d matrix_;
};

}  // namespace diffpills::detail
