// The two-variable box QP of the paper's Appendix A:
//
//     minimize 1/2 x'Px + c'x   subject to  [I; -I] x <= [1; 0]   (0 <= x <= 1)
//
// with P symmetric positive semidefinite (2 x 2). The minimum lies at the unconstrained
// minimizer, on one of the four sides, or at one of the four corners; the solver evaluates those
// candidates and keeps the cheapest feasible one (Algorithm 1), then recovers the multipliers
// from the stationarity condition (Algorithm 2).
//
// Singular P (two parallel segments, or a segment of zero length) is handled on purpose. The
// paper's candidates divide by P's diagonal and its inverse; here a side's candidate minimizes the
// cost along that side in closed form (clamped to the side, and the side's midpoint where the
// cost is flat along it), and the interior candidate is used only when P is safely invertible:
// det P > 1e-12 P11 P22, a test relative to P's own scale (an absolute threshold, like
// DiffPills.jl's 1e-4, misfires at small and large scales). When P is singular the minimizer is
// generally a whole segment of the box; the solver returns its midpoint, found as the middle of
// the optimal candidates along P's null direction. That choice moves continuously with the data
// while P stays singular, and the returned cost is the minimum either way.
#pragma once

#include <Eigen/Core>

namespace diffpills::qp {

struct BoxQpResult {
  Eigen::Vector2d x;
  // Multipliers of x1 <= 1, x2 <= 1, -x1 <= 0, -x2 <= 0, in that order (the paper's G = [I; -I]).
  Eigen::Vector4d lambda;
};

// Throws std::invalid_argument for non-finite data.
BoxQpResult solve_box_qp(const Eigen::Matrix2d& P, const Eigen::Vector2d& c);

// Algorithm 2: lambda from y = -Px - c, on the bounds where x sits. The paper's threshold
// eps = 1e-12 is made relative to the size of P and c.
Eigen::Vector4d recover_box_duals(const Eigen::Vector2d& x, const Eigen::Matrix2d& P,
                                  const Eigen::Vector2d& c);

}  // namespace diffpills::qp
