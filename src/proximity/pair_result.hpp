// From a solved pair QP to the public results: phi, points, normal, gradient (envelope theorem)
// and, on request, the Jacobians of the points (implicit function theorem).
#pragma once

#include "diffpills/proximity.hpp"
#include "pair_problem.hpp"
#include "pair_solve.hpp"

namespace diffpills::detail {

Proximity make_proximity(const PairProblem& problem, const PairSolution& solution);
ProximityJacobian make_proximity_jacobian(const PairProblem& problem, const PairSolution& solution);

}  // namespace diffpills::detail
