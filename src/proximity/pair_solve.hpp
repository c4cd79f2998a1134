// Solving the pair QP (pair_problem.hpp) with the general solvers: the reference path.
#pragma once

#include <Eigen/Core>
#include <array>

#include "diffpills/proximity.hpp"
#include "pair_problem.hpp"
#include "posed_core.hpp"

namespace diffpills::detail {

struct PairSolution {
  Eigen::VectorXd x;       // the core parameters [x1; x2]
  Eigen::VectorXd lambda;  // multipliers of G x <= h; positive exactly on the active rows
};

// The interior-point method with polish (qp/interior_point.hpp). A pair without parameters (two
// spheres) needs no solve. Throws SolverError if the method fails.
PairSolution solve_pair(const PairProblem& problem);

// The two sides of a solution in the form the result builder takes: each core's body point, and
// the body directions its active rows leave free (a segment: its axis unless a bound is active;
// a polygon: the face plane with no active row, the row's edge tangent with one, none with two,
// which with non-redundant rows means a vertex).
std::array<ClosestFeature, 2> core_solutions(const PairProblem& problem,
                                             const PairSolution& solution);

}  // namespace diffpills::detail
