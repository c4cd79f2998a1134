#include "pair_result.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>

namespace diffpills::detail {
namespace {

using Matrix3x14 = Eigen::Matrix<double, 3, 14>;

// d p / d[r1 q1 r2 q2] with the body point u held fixed: p = r + Q(q) u, so dp/dr = I and
// dp/dq = d(Q(q) u)/dq, in the shape's seven columns (column offset 0 or 7).
Matrix3x14 fixed_point_jacobian(const PosedCore& core, const ClosestFeature& side, int column) {
  Matrix3x14 jacobian = Matrix3x14::Zero();
  jacobian.block<3, 3>(0, column).setIdentity();
  jacobian.block<3, 4>(0, column + 3) = core.attitude.rotate_jacobian(side.body_point);
  return jacobian;
}

enum class NormalRule { kClosestPoints, kOrigins, kBodyAxis };

// The normal's rule (see proximity.hpp): the closest-point direction while the cores are apart by
// more than the frame's tolerance (1e-12 of the scene's size); otherwise the direction between the
// body origins, or shape 1's body z axis if those coincide too. Compared squared, to spare square
// roots on the hot path; in the frame's units no square under- or overflows.
NormalRule normal_rule(const PairFrame& frame, const PosedCore& a, const PosedCore& b,
                       const Eigen::Vector3d& p1, const Eigen::Vector3d& p2) {
  const double tolerance2 = frame.tolerance * frame.tolerance;
  if ((p2 - p1).squaredNorm() > tolerance2) return NormalRule::kClosestPoints;
  if ((b.r - a.r).squaredNorm() > tolerance2) return NormalRule::kOrigins;
  return NormalRule::kBodyAxis;
}

// d(v / |v|) = (I - n n') / |v| dv, applied as (dv - n (n' dv)) / |v| (no 3 x 3 matrix).
Matrix3x14 unit_vector_motion(const Eigen::Vector3d& v, const Matrix3x14& dv) {
  const double inverse_length = 1.0 / v.norm();
  const Eigen::Vector3d n = v * inverse_length;
  return (dv - n * (n.transpose() * dv)) * inverse_length;
}

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
void add_point_motion(const PosedCore& a, const ClosestFeature& sa, const PosedCore& b,
                      const ClosestFeature& sb, const Eigen::Vector3d& difference, Matrix3x14& dp1,
                      Matrix3x14& dp2) {
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

void add_point_motion(const PosedCore& a, const ClosestFeature& sa, const PosedCore& b,
                      const ClosestFeature& sb, const Eigen::Vector3d& difference, Matrix3x14& dp1,
                      Matrix3x14& dp2) {
  switch (sa.free_dimensions + sb.free_dimensions) {
    case 1:
      return add_point_motion<1>(a, sa, b, sb, difference, dp1, dp2);
    case 2:
      return add_point_motion<2>(a, sa, b, sb, difference, dp1, dp2);
    case 3:
      return add_point_motion<3>(a, sa, b, sb, difference, dp1, dp2);
    case 4:
      return add_point_motion<4>(a, sa, b, sb, difference, dp1, dp2);
    default:
      return;  // both points fixed (vertices, segment ends, spheres): nothing moves them
  }
}

// The frame's results (see the header) in the inputs' units.
void restore_units(const PairFrame& frame, Proximity& result) {
  const double s = frame.scale;
  result.phi = result.phi * s * s;  // two products: s * s alone may underflow where phi does not
  result.gradient.segment<3>(0) *= s;
  result.gradient.segment<4>(3) *= s * s;
  result.gradient.segment<3>(7) *= s;
  result.gradient.segment<4>(10) *= s * s;
}

}  // namespace

Proximity make_proximity(const PairFrame& frame, const Pose& pose_a, const PosedCore& a,
                         const ClosestFeature& side_a, const Pose& pose_b, const PosedCore& b,
                         const ClosestFeature& side_b) {
  Proximity result;
  const Eigen::Vector3d offset_a = a.attitude.matrix() * side_a.body_point;  // Q u, frame units
  const Eigen::Vector3d offset_b = b.attitude.matrix() * side_b.body_point;
  const Eigen::Vector3d p1 = a.r + offset_a;
  const Eigen::Vector3d p2 = b.r + offset_b;
  const Eigen::Vector3d difference = p1 - p2;
  const double radius_sum = a.radius + b.radius;
  result.phi = difference.squaredNorm() - radius_sum * radius_sum;  // eq. caps_prox
  // Envelope theorem: d phi = 2 (p1 - p2)' (dp1 - dp2) with the body points held fixed.
  result.gradient.segment<3>(0) = 2.0 * difference;
  result.gradient.segment<4>(3) = 2.0 * a.attitude.rotate_gradient(side_a.body_point, difference);
  result.gradient.segment<3>(7) = -2.0 * difference;
  result.gradient.segment<4>(10) = -2.0 * b.attitude.rotate_gradient(side_b.body_point, difference);

  switch (normal_rule(frame, a, b, p1, p2)) {
    case NormalRule::kClosestPoints:
      result.normal = difference * (-1.0 / difference.norm());  // one division, not three
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
  restore_units(frame, result);
  result.core_points = {pose_a.r() + frame.scale * offset_a, pose_b.r() + frame.scale * offset_b};
  const double radius_a = frame.scale * a.radius, radius_b = frame.scale * b.radius;
  result.points = {result.core_points[0] + radius_a * result.normal,
                   result.core_points[1] - radius_b * result.normal};  // eqs. caps_c_1, caps_c_2
  return result;
}

ProximityJacobian make_proximity_jacobian(const PairFrame& frame, const Pose& pose_a,
                                          const PosedCore& a, const ClosestFeature& side_a,
                                          const Pose& pose_b, const PosedCore& b,
                                          const ClosestFeature& side_b) {
  ProximityJacobian result;
  static_cast<Proximity&>(result) = make_proximity(frame, pose_a, a, side_a, pose_b, b, side_b);
  const Eigen::Vector3d p1 = a.r + a.attitude.matrix() * side_a.body_point;
  const Eigen::Vector3d p2 = b.r + b.attitude.matrix() * side_b.body_point;

  Matrix3x14 dp1 = fixed_point_jacobian(a, side_a, 0);
  Matrix3x14 dp2 = fixed_point_jacobian(b, side_b, 7);
  add_point_motion(a, side_a, b, side_b, p1 - p2, dp1, dp2);

  Matrix3x14 dnormal = Matrix3x14::Zero();
  switch (normal_rule(frame, a, b, p1, p2)) {
    case NormalRule::kClosestPoints:
      dnormal = unit_vector_motion(p2 - p1, dp2 - dp1);
      break;
    case NormalRule::kOrigins: {
      Matrix3x14 d_origins = Matrix3x14::Zero();  // d(r2 - r1)
      d_origins.block<3, 3>(0, 0) = -Eigen::Matrix3d::Identity();
      d_origins.block<3, 3>(0, 7) = Eigen::Matrix3d::Identity();
      dnormal = unit_vector_motion(b.r - a.r, d_origins);
      break;
    }
    case NormalRule::kBodyAxis:
      dnormal.block<3, 4>(0, 3) = a.attitude.rotate_jacobian(Eigen::Vector3d::UnitZ());
      break;
  }
  result.core_points_jacobian.topRows<3>() = dp1;
  result.core_points_jacobian.bottomRows<3>() = dp2;
  result.points_jacobian.topRows<3>() = dp1 + a.radius * dnormal;
  result.points_jacobian.bottomRows<3>() = dp2 - b.radius * dnormal;
  // d/dr is free of units (a length per length), d/dq is a length: the quaternion columns scale.
  for (const int column : {3, 10}) {
    result.core_points_jacobian.middleCols<4>(column) *= frame.scale;
    result.points_jacobian.middleCols<4>(column) *= frame.scale;
  }
  return result;
}

}  // namespace diffpills::detail
