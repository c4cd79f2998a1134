// A quadrotor as a rigid body with quaternion attitude. State (13) [r, q, v, w]: position r and
// velocity v in the world frame, attitude q = [w, x, y, z] (body to world), angular velocity w in
// the body frame. Controls (4): rotor thrusts u_i >= 0 along the body z axis, rotors in a plus
// configuration at arm length l on the body +x, +y, -x, -y axes, spinning alternately, so that
//   r' = v
//   q' = 1/2 q (x) [0, w]                                (quaternion product)
//   v' = -g e_z + R(q) e_z (u1 + u2 + u3 + u4) / m
//   w' = J^-1 (tau - w x J w),  tau = [l (u2 - u4), l (u3 - u1), k_m (u1 - u2 + u3 - u4)]
// with R(q) e_z written as the unit-quaternion polynomial [2(xz + wy), 2(yz - wx), 1 - 2x^2 -
// 2y^2]. One step is RK4 (rk4.hpp) followed by renormalizing q, which RK4 does not preserve; the
// step's Jacobians include that projection, so q stays a unit quaternion along any rollout.
#pragma once

#include <Eigen/Core>

namespace diffpills::trajopt {

struct Quadrotor {
  using State = Eigen::Matrix<double, 13, 1>;
  using Control = Eigen::Matrix<double, 4, 1>;
  using StateMatrix = Eigen::Matrix<double, 13, 13>;
  using ControlMatrix = Eigen::Matrix<double, 13, 4>;

  double mass = 0.5;                               // kg
  Eigen::Vector3d inertia{0.0023, 0.0023, 0.004};  // diagonal of J, kg m^2
  double arm = 0.175;                              // m
  double torque_per_thrust = 0.0245;               // k_m, m
  double gravity = 9.81;                           // m/s^2

  // The thrust of each rotor that holds the body level in a hover: m g / 4.
  double hover_thrust() const { return 0.25 * mass * gravity; }

  // x' = F(x, u) with Fx (13 x 13) and Fu (13 x 4).
  void derivative(const State& x, const Control& u, State& xdot, StateMatrix& Fx,
                  ControlMatrix& Fu) const;

  // One RK4 step of length h, then q <- q / |q|, with the exact Jacobians of both.
  void step(double h, const State& x, const Control& u, State& next, StateMatrix& A,
            ControlMatrix& B) const;

  using Hessian = Eigen::Matrix<double, 17, 17>;
  // The Hessian of a' F(x, u) with respect to [x; u].
  Hessian weighted_hessian(const State& x, const Control& u, const State& a) const;
  // The Hessian of lambda' step(h, x, u) with respect to [x; u], the renormalization included.
  Hessian step_hessian(double h, const State& x, const Control& u, const State& lambda) const;
};

}  // namespace diffpills::trajopt
