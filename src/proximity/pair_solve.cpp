#include "pair_solve.hpp"

#include <string>

#include "diffpills/qp/box_active_set.hpp"
#include "diffpills/qp/interior_point.hpp"

namespace diffpills::detail {

PairSolution solve_pair(const PairProblem& problem, Method method) {
  PairSolution solution;
  const int n = problem.n();
  if (n == 0) {
    return solution;
  }
  const Eigen::MatrixXd P = problem.F.transpose() * problem.F;
  const Eigen::VectorXd c = problem.F.transpose() * problem.g;

  const bool two_segments = problem.cores[0]->is_segment && problem.cores[1]->is_segment;
  if (two_segments && method == Method::kDefault) {
    const qp::BoxQpResult box = qp::solve_box_qp(P, c);
    solution.x = box.x;
    // The box solver orders its multipliers [x1 <= 1, x2 <= 1, -x1 <= 0, -x2 <= 0]; the pair's
    // G = blkdiag([1; -1], [1; -1]) orders them [x1 <= 1, -x1 <= 0, x2 <= 1, -x2 <= 0].
    solution.lambda.resize(4);
    solution.lambda << box.lambda(0), box.lambda(2), box.lambda(1), box.lambda(3);
    return solution;
  }

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
  solution.iterations = result.iterations;
  return solution;
}

}  // namespace diffpills::detail
