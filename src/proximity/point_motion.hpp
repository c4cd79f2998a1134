// How a pair's two core points move with the poses: the pieces of the implicit function theorem
// shared by the proximity's and the signed distance's result builders. All in a query's frame
// (pair_frame.hpp); a Jacobian has the 14 columns d[r1 q1 r2 q2].
#pragma once

#include <Eigen/Core>
#include <array>

#include "posed_core.hpp"

namespace diffpills::detail {

using Matrix3x14 = Eigen::Matrix<double, 3, 14>;

// The motion of the pair's two core points. They are a stationary pair of |p1 - p2|^2 over their
// features' free directions (closest points, or the witnesses of a facet of the cores' Minkowski
// difference), and stay one as the poses move (point_motion.cpp). With f = |p1 - p2|^2 over the
// poses x = [r1 q1 r2 q2] and the Z = z1 + z2 free coordinates xi (side 1's first):
struct PointMotion {
  Matrix3x14 dp1, dp2;  // d p_i / dx, the points' total Jacobians
  // d(Q_i u_i)/dq_i at the fixed body points u_i (3 x 4 each): the rotation part of the points'
  // Jacobians with the body points held fixed.
  std::array<Eigen::Matrix<double, 3, 4>, 2> turn;
  // coupling = f_xi,x / 2 and free_motion = dxi/dx = -(f_xi,xi)^+ f_xi,x, Z x 14 each in the
  // first Z = free rows (the rest unset): the pieces phi's Hessian reuses (phi_hessian.hpp).
  int free = 0;
  Eigen::Matrix<double, 4, 14> coupling, free_motion;
};
PointMotion core_point_motion(const PosedCore& a, const ClosestFeature& sa, const PosedCore& b,
                              const ClosestFeature& sb);

// The results' 6x14 Jacobians of [p1; p2] and of the surface points [p1 + R1 n; p2 - R2 n], given
// the normal's motion, in the inputs' units: d/dr is free of units (a length per length), d/dq is
// a length, so the quaternion columns are multiplied by the frame's scale.
void point_jacobians(double scale, const PosedCore& a, const PosedCore& b,
                     const PointMotion& motion, const Matrix3x14& dnormal,
                     Eigen::Matrix<double, 6, 14>& core_points_jacobian,
                     Eigen::Matrix<double, 6, 14>& points_jacobian);

// d(v / |v|) for dv: (I - n n') / |v| dv.
Matrix3x14 unit_vector_motion(const Eigen::Vector3d& v, const Matrix3x14& dv);

}  // namespace diffpills::detail
