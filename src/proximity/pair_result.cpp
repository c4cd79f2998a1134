#include "pair_result.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <vector>

#include "diffpills/rotation.hpp"

namespace diffpills::detail {
namespace {

using Matrix3x14 = Eigen::Matrix<double, 3, 14>;

// d p_i / d[r1 q1 r2 q2] with the core parameters x held fixed: p_i = r_i + Q(q_i) u_i, so
// dp_i/dr_i = I and dp_i/dq_i = d(Q(q_i) u_i)/dq_i, in shape i's seven columns.
Matrix3x14 fixed_parameter_jacobian(const PairProblem& problem, int i, const Eigen::VectorXd& x) {
  Matrix3x14 jacobian = Matrix3x14::Zero();
  const int column = 7 * i;
  jacobian.block<3, 3>(0, column).setIdentity();
  jacobian.block<3, 4>(0, column + 3) =
      rotate_jacobian(problem.q[static_cast<std::size_t>(i)], problem.body_point(i, x));
  return jacobian;
}

// Below this distance the cores count as intersecting. Rounding in p1 - p2 is of order
// eps * max(|p1|, |p2|, core size), so the threshold is relative to the same quantities.
double intersection_tolerance(const PairProblem& problem, const Eigen::Vector3d& p1,
                              const Eigen::Vector3d& p2) {
  return 1e-12 * std::max({std::max(problem.cores[0]->size, problem.cores[1]->size),
                           p1.lpNorm<Eigen::Infinity>(), p2.lpNorm<Eigen::Infinity>()});
}

enum class NormalRule { kClosestPoints, kOrigins, kBodyAxis };

// The normal's rule (see proximity.hpp): the closest-point direction while the cores are apart;
// otherwise the direction between the body origins, or shape 1's body z axis if those coincide.
NormalRule normal_rule(const PairProblem& problem, const Eigen::Vector3d& p1,
                       const Eigen::Vector3d& p2) {
  const double tolerance = intersection_tolerance(problem, p1, p2);
  if ((p2 - p1).norm() > tolerance) return NormalRule::kClosestPoints;
  if ((problem.r[1] - problem.r[0]).norm() > tolerance) return NormalRule::kOrigins;
  return NormalRule::kBodyAxis;
}

// d(v / |v|) = (I - n n') / |v| dv.
Eigen::Matrix3d unit_vector_jacobian(const Eigen::Vector3d& v) {
  const Eigen::Vector3d n = v.normalized();
  return (Eigen::Matrix3d::Identity() - n * n.transpose()) / v.norm();
}

// Implicit function theorem on the KKT conditions of the scaled pair QP (paper section II-C):
// with e^ = F x + g and the active rows A = {j : lambda_j > 0},
//   stationarity  F'e^ + G_A' lambda_A = 0,   activity  G_A x = h_A.
// Differentiating in a pose coordinate xi (G, h do not depend on poses):
//   [ F'F  G_A' ] [ dx       ]   [ -(F' de^/dxi|_x + dF'/dxi e^) ]
//   [ G_A  0    ] [ dlambda_A ] = [ 0                             ]
// where de^/dxi|_x = (dp1/dxi - dp2/dxi)|_x / s and, since F' = [U1'Q1'; -U2'Q2'] / s,
//   dF'/dq_i e^ = +-U_i' d(Q_i' e^)/dq_i / s   (+ for core 1, - for core 2).
// The system is solved by a complete orthogonal decomposition: where the minimizer is not unique
// the matrix is singular and the minimum-norm solution is returned (see proximity.hpp).
Eigen::MatrixXd parameter_jacobian(const PairProblem& problem, const PairSolution& solution,
                                   const Matrix3x14& difference_jacobian,
                                   const Eigen::Vector3d& difference) {
  const int n = problem.n();
  const double s = problem.scale;
  const Eigen::Vector3d scaled_difference = difference / s;
  Eigen::MatrixXd rhs_top = -(problem.F.transpose() * difference_jacobian) / s;
  int row = 0;
  for (int i = 0; i < 2; ++i) {
    const Core& core = *problem.cores[static_cast<std::size_t>(i)];
    const double sign = i == 0 ? 1.0 : -1.0;
    rhs_top.block(row, 7 * i + 3, core.dim, 4) -=
        sign / s * core.U.leftCols(core.dim).transpose() *
        rotate_transpose_jacobian(problem.q[static_cast<std::size_t>(i)], scaled_difference);
    row += core.dim;
  }
  std::vector<Eigen::Index> active;
  for (Eigen::Index j = 0; j < solution.lambda.size(); ++j) {
    if (solution.lambda(j) > 0.0) active.push_back(j);
  }
  const auto k = static_cast<Eigen::Index>(active.size());
  Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(n + k, n + k);
  kkt.topLeftCorner(n, n) = problem.F.transpose() * problem.F;
  for (Eigen::Index j = 0; j < k; ++j) {
    const Eigen::Index constraint = active[static_cast<std::size_t>(j)];
    kkt.block(n + j, 0, 1, n) = problem.G.row(constraint);
    kkt.block(0, n + j, n, 1) = problem.G.row(constraint).transpose();
  }
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n + k, 14);
  rhs.topRows(n) = rhs_top;
  return kkt.completeOrthogonalDecomposition().solve(rhs).topRows(n);
}

}  // namespace

