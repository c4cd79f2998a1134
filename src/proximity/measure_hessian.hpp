// The Hessian of a measure of two cores' witness points with respect to [r1 q1 r2 q2], from the
// points' Jacobians: the signed distance's (signed_distance.cpp), apart and in penetration. (phi's
// own Hessian takes a shorter route from the implicit function theorem's pieces: phi_hessian.hpp.)
//
// Measures of the witness points (phi, the distance) have, by the envelope theorem, the gradient
//
//   g(x) = J_f' w,   J_f = d(P_1 - P_2)/dx at fixed body points xi,   P_i = r_i + Q(q_i) xi_i,
//
// with w a vector of the points (phi: w = 2 (p1 - p2); the distance: w = -normal). With xi = xi(x)
// the optimal body points and dxi_i/dx = Q_i' (J_i - J_f,i) (from dp_i = J_f,i dx + Q_i dxi_i, J_i
// the points' total Jacobians, by the implicit function theorem), differentiating once more:
//
//   H = J_f' dw/dx                                          (w's motion)
//     + blockdiag_q( hess_q1 [w . Q(q1) xi_1], -hess_q2 [w . Q(q2) xi_2] )
//                                                           (w . P's second derivatives, xi fixed)
//     + rows q1: A_1' dxi_1/dx,  - rows q2: A_2' dxi_2/dx     (the q-gradient's motion with xi)
//
// with A_i = d(Q(q_i)' w)/dq_i (3 x 4), since w . Q(q) xi = (Q(q)' w) . xi; the second term uses
// UnitQuaternion::rotate_hessian. H is symmetric where the measure is twice differentiable; the
// computed one is symmetrized, (H + H') / 2, which removes rounding only.
#pragma once

#include <Eigen/Core>
#include <array>

#include "diffpills/shapes.hpp"

namespace diffpills::detail {

// points: the witness points on the cores (world); points_jacobian: their 6 x 14 Jacobian; w and
// dw: the vector above and its 3 x 14 Jacobian.
Eigen::Matrix<double, 14, 14> measure_hessian(const Pose& pose_a, const Pose& pose_b,
                                              const std::array<Eigen::Vector3d, 2>& points,
                                              const Eigen::Matrix<double, 6, 14>& points_jacobian,
                                              const Eigen::Vector3d& w,
                                              const Eigen::Matrix<double, 3, 14>& dw);

}  // namespace diffpills::detail
