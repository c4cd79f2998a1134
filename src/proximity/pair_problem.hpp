// The closest-point QP of two cores (paper eqs. caps_qp_cost-caps_qp_cons,
// polygon_qp_cost-polygon_qp_cons, polygon_caps_qp_cost-polygon_caps_qp_cons, in one form).
//
// With p_i = r_i + Q_i (U_i x_i + u0_i) and x = [x1; x2], the core-to-core difference is affine:
//
//     p1 - p2 = s (F x + g),   F = [Q1 U1, -Q2 U2] / s,   g = (r1 + Q1 u01 - r2 - Q2 u02) / s
//
// so |p1 - p2|^2 = s^2 (x'Px + 2 c'x + g'g) with P = F'F and c = F'g, subject to the
// pose-independent G x <= h = blkdiag(G1, G2) x <= [h1; h2]. The scale s (the larger core size)
// makes the data dimensionless. For two capsules this is the paper's F = [a1 - b1, b2 - a2] and
// c = F'(b1 - b2) divided by s; for two polygons F = [Q~1, -Q~2] and c = F'(r1 - r2), up to the
// extent scaling of each polygon's parameter.
#pragma once

#include <Eigen/Core>
#include <array>

#include "parametric_core.hpp"
#include "posed_core.hpp"

namespace diffpills::detail {

struct PairProblem {
  std::array<const ParametricCore*, 2> cores{};
  double scale = 1.0;  // s
  Eigen::MatrixXd F;   // 3 x n
  Eigen::Vector3d g;
  Eigen::MatrixXd G;  // (m1 + m2) x n, block diagonal
  Eigen::VectorXd h;

  int n() const { return cores[0]->dim + cores[1]->dim; }
  // The parameters of core i within x.
  Eigen::VectorXd parameters(int i, const Eigen::VectorXd& x) const;
  // Body-frame point U_i x_i + u0_i of core i.
  Eigen::Vector3d body_point(int i, const Eigen::VectorXd& x) const;
};

// The cores must outlive the problem. The poses are the posed cores' (in the query's frame).
PairProblem make_pair_problem(const ParametricCore& core1, const PosedCore& pose1,
                              const ParametricCore& core2, const PosedCore& pose2);

}  // namespace diffpills::detail
