#include "point_motion.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>

namespace diffpills::detail {
namespace {

// Implicit function theorem with the active set eliminated (posed_core.hpp). Near the
// solution p_i = r_i + Q_i (u_i + D_i xi_i), and the free coordinates xi = (xi1, xi2) minimize
// f = |e|^2, e = p1 - p2, without constraints. With M = [Q1 D1, -Q2 D2] stationarity is
// f_xi / 2 = M'e = 0; differentiating in a pose coordinate at the solution (xi = 0),
//   M'M dxi = -coupling,   coupling = f_xi,x / 2 = M' de/dx|_xi + dM'/dx e,
//   de/dx|_xi = dp1|_u - dp2|_u,   dM'/dq_i e = +-D_i' d(Q_i' e)/dq_i   (+ core 1, - core 2).
// M'M = f_xi,xi / 2 is Z x Z with Z = z1 + z2 <= 4 free coordinates, solved at that fixed size (a
// template per Z) so that a capsule pair solves 2 x 2, not a padded 4 x 4.
//
// (M'M)^-1 = M^+ M^+' with M^+ = (M'M)^-1 M' the pseudo-inverse of M, which for Z <= 3 has a
// closed form in cross products (m_k the columns of M, n = m1 x m2):
//   Z = 1:  M^+ = m1' / |m1|^2
//   Z = 2:  M^+ = [ (m2 x n)' ; (n x m1)' ] / |n|^2                       (m_j . row k = delta)
//   Z = 3:  M^+ = M^-1 = [ (m2 x m3)' ; (m3 x m1)' ; (m1 x m2)' ] / (m1 . (m2 x m3))
// Forming M'M and inverting it instead loses its small eigenvalue: for two unit directions at an
// angle theta, det(M'M) = 1 - (m1 . m2)^2 = sin^2 theta cancels to nothing below theta ~ 1e-8,
// while |m1 x m2| = sin theta keeps its digits. The directions are dependent (the closest points
// not unique) when that sine, |n| / (|m1| |m2|) or |m1 . (m2 x m3)| / (|m1| |m2| |m3|), is at
// most 1e-12: the very threshold the solvers' parallel tests use, so that the points the solver
// calls unique get their exact derivatives (an earlier test on det(M'M) / prod(diag) <= 1e-12, a
// sine of 1e-6, gave twisted segments between the two thresholds the parallel answer, 1e12
// off). Four free coordinates in three dimensions are always dependent. Dependent directions
// take the minimum-norm motion: the pseudo-inverse of M'M, eigenvalues below 1e-12 of the
// largest treated as zero (at a sine below 1e-12 the small eigenvalue, below 1e-24, is rounding).
template <int Z>
bool independent_pseudo_inverse(const Eigen::Matrix<double, 3, Z>& M,
                                Eigen::Matrix<double, Z, 3>& pseudo_inverse) {
  constexpr double kSine = 1e-12;
  if constexpr (Z == 1) {
    const double length2 = M.squaredNorm();
    if (!(length2 > 0.0)) return false;
    pseudo_inverse = M.transpose() / length2;
    return true;
  } else if constexpr (Z == 2) {
    const Eigen::Vector3d m1 = M.col(0), m2 = M.col(1);
    const Eigen::Vector3d n = m1.cross(m2);
    const double n2 = n.squaredNorm();
    if (!(n2 > kSine * kSine * m1.squaredNorm() * m2.squaredNorm())) return false;
    const double inverse = 1.0 / n2;  // one division, not six
    pseudo_inverse.row(0) = m2.cross(n).transpose() * inverse;
    pseudo_inverse.row(1) = n.cross(m1).transpose() * inverse;
    return true;
  } else if constexpr (Z == 3) {
    const Eigen::Vector3d m1 = M.col(0), m2 = M.col(1), m3 = M.col(2);
    const Eigen::Vector3d n = m2.cross(m3);
    const double volume = m1.dot(n);
    if (!(std::abs(volume) > kSine * m1.norm() * m2.norm() * m3.norm())) return false;
    const double inverse = 1.0 / volume;
    pseudo_inverse.row(0) = n.transpose() * inverse;
    pseudo_inverse.row(1) = m3.cross(m1).transpose() * inverse;
    pseudo_inverse.row(2) = m1.cross(m2).transpose() * inverse;
    return true;
  } else {
    return false;
  }
}

template <int Z>
void add_point_motion(const PosedCore& a, const ClosestFeature& sa, const PosedCore& b,
                      const ClosestFeature& sb, const Eigen::Vector3d& difference,
                      PointMotion& motion) {
  const int z1 = sa.free_dimensions;
  Eigen::Matrix<double, 3, Z> M;
  motion.free = Z;
  auto coupling = motion.coupling.topRows<Z>();
  auto dxi = motion.free_motion.topRows<Z>();
  const Eigen::Matrix<double, 3, 4> turn_a = a.attitude.rotate_transpose_jacobian(difference);
  const Eigen::Matrix<double, 3, 4> turn_b = b.attitude.rotate_transpose_jacobian(difference);
  for (int k = 0; k < Z; ++k) {
    const bool first = k < z1;
    const Eigen::Vector3d direction =
        first ? sa.free_directions.col(k) : sb.free_directions.col(k - z1);
    M.col(k) = first ? Eigen::Vector3d(a.attitude.matrix() * direction)
                     : Eigen::Vector3d(-b.attitude.matrix() * direction);
    coupling.row(k) = M.col(k).transpose() * (motion.dp1 - motion.dp2);
    if (first) {
      coupling.row(k).template segment<4>(3) += direction.transpose() * turn_a;
    } else {
      coupling.row(k).template segment<4>(10) -= direction.transpose() * turn_b;
    }
  }
  Eigen::Matrix<double, Z, 3> pseudo_inverse_of_M;
  if (independent_pseudo_inverse<Z>(M, pseudo_inverse_of_M)) {
    const Eigen::Matrix<double, Z, Z> inverse_curvature =
        pseudo_inverse_of_M * pseudo_inverse_of_M.transpose();
    dxi.noalias() = -(inverse_curvature * coupling);
  } else {
    const Eigen::Matrix<double, Z, Z> curvature = M.transpose() * M;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, Z, Z>> eigen(curvature);
    const double largest = eigen.eigenvalues().cwiseAbs().maxCoeff();
    Eigen::Matrix<double, Z, Z> pseudo_inverse = Eigen::Matrix<double, Z, Z>::Zero();
    for (int k = 0; k < Z; ++k) {
      const double value = eigen.eigenvalues()(k);
      if (value > 1e-12 * largest) {
        pseudo_inverse +=
            eigen.eigenvectors().col(k) * eigen.eigenvectors().col(k).transpose() / value;
      }
    }
    dxi.noalias() = -(pseudo_inverse * coupling);
  }
  for (int k = 0; k < Z; ++k) {  // dp1 += Q1 D1 dxi1, dp2 += Q2 D2 dxi2 = -(M's right block) dxi2
    (k < z1 ? motion.dp1 : motion.dp2) += M.col(k) * dxi.row(k) * (k < z1 ? 1.0 : -1.0);
  }
}

// d p / d[r1 q1 r2 q2] with the body point u held fixed: p = r + Q(q) u, so dp/dr = I and
// dp/dq = d(Q(q) u)/dq = turn, in the shape's seven columns (column offset 0 or 7).
void set_fixed_point_jacobian(const Eigen::Matrix<double, 3, 4>& turn, int column,
                              Matrix3x14& jacobian) {
  jacobian.setZero();
  jacobian.block<3, 3>(0, column).setIdentity();
  jacobian.block<3, 4>(0, column + 3) = turn;
}

}  // namespace

PointMotion core_point_motion(const PosedCore& a, const ClosestFeature& sa, const PosedCore& b,
                              const ClosestFeature& sb) {
  PointMotion motion;
  motion.turn = {a.attitude.rotate_jacobian(sa.body_point),
                 b.attitude.rotate_jacobian(sb.body_point)};
  set_fixed_point_jacobian(motion.turn[0], 0, motion.dp1);
  set_fixed_point_jacobian(motion.turn[1], 7, motion.dp2);
  const Eigen::Vector3d p1 = a.r + a.attitude.matrix() * sa.body_point;
  const Eigen::Vector3d p2 = b.r + b.attitude.matrix() * sb.body_point;
  const Eigen::Vector3d difference = p1 - p2;
  switch (sa.free_dimensions + sb.free_dimensions) {
    case 1:
      add_point_motion<1>(a, sa, b, sb, difference, motion);
      break;
    case 2:
      add_point_motion<2>(a, sa, b, sb, difference, motion);
      break;
    case 3:
      add_point_motion<3>(a, sa, b, sb, difference, motion);
      break;
    case 4:
      add_point_motion<4>(a, sa, b, sb, difference, motion);
      break;
    default:  // both points fixed (vertices, segment ends, spheres): nothing moves them
      break;
  }
  return motion;
}

// Column by column: a column of a 6 x 14 matrix is six consecutive doubles, written once, with
// its unit factor (scale for the quaternion columns) applied on the way.
void point_jacobians(double scale, const PosedCore& a, const PosedCore& b,
                     const PointMotion& motion, const Matrix3x14& dnormal,
                     Eigen::Matrix<double, 6, 14>& core_points_jacobian,
                     Eigen::Matrix<double, 6, 14>& points_jacobian) {
  for (int column = 0; column < 14; ++column) {
    const bool rotation = (column >= 3 && column < 7) || column >= 10;
    const double factor = rotation ? scale : 1.0;
    const Eigen::Vector3d dp1 = factor * motion.dp1.col(column);
    const Eigen::Vector3d dp2 = factor * motion.dp2.col(column);
    const Eigen::Vector3d dn = factor * dnormal.col(column);
    core_points_jacobian.col(column) << dp1, dp2;
    points_jacobian.col(column) << dp1 + a.radius * dn, dp2 - b.radius * dn;
  }
}

// Applied as (dv - n (n' dv)) / |v|: no 3 x 3 matrix.
Matrix3x14 unit_vector_motion(const Eigen::Vector3d& v, const Matrix3x14& dv) {
  const double inverse_length = 1.0 / v.norm();
  const Eigen::Vector3d n = v * inverse_length;
  return (dv - n * (n.transpose() * dv)) * inverse_length;
}

}  // namespace diffpills::detail
