// The Hessian of phi with respect to the poses, from the pieces the points' Jacobians already
// computed (point_motion.hpp): the second-order implicit function theorem on the active set.
//
// Near the solution phi + (R1 + R2)^2 = min over xi of f(x, xi) = |e|^2, e = p1 - p2, with
// p_i = r_i + Q(q_i) (u_i + D_i xi_i), x = [r1 q1 r2 q2] the poses and xi the free coordinates of
// the active features (none at vertices and segment ends). The minimizer xi(x) is stationary,
// f_xi = 0, so d phi/dx = f_x (the envelope theorem) and differentiating once more,
//
//   H = f_xx + f_x,xi dxi/dx,   dxi/dx = -f_xi,xi^+ f_xi,x       (the Schur complement of f_xi,xi)
//
// with, at xi = 0 and J = de/dx|_xi = [I, G1, -I, -G2], G_i = d(Q(q_i) u_i)/dq_i (3 x 4):
//
//   f_xx / 2 = J'J + blockdiag_q( hess_q1 [e . Q(q1) u1], -hess_q2 [e . Q(q2) u2] )
//   f_x,xi dxi/dx / 2 = coupling' free_motion                   (PointMotion's Z x 14 pieces)
//
// J'J has the blocks I, G_i, G_i'G_j with signs, and the rotation Hessians are
// UnitQuaternion::rotate_hessian. Where f_xi,xi is singular (non-unique closest points) the
// pseudo-inverse makes H the derivative of the reported gradient along the reported Jacobians,
// the documented one-sided choice. The computed H is symmetric up to the rounding of the reduced
// term; its lower triangle is mirrored, so the result is exactly symmetric.
//
// Units: computed in the query's frame (pair_frame.hpp), then brought back by the scale s:
// phi is s^2 times the frame's, positions are s times, quaternions unitless, so the r-r block is
// unchanged, r-q entries are multiplied by s and q-q entries by s twice (one product each, as s^2
// alone may underflow); the rotation Hessians get s^2 inside rotate_hessian, before its 1 / |q|^2.
#pragma once

#include <Eigen/Core>

#include "point_motion.hpp"
#include "posed_core.hpp"

namespace diffpills::detail {

// Sets H to phi's 14 x 14 Hessian in the inputs' units, for points that are apart (the cores do
// not intersect); `motion` is core_point_motion of the same sides. (Written in place: the result
// is a large part of what a Hessian query costs to move.)
void phi_hessian(double scale, const PosedCore& a, const ClosestFeature& side_a, const PosedCore& b,
                 const ClosestFeature& side_b, const PointMotion& motion,
                 Eigen::Matrix<double, 14, 14>& H);

}  // namespace diffpills::detail
