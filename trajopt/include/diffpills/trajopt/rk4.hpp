// Classical Runge-Kutta 4 for x' = F(x, u) with u held over the step, with the exact Jacobians
// of the discrete map (the chain rule through the four stages, no finite differences):
//   k1 = F(x),  k2 = F(x + h/2 k1),  k3 = F(x + h/2 k2),  k4 = F(x + h k3)
//   next = x + h/6 (k1 + 2 k2 + 2 k3 + k4)
//   dk_i = Fx(x_i) dx_i + Fu(x_i) du,   dx_1 = dx, dx_2 = dx + h/2 dk1, dx_3 = dx + h/2 dk2,
//   dx_4 = dx + h dk3.
// A template over the sizes: with fixed N and M (the car: 5 and 2) every temporary lives on the
// stack, which made the car-bus solve ~40% faster than dynamic matrices; Eigen::Dynamic works too.
#pragma once

#include <Eigen/Core>

namespace diffpills::trajopt {

// derivative(x, u, xdot, Fx, Fu) evaluates F and its Jacobians Fx (N x N), Fu (N x M).
template <int N, int M, class Derivative>
void rk4_step(const Derivative& derivative, double h, const Eigen::Matrix<double, N, 1>& x,
              const Eigen::Matrix<double, M, 1>& u, Eigen::Matrix<double, N, 1>& next,
              Eigen::Matrix<double, N, N>& A, Eigen::Matrix<double, N, M>& B) {
  using Vector = Eigen::Matrix<double, N, 1>;
  using StateMatrix = Eigen::Matrix<double, N, N>;
  using ControlMatrix = Eigen::Matrix<double, N, M>;
  const auto n = x.size();
  const StateMatrix I = StateMatrix::Identity(n, n);
  const double offsets[3] = {0.5 * h, 0.5 * h, h};  // stage i + 1 starts at x + offsets[i] k_i
  const double weights[4] = {h / 6.0, h / 3.0, h / 3.0, h / 6.0};
  Vector stage = x;
  StateMatrix stage_x = I;                                   // d stage / dx
  ControlMatrix stage_u = ControlMatrix::Zero(n, u.size());  // d stage / du
  next = x;
  A = I;
  B = ControlMatrix::Zero(n, u.size());
  for (int i = 0; i < 4; ++i) {
    Vector k;
    StateMatrix Fx;
    ControlMatrix Fu;
    derivative(stage, u, k, Fx, Fu);
    const StateMatrix kx = Fx * stage_x;
    const ControlMatrix ku = Fx * stage_u + Fu;
    next += weights[i] * k;
    A += weights[i] * kx;
    B += weights[i] * ku;
    if (i < 3) {
      stage = x + offsets[i] * k;
      stage_x = I + offsets[i] * kx;
      stage_u = offsets[i] * ku;
    }
  }
}

}  // namespace diffpills::trajopt