Proximity make_proximity(const PairProblem& problem, const PairSolution& solution) {
  Proximity result;
  const Eigen::Vector3d p1 = problem.world_point(0, solution.x);
  const Eigen::Vector3d p2 = problem.world_point(1, solution.x);
  const double radius_sum = problem.cores[0]->radius + problem.cores[1]->radius;
  const Eigen::Vector3d difference = p1 - p2;
  result.phi = difference.squaredNorm() - radius_sum * radius_sum;  // eq. caps_prox
  result.core_points = {p1, p2};
  // Envelope theorem: d phi = 2 (p1 - p2)' (dp1 - dp2) at fixed x*.
  const Matrix3x14 difference_jacobian = fixed_parameter_jacobian(problem, 0, solution.x) -
                                         fixed_parameter_jacobian(problem, 1, solution.x);
  result.gradient = 2.0 * difference_jacobian.transpose() * difference;

  switch (normal_rule(problem, p1, p2)) {
    case NormalRule::kClosestPoints:
      result.normal = (p2 - p1).normalized();
      break;
    case NormalRule::kOrigins:
      result.cores_intersect = true;
      result.normal = (problem.r[1] - problem.r[0]).normalized();
      break;
    case NormalRule::kBodyAxis:
      result.cores_intersect = true;
      result.normal = problem.rotation[0].col(2);
      break;
  }
  // eqs. caps_c_1, caps_c_2
  result.points = {p1 + problem.cores[0]->radius * result.normal,
                   p2 - problem.cores[1]->radius * result.normal};
  return result;
}

ProximityJacobian make_proximity_jacobian(const PairProblem& problem,
                                          const PairSolution& solution) {
  ProximityJacobian result;
  static_cast<Proximity&>(result) = make_proximity(problem, solution);
  const Eigen::Vector3d& p1 = result.core_points[0];
  const Eigen::Vector3d& p2 = result.core_points[1];

  // dp_i = dp_i|_x + Q_i U_i dx_i.
  Matrix3x14 dp1 = fixed_parameter_jacobian(problem, 0, solution.x);
  Matrix3x14 dp2 = fixed_parameter_jacobian(problem, 1, solution.x);
  if (problem.n() > 0) {
    const Eigen::MatrixXd dx = parameter_jacobian(problem, solution, dp1 - dp2, p1 - p2);
    const Core& core1 = *problem.cores[0];
    const Core& core2 = *problem.cores[1];
    dp1 += problem.rotation[0] * core1.U.leftCols(core1.dim) * dx.topRows(core1.dim);
    dp2 += problem.rotation[1] * core2.U.leftCols(core2.dim) * dx.bottomRows(core2.dim);
  }
  result.core_points_jacobian.topRows<3>() = dp1;
  result.core_points_jacobian.bottomRows<3>() = dp2;

  Matrix3x14 dnormal = Matrix3x14::Zero();
  switch (normal_rule(problem, p1, p2)) {
    case NormalRule::kClosestPoints:
      dnormal = unit_vector_jacobian(p2 - p1) * (dp2 - dp1);
      break;
    case NormalRule::kOrigins: {
      const Eigen::Matrix3d d_unit = unit_vector_jacobian(problem.r[1] - problem.r[0]);
      dnormal.block<3, 3>(0, 0) = -d_unit;
      dnormal.block<3, 3>(0, 7) = d_unit;
      break;
    }
    case NormalRule::kBodyAxis:
      dnormal.block<3, 4>(0, 3) = rotate_jacobian(problem.q[0], Eigen::Vector3d::UnitZ());
      break;
  }
  result.points_jacobian.topRows<3>() = dp1 + problem.cores[0]->radius * dnormal;
  result.points_jacobian.bottomRows<3>() = dp2 - problem.cores[1]->radius * dnormal;
  return result;
}

}  // namespace diffpills::detail
