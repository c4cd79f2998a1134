#include "pair_problem.hpp"

#include <algorithm>

namespace diffpills::detail {

Eigen::VectorXd PairProblem::parameters(int i, const Eigen::VectorXd& x) const {
  return i == 0 ? x.head(cores[0]->dim) : x.segment(cores[0]->dim, cores[1]->dim);
}

Eigen::Vector3d PairProblem::body_point(int i, const Eigen::VectorXd& x) const {
  const ParametricCore& core = *cores[static_cast<std::size_t>(i)];
  return core.U.leftCols(core.dim) * parameters(i, x) + core.u0;
}

PairProblem make_pair_problem(const ParametricCore& core1, const PosedCore& pose1,
                              const ParametricCore& core2, const PosedCore& pose2) {
  PairProblem problem;
  problem.cores = {&core1, &core2};
  const Eigen::Matrix3d& rotation1 = pose1.attitude.matrix();
  const Eigen::Matrix3d& rotation2 = pose2.attitude.matrix();
  // Two spheres have no parameters and no size; any positive scale then serves.
  problem.scale = std::max(core1.size, core2.size);
  if (problem.scale == 0.0) {
    problem.scale = 1.0;
  }
  const int n1 = core1.dim;
  const int n2 = core2.dim;
  const double inverse_scale = 1.0 / problem.scale;
  problem.F.resize(3, n1 + n2);
  problem.F.leftCols(n1) = inverse_scale * rotation1 * core1.U.leftCols(n1);
  problem.F.rightCols(n2) = -inverse_scale * rotation2 * core2.U.leftCols(n2);
  problem.g = inverse_scale * (pose1.r + rotation1 * core1.u0 - pose2.r - rotation2 * core2.u0);
  const Eigen::Index m1 = core1.G.rows();
  const Eigen::Index m2 = core2.G.rows();
  problem.G = Eigen::MatrixXd::Zero(m1 + m2, n1 + n2);
  problem.G.topLeftCorner(m1, n1) = core1.G;
  problem.G.bottomRightCorner(m2, n2) = core2.G;
  problem.h.resize(m1 + m2);
  problem.h << core1.h, core2.h;
  return problem;
}

}  // namespace diffpills::detail
