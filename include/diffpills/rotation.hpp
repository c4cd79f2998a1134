// Quaternion and rotation utilities (DESIGN.md section 1).
//
// Conventions: q = [w, x, y, z], scalar first, Hamilton product, rotating body to world:
// x_world = r + Q(q) x_body. The functions that rotate (rotation_matrix, rotate_*,
// quaternion_to_mrp) accept a non-unit q and normalize it internally; their derivatives with
// respect to q include that normalization, so at a unit q they have no component along q. The
// product matrices (left_multiply_matrix, right_multiply_matrix, attitude_jacobian) and
// quaternion_product are those of q as given, linear in q; attitude_gradient, built on them, is
// still the same for every scaling of q, since a dphi/dq that includes the normalization scales as
// 1 / |q|. Callers are expected to pass a validated quaternion (see Pose); these functions do not
// check for zero norm.
#pragma once

#include <Eigen/Core>

namespace diffpills {

// Q(q / |q|): the rotation matrix of the normalized quaternion.
Eigen::Matrix3d rotation_matrix(const Eigen::Vector4d& q);

// d/dq [ Q(q / |q|) v ]  (3x4), for a fixed body-frame vector v.
Eigen::Matrix<double, 3, 4> rotate_jacobian(const Eigen::Vector4d& q, const Eigen::Vector3d& v);

// d/dq [ w . Q(q / |q|) v ]  (4-vector): w' rotate_jacobian(q, v) without forming the Jacobian,
// which is all a gradient of a scalar needs (dphi/dq = 2 (p1 - p2)' dp1/dq).
Eigen::Vector4d rotate_gradient(const Eigen::Vector4d& q, const Eigen::Vector3d& v,
                                const Eigen::Vector3d& w);

// d^2/dq^2 [ w . Q(q / |q|) v ]  (4x4, symmetric): the second derivative of rotate_gradient's
// function, normalization included (for Hessians of phi and of the signed distance).
Eigen::Matrix4d rotate_hessian(const Eigen::Vector4d& q, const Eigen::Vector3d& v,
                               const Eigen::Vector3d& w);

// d/dq [ Q(q / |q|)^T v ]  (3x4), for a fixed world-frame vector v.
Eigen::Matrix<double, 3, 4> rotate_transpose_jacobian(const Eigen::Vector4d& q,
                                                      const Eigen::Vector3d& v);

// L(q): the left-multiplication matrix, q (x) p = L(q) p.
Eigen::Matrix4d left_multiply_matrix(const Eigen::Vector4d& q);

// a (x) b, the Hamilton product of the quaternions as given:
//   [a0 b0 - av.bv ; a0 bv + b0 av + av x bv],
// written out (L(a) b without forming L(a), equal to it up to rounding: the terms are summed in
// another order). It composes every primitive's attitude in a scene query and every frame of a
// serial chain.
inline Eigen::Vector4d quaternion_product(const Eigen::Vector4d& a, const Eigen::Vector4d& b) {
  return {a(0) * b(0) - a(1) * b(1) - a(2) * b(2) - a(3) * b(3),
          a(0) * b(1) + a(1) * b(0) + a(2) * b(3) - a(3) * b(2),
          a(0) * b(2) - a(1) * b(3) + a(2) * b(0) + a(3) * b(1),
          a(0) * b(3) + a(1) * b(2) - a(2) * b(1) + a(3) * b(0)};
}

// R(q): the right-multiplication matrix, p (x) q = R(q) p. (Chains a gradient through a
// composition of attitudes: d(p (x) q)/dp = R(q).)
Eigen::Matrix4d right_multiply_matrix(const Eigen::Vector4d& q);

// G(q) = L(q) H with H = [0; I3] (4x3): the attitude Jacobian. For the body-frame perturbation
// q (x) [1, theta/2], dq/dtheta = 1/2 G(q) at theta = 0.
Eigen::Matrix<double, 4, 3> attitude_jacobian(const Eigen::Vector4d& q);

// dphi/dtheta = 1/2 H^T L(q)^T dphi/dq: the gradient with respect to a body-frame rotation vector,
// the 3-vector trajectory optimizers want instead of the 4-vector dphi/dq.
Eigen::Vector3d attitude_gradient(const Eigen::Vector4d& q, const Eigen::Vector4d& dphi_dq);

// The 14-entry pose gradient [dr1, dq1, dr2, dq2] reduced to 12 entries [dr1, dtheta1, dr2,
// dtheta2] with attitude_gradient applied to each quaternion block.
Eigen::Matrix<double, 12, 1> reduce_pose_gradient(const Eigen::Vector4d& q1,
                                                  const Eigen::Vector4d& q2,
                                                  const Eigen::Matrix<double, 14, 1>& gradient);

// Modified Rodrigues parameters p = v / (1 + w) for q = [w, v] (normalized first). The shadow set
// is chosen so that |p| <= 1: q and -q are the same attitude, and q with w < 0 is flipped first.
Eigen::Vector3d quaternion_to_mrp(const Eigen::Vector4d& q);

// q = [1 - p'p, 2 p] / (1 + p'p): the unit quaternion of modified Rodrigues parameters p.
Eigen::Vector4d mrp_to_quaternion(const Eigen::Vector3d& p);

// dq/dp (4x3) of mrp_to_quaternion, to chain pose gradients to MRP-posed bodies:
// dphi/dp = (dq/dp)^T dphi/dq.
Eigen::Matrix<double, 4, 3> mrp_to_quaternion_jacobian(const Eigen::Vector3d& p);

}  // namespace diffpills
