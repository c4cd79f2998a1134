// How a pair's two core points move with the poses: the pieces of the implicit function theorem
// shared by the proximity's and the signed distance's result builders. All in a query's frame
// (pair_frame.hpp); a Jacobian has the 14 columns d[r1 q1 r2 q2].
#pragma once

#include <Eigen/Core>

#include "posed_core.hpp"

namespace diffpills::detail {

using Matrix3x14 = Eigen::Matrix<double, 3, 14>;

// d p / d[r1 q1 r2 q2] with the body point u held fixed: p = r + Q(q) u, so dp/dr = I and
// dp/dq = d(Q(q) u)/dq, in the shape's seven columns (column offset 0 or 7).
Matrix3x14 fixed_point_jacobian(const PosedCore& core, const ClosestFeature& side, int column);

// Adds to dp1, dp2 the motion of the points along their features' free directions: the points
// are a stationary pair of |p1 - p2|^2 over those directions (closest points, or the witnesses of
// a facet of the cores' Minkowski difference), and stay one as the poses move. `difference` is
// p1 - p2.
void add_point_motion(const PosedCore& a, const ClosestFeature& sa, const PosedCore& b,
                      const ClosestFeature& sb, const Eigen::Vector3d& difference, Matrix3x14& dp1,
                      Matrix3x14& dp2);

// The motion of the pair's two core points: fixed_point_jacobian of each side plus the motion
// along their features (add_point_motion).
struct PointMotion {
  Matrix3x14 dp1, dp2;
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
