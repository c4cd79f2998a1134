// Solving the pair QP (pair_problem.hpp) with the method the caller chose.
#pragma once

#include <Eigen/Core>

#include "diffpills/proximity.hpp"
#include "pair_problem.hpp"

namespace diffpills::detail {

struct PairSolution {
  Eigen::VectorXd x;  // the core parameters [x1; x2]
  Eigen::VectorXd
      lambda;          // multipliers of G x <= h (dimensionless, for the scaled cost 1/2|Fx+g|^2)
  int iterations = 0;  // interior-point iterations; 0 for closed-form solves
};

// Method::kDefault: two segments go to the Appendix A box solver (exact, closed form); every other
// pair, and Method::kInteriorPoint, to the interior-point method with polish. A pair without
// parameters (two spheres) needs no solve. Throws SolverError if the interior point method fails.
PairSolution solve_pair(const PairProblem& problem, Method method);

}  // namespace diffpills::detail
