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
// with central differences and the poses with the 4x4 products written out separately.
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
  std::vector<Eigen::Matrix<double, 3, Eigen::Dynamic>> d_origin;
  std::vector<Eigen::Matrix<double, 4, Eigen::Dynamic>> d_attitude;
};

// Throws std::invalid_argument if the parameter lists differ in length or q does not match them.
ChainFrames forward_kinematics(const SerialChain& chain, const Eigen::VectorXd& q,
                               bool derivatives = true);

}  // namespace diffpills::trajopt
