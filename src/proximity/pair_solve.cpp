#include "pair_solve.hpp"

#include <string>

#include "diffpills/qp/interior_point.hpp"

namespace diffpills::detail {

PairSolution solve_pair(const PairProblem& problem) {
  PairSolution solution;
  const int n = problem.n();
  if (n == 0) {
    return solution;
  }
  // The paper's P = F'F, c = F'g (eqs. caps_qp_cost, polygon_qp_cost, polygon_caps_qp_cost).
  const Eigen::MatrixXd P = problem.F.transpose() * problem.F;
  const Eigen::VectorXd c = problem.F.transpose() * problem.g;

  qp::InteriorPointSolver solver;
  const qp::InteriorPointResult& result = solver.solve(P, c, problem.G, problem.h);
  if (result.status != qp::Status::kSolved) {
    throw SolverError(std::string("diffpills: the interior-point method stopped with status ") +
                      qp::to_string(result.status) + " after " + std::to_string(result.iterations) +
                      " iterations");
  }
  solution.x = result.x;
  solution.lambda = result.lambda;
  if (!result.polished) {
    // An unpolished interior point keeps every multiplier positive; the active set is the rows
    // whose multiplier dominates their slack, the same guess the polish makes.
    for (Eigen::Index i = 0; i < result.lambda.size(); ++i) {
      if (result.lambda(i) <= result.s(i)) solution.lambda(i) = 0.0;
    }
  }
  return solution;
}

std::array<ClosestFeature, 2> core_solutions(const PairProblem& problem,
                                             const PairSolution& solution) {
  std::array<ClosestFeature, 2> sides;
  Eigen::Index row = 0;
  for (int i = 0; i < 2; ++i) {
    const ParametricCore& core = *problem.cores[static_cast<std::size_t>(i)];
    ClosestFeature& side = sides[static_cast<std::size_t>(i)];
    side.body_point = problem.body_point(i, solution.x);
    int active = 0;
    Eigen::Index last_active = 0;
    for (Eigen::Index j = 0; j < core.G.rows(); ++j) {
      if (solution.lambda(row + j) > 0.0) {
        ++active;
        last_active = j;
      }
    }
    row += core.G.rows();
    if (core.dim == 1 && active == 0) {
      side.free_dimensions = 1;
      side.free_directions.col(0) = Eigen::Vector3d::UnitX();
    } else if (core.dim == 2 && active == 0) {
      side.free_dimensions = 2;
      side.free_directions.col(0) = Eigen::Vector3d::UnitX();
      side.free_directions.col(1) = Eigen::Vector3d::UnitY();
    } else if (core.dim == 2 && active == 1) {
      side.free_dimensions = 1;
      side.free_directions.col(0) << -core.G(last_active, 1), core.G(last_active, 0), 0.0;
    }
  }
  return sides;
}

}  // namespace diffpills::detail
