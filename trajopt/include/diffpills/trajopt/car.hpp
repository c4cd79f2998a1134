// The paper's car (section V) as a kinematic bicycle. State [px, py, theta, v, gamma], controls
// [u1, u2] (acceleration, steering-angle rate):
//   px' = v cos(theta),  py' = v sin(theta),  theta' = v tan(gamma) / l,  v' = u1,  gamma' = u2
// with wheelbase l. The paper lists only the other four equations; the heading equation is the
// standard kinematic bicycle's, the model its figure's car follows.
#pragma once

#include <Eigen/Core>

namespace diffpills::trajopt {

struct Car {
  using State = Eigen::Matrix<double, 5, 1>;
  using Control = Eigen::Matrix<double, 2, 1>;

  double wheelbase = 2.5;

  // x' = F(x, u) with Fx (5 x 5) and Fu (5 x 2).
  void derivative(const State& x, const Control& u, State& xdot, Eigen::Matrix<double, 5, 5>& Fx,
                  Eigen::Matrix<double, 5, 2>& Fu) const;

  // One RK4 step of length h with its exact Jacobians (rk4.hpp).
  void step(double h, const State& x, const Control& u, State& next, Eigen::Matrix<double, 5, 5>& A,
            Eigen::Matrix<double, 5, 2>& B) const;

  // The Hessian of a' F(x, u) with respect to [x; u] (7 x 7).
  Eigen::Matrix<double, 7, 7> weighted_hessian(const State& x, const Control& u,
                                               const State& a) const;
  // The Hessian of lambda' step(h, x, u) with respect to [x; u] (rk4.hpp's rk4_hessian).
  Eigen::Matrix<double, 7, 7> step_hessian(double h, const State& x, const Control& u,
                                           const State& lambda) const;
};

}  // namespace diffpills::trajopt
