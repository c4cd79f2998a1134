// From the two sides of a solved pair to the public results: phi, points, normal, gradient
// (envelope theorem) and, on request, the Jacobians of the points (implicit function theorem).
// Every solver ends here, so all of them report the same quantities the same way.
#pragma once

#include "core_solution.hpp"
#include "diffpills/proximity.hpp"

namespace diffpills::detail {

Proximity make_proximity(const PosedCore& a, const CoreSolution& solution_a, const PosedCore& b,
                         const CoreSolution& solution_b);
ProximityJacobian make_proximity_jacobian(const PosedCore& a, const CoreSolution& solution_a,
                                          const PosedCore& b, const CoreSolution& solution_b);

}  // namespace diffpills::detail
