// A serial arm of revolute joints in modified Denavit-Hartenberg parameters (Craig's convention),
// with the poses of its frames and their exact derivatives with respect to the joint angles.
//
// Frame 0 is the base, at the world's origin. Frame i (1 <= i <= n) follows frame i - 1 by
//
//     T_i = RotX(alpha_i) TransX(a_i) RotZ(q_i) TransZ(d_i),
//
// and frame n + 1, the flange, follows frame n by TransZ(flange_d). So frame i's rotation is
// R_i = R_{i-1} RotX(alpha_i) RotZ(q_i), its origin o_i = o_{i-1} + R_{i-1} (a_i e_x) +
// R_{i-1} RotX(alpha_i) (d_i e_z); as quaternions, q_i = q_{i-1} (x) qx(alpha_i) (x) qz(q_i).
//
// Derivatives. Joint j turns everything after it about its axis, the line through o_j along
// z_j = R_j e_z (RotZ(q_j) is about it and TransZ(d_j) moves along it, so o_j lies on it). Hence
// for every frame f >= j
//
//     d o_f / d q_j = z_j x (o_f - o_j),      d q_f / d q_j = 1/2 [0, z_j] (x) q_f
//
// (a world-frame rotation of rate z_j), and zero for f < j. These are exact; tests compare them
// with central differences and the poses with the 4x4 products written out separately. The same
// holds for any point p and attitude q_p fixed in frame f (a shape posed in it).
//
// Second derivatives (attached_pose_derivatives' curvature). For i <= j <= f, joint i turns z_j, p
// and o_j alike (z_j by z_i x z_j, p - o_j by z_i x (p - o_j)), and joint j leaves z_j and o_j
// where they are, so with the Jacobi identity
//     d2 p / dq_i dq_j = z_i x (z_j x (p - o_j)),    d2 q_p / dq_i dq_j = 1/4 [0, z_i] (x) [0, z_j]
//     (x) q_p
// (the second: 1/2 [0, z_i x z_j] (x) q_p + 1/4 [0, z_j] (x) [0, z_i] (x) q_p, and
// [0, a] (x) [0, b] = [-a.b, a x b]).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace diffpills::trajopt {

struct SerialChain {
  std::vector<double> a, d, alpha;  // one of each per joint, in meters and radians
  double flange_d = 0.0;
  int joints() const { return static_cast<int>(a.size()); }
};

// The n + 2 frames' poses (base, after each joint, flange) at joint angles q, and with
// `derivatives` their Jacobians with respect to q (3 x n and 4 x n each).
struct ChainFrames {
  std::vector<Eigen::Vector3d> origin;
  std::vector<Eigen::Vector4d> attitude;  // unit quaternions [w x y z], body to world
  std::vector<Eigen::Vector3d> axis;      // axis[j] = z_j for joints j = 1 .. n (axis[0] unused)
  std::vector<Eigen::Matrix<double, 3, Eigen::Dynamic>> d_origin;
  std::vector<Eigen::Matrix<double, 4, Eigen::Dynamic>> d_attitude;
};

// Throws std::invalid_argument if the parameter lists differ in length or q does not match them.
ChainFrames forward_kinematics(const SerialChain& chain, const Eigen::Ref<const Eigen::VectorXd>& q,
                               bool derivatives = true);
// The same, written into `frames`, whose storage is reused: nothing is allocated when frames holds
// an earlier call's result for this chain with derivatives, or for any call without them (for
// loops that pose the chain many times). Without `derivatives`, frames' d_origin and d_attitude
// keep an earlier call's Jacobians for this chain (stale: not at q) or are emptied.
void forward_kinematics(const SerialChain& chain, const Eigen::Ref<const Eigen::VectorXd>& q,
                        bool derivatives, ChainFrames& frames);

// For a pose (p, q_p) fixed in frame f (frames from forward_kinematics at q, 0 <= f <= n + 1):
// its Jacobian with respect to q (7 x n, rows [p; q_p]), and sum_k gradient_k d2 pose_k / dq2
// (n x n), the term a chain rule through the pose adds to J' H J.
struct AttachedPoseDerivatives {
  Eigen::Matrix<double, 7, Eigen::Dynamic> jacobian;
  Eigen::MatrixXd curvature;
};
AttachedPoseDerivatives attached_pose_derivatives(const ChainFrames& frames, int frame,
                                                  const Eigen::Vector3d& position,
                                                  const Eigen::Vector4d& attitude,
                                                  const Eigen::Matrix<double, 7, 1>& gradient);

}  // namespace diffpills::trajopt
