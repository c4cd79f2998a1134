#include "pair_result.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>

#include "diffpills/rotation.hpp"

namespace diffpills::detail {
namespace {

using Matrix3x14 = Eigen::Matrix<double, 3, 14>;

// d p / d[r1 q1 r2 q2] with the body point u held fixed: p = r + Q(q) u, so dp/dr = I and
// dp/dq = d(Q(q) u)/dq, in the shape's seven columns (column offset 0 or 7).
Matrix3x14 fixed_point_jacobian(const PosedCore& core, const CoreSolution& solution, int column) {
  Matrix3x14 jacobian = Matrix3x14::Zero();
  jacobian.block<3, 3>(0, column).setIdentity();
  jacobian.block<3, 4>(0, column + 3) = rotate_jacobian(core.q, solution.body_point);
  return jacobian;
}

// Below this distance the cores count as intersecting. Rounding in p1 - p2 is of order
// eps * max(|p1|, |p2|, core size), so the threshold is relative to the same quantities.
double intersection_tolerance(const PosedCore& a, const PosedCore& b, const Eigen::Vector3d& p1,
                              const Eigen::Vector3d& p2) {
  return 1e-12 *
         std::max({a.size, b.size, p1.lpNorm<Eigen::Infinity>(), p2.lpNorm<Eigen::Infinity>()});
}

enum class NormalRule { kClosestPoints, kOrigins, kBodyAxis };

// The normal's rule (see proximity.hpp): the closest-point direction while the cores are apart;
// otherwise the direction between the body origins, or shape 1's body z axis if those coincide.
NormalRule normal_rule(const PosedCore& a, const PosedCore& b, const Eigen::Vector3d& p1,
                       const Eigen::Vector3d& p2) {
  const double tolerance = intersection_tolerance(a, b, p1, p2);
  if ((p2 - p1).norm() > tolerance) return NormalRule::kClosestPoints;
  if ((b.r - a.r).norm() > tolerance) return NormalRule::kOrigins;
  return NormalRule::kBodyAxis;
}

// d(v / |v|) = (I - n n') / |v| dv.
Eigen::Matrix3d unit_vector_jacobian(const Eigen::Vector3d& v) {
  const Eigen::Vector3d n = v.normalized();
  return (Eigen::Matrix3d::Identity() - n * n.transpose()) / v.norm();
}

using FreeMatrix = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 4>;
using ReducedRhs = Eigen::Matrix<double, Eigen::Dynamic, 14, 0, 4, 14>;

// Implicit function theorem with the active set eliminated (core_solution.hpp). Near the
// solution p_i = r_i + Q_i (u_i + D_i xi_i), and the free coordinates xi = (xi1, xi2) minimize
// |e|^2, e = p1 - p2, without constraints. With M = [Q1 D1, -Q2 D2] stationarity is M'e = 0;
// differentiating in a pose coordinate at the solution (xi = 0),
//   M'M dxi = -(M' de/dpose|_xi + dM'/dpose e),
//   de/dpose|_xi = dp1|_u - dp2|_u,   dM'/dq_i e = +-D_i' d(Q_i' e)/dq_i   (+ core 1, - core 2).
// M'M is at most 4 x 4. Where the closest points are not unique (parallel features) it is
// singular; the pseudo-inverse then gives the minimum-norm motion, with eigenvalues below 1e-12
// of the largest treated as zero, the same relative threshold as the parallel test of the box
// solver (sin^2 of the angle between features).
void add_point_motion(const PosedCore& a, const CoreSolution& sa, const PosedCore& b,
                      const CoreSolution& sb, const Eigen::Vector3d& difference, Matrix3x14& dp1,
                      Matrix3x14& dp2) {
  const int z1 = sa.free_dimensions;
  const int z2 = sb.free_dimensions;
  const int z = z1 + z2;
  if (z == 0) return;
  FreeMatrix M(3, z);
  M.leftCols(z1) = a.rotation * sa.free_directions.leftCols(z1);
  M.rightCols(z2) = -b.rotation * sb.free_directions.leftCols(z2);
  ReducedRhs rhs = -M.transpose() * (dp1 - dp2);
  rhs.block(0, 3, z1, 4) -=
      sa.free_directions.leftCols(z1).transpose() * rotate_transpose_jacobian(a.q, difference);
  rhs.block(z1, 10, z2, 4) +=
      sb.free_directions.leftCols(z2).transpose() * rotate_transpose_jacobian(b.q, difference);
  // The eigen-decomposition runs on a fixed 4 x 4 matrix: the z x z Hessian padded with a
  // diagonal block of its mean eigenvalue, which leaves the Hessian's own eigenpairs untouched.
  Eigen::Matrix4d padded = Eigen::Matrix4d::Zero();
  padded.topLeftCorner(z, z) = M.transpose() * M;
  const double mean = padded.trace() / z;
  for (int k = z; k < 4; ++k) padded(k, k) = mean;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eigen(padded);
  const double largest = eigen.eigenvalues().cwiseAbs().maxCoeff();
  Eigen::Matrix4d pseudo_inverse = Eigen::Matrix4d::Zero();
  for (int k = 0; k < 4; ++k) {
    const double value = eigen.eigenvalues()(k);
    if (value > 1e-12 * largest) {
      pseudo_inverse +=
          eigen.eigenvectors().col(k) * eigen.eigenvectors().col(k).transpose() / value;
    }
  }
  const ReducedRhs dxi = pseudo_inverse.topLeftCorner(z, z) * rhs;
  dp1 += M.leftCols(z1) * dxi.topRows(z1);
  dp2 -= M.rightCols(z2) * dxi.bottomRows(z2);  // M's right block carries the minus sign
}

}  // namespace

Proximity make_proximity(const PosedCore& a, const CoreSolution& solution_a, const PosedCore& b,
                         const CoreSolution& solution_b) {
  Proximity result;
  const Eigen::Vector3d p1 = a.r + a.rotation * solution_a.body_point;
  const Eigen::Vector3d p2 = b.r + b.rotation * solution_b.body_point;
  const Eigen::Vector3d difference = p1 - p2;
  const double radius_sum = a.radius + b.radius;
  result.phi = difference.squaredNorm() - radius_sum * radius_sum;  // eq. caps_prox
  result.core_points = {p1, p2};
  // Envelope theorem: d phi = 2 (p1 - p2)' (dp1 - dp2) with the body points held fixed.
  result.gradient.segment<3>(0) = 2.0 * difference;
  result.gradient.segment<4>(3) =
      2.0 * rotate_jacobian(a.q, solution_a.body_point).transpose() * difference;
  result.gradient.segment<3>(7) = -2.0 * difference;
  result.gradient.segment<4>(10) =
      -2.0 * rotate_jacobian(b.q, solution_b.body_point).transpose() * difference;

  switch (normal_rule(a, b, p1, p2)) {
    case NormalRule::kClosestPoints:
      result.normal = (p2 - p1).normalized();
      break;
    case NormalRule::kOrigins:
      result.cores_intersect = true;
      result.normal = (b.r - a.r).normalized();
      break;
    case NormalRule::kBodyAxis:
      result.cores_intersect = true;
      result.normal = a.rotation.col(2);
      break;
  }
  result.points = {p1 + a.radius * result.normal, p2 - b.radius * result.normal};  // caps_c_1/2
  return result;
}

ProximityJacobian make_proximity_jacobian(const PosedCore& a, const CoreSolution& solution_a,
                                          const PosedCore& b, const CoreSolution& solution_b) {
  ProximityJacobian result;
  static_cast<Proximity&>(result) = make_proximity(a, solution_a, b, solution_b);
  const Eigen::Vector3d& p1 = result.core_points[0];
  const Eigen::Vector3d& p2 = result.core_points[1];

  Matrix3x14 dp1 = fixed_point_jacobian(a, solution_a, 0);
  Matrix3x14 dp2 = fixed_point_jacobian(b, solution_b, 7);
  add_point_motion(a, solution_a, b, solution_b, p1 - p2, dp1, dp2);
  result.core_points_jacobian.topRows<3>() = dp1;
  result.core_points_jacobian.bottomRows<3>() = dp2;

  Matrix3x14 dnormal = Matrix3x14::Zero();
  switch (normal_rule(a, b, p1, p2)) {
    case NormalRule::kClosestPoints:
      dnormal = unit_vector_jacobian(p2 - p1) * (dp2 - dp1);
      break;
    case NormalRule::kOrigins: {
      const Eigen::Matrix3d d_unit = unit_vector_jacobian(b.r - a.r);
      dnormal.block<3, 3>(0, 0) = -d_unit;
      dnormal.block<3, 3>(0, 7) = d_unit;
      break;
    }
    case NormalRule::kBodyAxis:
      dnormal.block<3, 4>(0, 3) = rotate_jacobian(a.q, Eigen::Vector3d::UnitZ());
      break;
  }
  result.points_jacobian.topRows<3>() = dp1 + a.radius * dnormal;
  result.points_jacobian.bottomRows<3>() = dp2 - b.radius * dnormal;
  return result;
}

}  // namespace diffpills::detail
