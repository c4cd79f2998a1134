#include "pair_result.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>

namespace diffpills::detail {
namespace {

using Matrix3x14 = Eigen::Matrix<double, 3, 14>;

// d p / d[r1 q1 r2 q2] with the body point u held fixed: p = r + Q(q) u, so dp/dr = I and
// dp/dq = d(Q(q) u)/dq, in the shape's seven columns (column offset 0 or 7).
Matrix3x14 fixed_point_jacobian(const PosedCore& core, const CoreSolution& solution, int column) {
  Matrix3x14 jacobian = Matrix3x14::Zero();
  jacobian.block<3, 3>(0, column).setIdentity();
  jacobian.block<3, 4>(0, column + 3) = core.attitude.rotate_jacobian(solution.body_point);
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

// Implicit function theorem with the active set eliminated (core_solution.hpp). Near the
// solution p_i = r_i + Q_i (u_i + D_i xi_i), and the free coordinates xi = (xi1, xi2) minimize
// |e|^2, e = p1 - p2, without constraints. With M = [Q1 D1, -Q2 D2] stationarity is M'e = 0;
// differentiating in a pose coordinate at the solution (xi = 0),
//   M'M dxi = -(M' de/dpose|_xi + dM'/dpose e),
//   de/dpose|_xi = dp1|_u - dp2|_u,   dM'/dq_i e = +-D_i' d(Q_i' e)/dq_i   (+ core 1, - core 2).
// Everything is fixed-size: each side's directions fill two columns of M (unused ones are zero),
// and the unused diagonal entries of M'M are set to the mean of the used ones, which leaves the
// solution for the used coordinates untouched and keeps the matrix invertible.
// Where the closest points are not unique (parallel features) M'M is singular; the pseudo-inverse
// then gives the minimum-norm motion, with eigenvalues below 1e-12 of the largest treated as zero,
// the relative threshold of the parallel tests (sin^2 of the angle between features). The cheap
// explicit inverse serves whenever det(M'M) / prod(diag) > 1e-12, which rules that out.
void add_point_motion(const PosedCore& a, const CoreSolution& sa, const PosedCore& b,
                      const CoreSolution& sb, const Eigen::Vector3d& difference, Matrix3x14& dp1,
                      Matrix3x14& dp2) {
  const int z1 = sa.free_dimensions;
  const int z2 = sb.free_dimensions;
  if (z1 + z2 == 0) return;
  Eigen::Matrix<double, 3, 4> M;
  M.leftCols<2>() = a.attitude.matrix() * sa.free_directions;
  M.rightCols<2>() = -b.attitude.matrix() * sb.free_directions;
  Eigen::Matrix<double, 4, 14> rhs = -M.transpose() * (dp1 - dp2);
  rhs.block<2, 4>(0, 3) -=
      sa.free_directions.transpose() * a.attitude.rotate_transpose_jacobian(difference);
  rhs.block<2, 4>(2, 10) +=
      sb.free_directions.transpose() * b.attitude.rotate_transpose_jacobian(difference);
  Eigen::Matrix4d hessian = M.transpose() * M;
  const bool used[4] = {z1 > 0, z1 > 1, z2 > 0, z2 > 1};
  double mean = 0.0;
  for (int k = 0; k < 4; ++k) mean += used[k] ? hessian(k, k) : 0.0;
  mean /= z1 + z2;
  for (int k = 0; k < 4; ++k) {
    if (!used[k]) hessian(k, k) = mean;
  }
  Eigen::Matrix<double, 4, 14> dxi;
  if (hessian.determinant() > 1e-12 * hessian.diagonal().prod()) {
    dxi = hessian.inverse() * rhs;
  } else {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eigen(hessian);
    const double largest = eigen.eigenvalues().cwiseAbs().maxCoeff();
    Eigen::Matrix4d pseudo_inverse = Eigen::Matrix4d::Zero();
    for (int k = 0; k < 4; ++k) {
      const double value = eigen.eigenvalues()(k);
      if (value > 1e-12 * largest) {
        pseudo_inverse +=
            eigen.eigenvectors().col(k) * eigen.eigenvectors().col(k).transpose() / value;
      }
    }
    dxi = pseudo_inverse * rhs;
  }
  dp1 += M.leftCols<2>() * dxi.topRows<2>();
  dp2 -= M.rightCols<2>() * dxi.bottomRows<2>();  // M's right block carries the minus sign
}

}  // namespace

Proximity make_proximity(const PosedCore& a, const CoreSolution& solution_a, const PosedCore& b,
                         const CoreSolution& solution_b) {
  Proximity result;
  const Eigen::Vector3d p1 = a.r + a.attitude.matrix() * solution_a.body_point;
  const Eigen::Vector3d p2 = b.r + b.attitude.matrix() * solution_b.body_point;
  const Eigen::Vector3d difference = p1 - p2;
  const double radius_sum = a.radius + b.radius;
  result.phi = difference.squaredNorm() - radius_sum * radius_sum;  // eq. caps_prox
  result.core_points = {p1, p2};
  // Envelope theorem: d phi = 2 (p1 - p2)' (dp1 - dp2) with the body points held fixed.
  result.gradient.segment<3>(0) = 2.0 * difference;
  result.gradient.segment<4>(3) =
      2.0 * a.attitude.rotate_gradient(solution_a.body_point, difference);
  result.gradient.segment<3>(7) = -2.0 * difference;
  result.gradient.segment<4>(10) =
      -2.0 * b.attitude.rotate_gradient(solution_b.body_point, difference);

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
      result.normal = a.attitude.matrix().col(2);
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
      dnormal.block<3, 4>(0, 3) = a.attitude.rotate_jacobian(Eigen::Vector3d::UnitZ());
      break;
  }
  result.points_jacobian.topRows<3>() = dp1 + a.radius * dnormal;
  result.points_jacobian.bottomRows<3>() = dp2 - b.radius * dnormal;
  return result;
}

}  // namespace diffpills::detail
