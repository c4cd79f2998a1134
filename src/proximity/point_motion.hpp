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

// d(v / |v|) for dv: (I - n n') / |v| dv.
Matrix3x14 unit_vector_motion(const Eigen::Vector3d& v, const Matrix3x14& dv);

}  // namespace diffpills::detail
