#include "point_motion.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace diffpills::detail {
namespace {

// Implicit function theorem with the active set eliminated (posed_core.hpp). Near the
// solution p_i = r_i + Q_i (u_i + D_i xi_i), and the free coordinates xi = (xi1, xi2) minimize
// |e|^2, e = p1 - p2, without constraints. With M = [Q1 D1, -Q2 D2] stationarity is M'e = 0;
// differentiating in a pose coordinate at the solution (xi = 0),
//   M'M dxi = -(M' de/dpose|_xi + dM'/dpose e),
//   de/dpose|_xi = dp1|_u - dp2|_u,   dM'/dq_i e = +-D_i' d(Q_i' e)/dq_i   (+ core 1, - core 2).
// M'M is Z x Z with Z = z1 + z2 <= 4 free coordinates, solved at that fixed size (a template per
// Z) so that a capsule pair solves 2 x 2, not a padded 4 x 4. Where the closest points are not
// unique (parallel features) M'M is singular; the pseudo-inverse then gives the minimum-norm
// motion, eigenvalues below 1e-12 of the largest treated as zero, the relative threshold of the
// parallel tests. The cheap closed-form inverse serves whenever det(M'M) / prod(diag) > 1e-12,
// which rules that out.
template <int Z>
void add_point_motion_of_size(const PosedCore& a, const ClosestFeature& sa, const PosedCore& b,
                              const ClosestFeature& sb, const Eigen::Vector3d& difference,
                              Matrix3x14& dp1, Matrix3x14& dp2) {
  const int z1 = sa.free_dimensions;
  Eigen::Matrix<double, 3, Z> M;
  Eigen::Matrix<double, Z, 14> rhs;
  const Eigen::Matrix<double, 3, 4> turn_a = a.attitude.rotate_transpose_jacobian(difference);
  const Eigen::Matrix<double, 3, 4> turn_b = b.attitude.rotate_transpose_jacobian(difference);
  for (int k = 0; k < Z; ++k) {
    const bool first = k < z1;
    const Eigen::Vector3d direction =
        first ? sa.free_directions.col(k) : sb.free_directions.col(k - z1);
    M.col(k) = first ? Eigen::Vector3d(a.attitude.matrix() * direction)
                     : Eigen::Vector3d(-b.attitude.matrix() * direction);
    rhs.row(k) = -M.col(k).transpose() * (dp1 - dp2);
    if (first) {
      rhs.row(k).template segment<4>(3) -= direction.transpose() * turn_a;
    } else {
      rhs.row(k).template segment<4>(10) += direction.transpose() * turn_b;
    }
  }
  const Eigen::Matrix<double, Z, Z> hessian = M.transpose() * M;
  Eigen::Matrix<double, Z, 14> dxi;
  if (hessian.determinant() > 1e-12 * hessian.diagonal().prod()) {
    dxi = hessian.inverse() * rhs;
  } else {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, Z, Z>> eigen(hessian);
    const double largest = eigen.eigenvalues().cwiseAbs().maxCoeff();
    Eigen::Matrix<double, Z, Z> pseudo_inverse = Eigen::Matrix<double, Z, Z>::Zero();
    for (int k = 0; k < Z; ++k) {
      const double value = eigen.eigenvalues()(k);
      if (value > 1e-12 * largest) {
        pseudo_inverse +=
            eigen.eigenvectors().col(k) * eigen.eigenvectors().col(k).transpose() / value;
      }
    }
    dxi = pseudo_inverse * rhs;
  }
  for (int k = 0; k < Z; ++k) {  // dp1 += Q1 D1 dxi1, dp2 += Q2 D2 dxi2 = -(M's right block) dxi2
    (k < z1 ? dp1 : dp2) += M.col(k) * dxi.row(k) * (k < z1 ? 1.0 : -1.0);
  }
}

}  // namespace

Matrix3x14 fixed_point_jacobian(const PosedCore& core, const ClosestFeature& side, int column) {
  Matrix3x14 jacobian = Matrix3x14::Zero();
  jacobian.block<3, 3>(0, column).setIdentity();
  jacobian.block<3, 4>(0, column + 3) = core.attitude.rotate_jacobian(side.body_point);
  return jacobian;
}

void add_point_motion(const PosedCore& a, const ClosestFeature& sa, const PosedCore& b,
                      const ClosestFeature& sb, const Eigen::Vector3d& difference, Matrix3x14& dp1,
                      Matrix3x14& dp2) {
  switch (sa.free_dimensions + sb.free_dimensions) {
    case 1:
      return add_point_motion_of_size<1>(a, sa, b, sb, difference, dp1, dp2);
    case 2:
      return add_point_motion_of_size<2>(a, sa, b, sb, difference, dp1, dp2);
    case 3:
      return add_point_motion_of_size<3>(a, sa, b, sb, difference, dp1, dp2);
    case 4:
      return add_point_motion_of_size<4>(a, sa, b, sb, difference, dp1, dp2);
    default:
      return;  // both points fixed (vertices, segment ends, spheres): nothing moves them
  }
}

PointMotion core_point_motion(const PosedCore& a, const ClosestFeature& sa, const PosedCore& b,
                              const ClosestFeature& sb) {
  PointMotion motion{fixed_point_jacobian(a, sa, 0), fixed_point_jacobian(b, sb, 7)};
  const Eigen::Vector3d p1 = a.r + a.attitude.matrix() * sa.body_point;
  const Eigen::Vector3d p2 = b.r + b.attitude.matrix() * sb.body_point;
  add_point_motion(a, sa, b, sb, p1 - p2, motion.dp1, motion.dp2);
  return motion;
}

void point_jacobians(double scale, const PosedCore& a, const PosedCore& b,
                     const PointMotion& motion, const Matrix3x14& dnormal,
                     Eigen::Matrix<double, 6, 14>& core_points_jacobian,
                     Eigen::Matrix<double, 6, 14>& points_jacobian) {
  core_points_jacobian.topRows<3>() = motion.dp1;
  core_points_jacobian.bottomRows<3>() = motion.dp2;
  points_jacobian.topRows<3>() = motion.dp1 + a.radius * dnormal;
  points_jacobian.bottomRows<3>() = motion.dp2 - b.radius * dnormal;
  for (const int column : {3, 10}) {
    core_points_jacobian.middleCols<4>(column) *= scale;
    points_jacobian.middleCols<4>(column) *= scale;
  }
}

// Applied as (dv - n (n' dv)) / |v|: no 3 x 3 matrix.
Matrix3x14 unit_vector_motion(const Eigen::Vector3d& v, const Matrix3x14& dv) {
  const double inverse_length = 1.0 / v.norm();
  const Eigen::Vector3d n = v * inverse_length;
  return (dv - n * (n.transpose() * dv)) * inverse_length;
}

}  // namespace diffpills::detail
