// Classical Runge-Kutta 4 for x' = F(x, u) with u held over the step, with the exact Jacobians
// of the discrete map (the chain rule through the four stages, no finite differences):
//   k1 = F(x),  k2 = F(x + h/2 k1),  k3 = F(x + h/2 k2),  k4 = F(x + h k3)
//   next = x + h/6 (k1 + 2 k2 + 2 k3 + k4)
//   dk_i = Fx(x_i) dx_i + Fu(x_i) du,   dx_1 = dx, dx_2 = dx + h/2 dk1, dx_3 = dx + h/2 dk2,
//   dx_4 = dx + h dk3.
// A template over the sizes: with fixed N and M (the car: 5 and 2) every temporary lives on the
// stack, which made the car-bus solve ~40% faster than dynamic matrices; Eigen::Dynamic works too.
//
// Second derivatives (rk4_hessian, for the exact Hessian of a Lagrangian): the Hessian of
// L = lambda' next with respect to z = [x; u]. Differentiating twice along a direction dz, with
// zeta_i = (s_i, u) the stages' inputs (s_1 = x, s_{i+1} = x + o_i k_i):
//   d2L = sum_i w_i lambda' d2k_i,   d2k_i = F''(zeta_i)[dzeta_i, dzeta_i] + Fx(s_i) d2s_i,
//   d2s_1 = 0,  d2s_{i+1} = o_i d2k_i,
// since x, u and every sum of stages are linear in z. Unrolling the d2s terms from the last stage
// back collects them in adjoints of the stages,
//   a_4 = w_4 lambda,   a_i = w_i lambda + o_i Fx(s_{i+1})' a_{i+1}   (i = 3, 2, 1),
// so that d2L = sum_i a_i' F''(zeta_i)[dzeta_i, dzeta_i], i.e.
//   H = sum_i D_i' W_i D_i,   D_i = d zeta_i / dz = [S_i; 0 I],   W_i = Hessian of a_i' F at
//   zeta_i,
// with S_i = d s_i / dz the forward pass's stage Jacobians. The model supplies W_i.
#pragma once

#include <Eigen/Core>

namespace diffpills::trajopt {

// Fx times a stage's Jacobian (N x N or N x M), for any Fx.
struct DenseProduct {
  template <class Jacobian, class Stage>
  auto operator()(const Jacobian& Fx, const Stage& stage) const {
    return (Fx * stage).eval();
  }
};

// derivative(x, u, xdot, Fx, Fu) evaluates F and its Jacobians Fx (N x N), Fu (N x M).
// product(Fx, S) returns Fx S for the stages' Jacobians S: the three stages after the first cost
// an N x N x (N + M) product each, and a model whose Fx has known zeros can skip them (the
// quadrotor's is zero outside 58 of its 169 entries).
template <int N, int M, class Derivative, class Product = DenseProduct>
void rk4_step(const Derivative& derivative, double h, const Eigen::Matrix<double, N, 1>& x,
              const Eigen::Matrix<double, M, 1>& u, Eigen::Matrix<double, N, 1>& next,
              Eigen::Matrix<double, N, N>& A, Eigen::Matrix<double, N, M>& B,
              const Product& product = {}) {
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
    // The first stage is x itself (stage_x = I, stage_u = 0): its products are Fx and Fu exactly,
    // and skipping them saves a quarter of the n x n x n products (the quadrotor: n = 13).
    const StateMatrix kx = i == 0 ? Fx : StateMatrix(product(Fx, stage_x));
    const ControlMatrix ku = i == 0 ? Fu : ControlMatrix(product(Fx, stage_u) + Fu);
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

// weighted_hessian(s, u, a) returns the Hessian of a' F(s, u) with respect to [s; u] ((N + M) x
// (N + M)); the result is the Hessian of lambda' next with respect to [x; u]. Fixed sizes only.
template <int N, int M, class Derivative, class WeightedHessian>
Eigen::Matrix<double, N + M, N + M> rk4_hessian(const Derivative& derivative,
                                                const WeightedHessian& weighted_hessian, double h,
                                                const Eigen::Matrix<double, N, 1>& x,
                                                const Eigen::Matrix<double, M, 1>& u,
                                                const Eigen::Matrix<double, N, 1>& lambda) {
  static_assert(N > 0 && M > 0, "rk4_hessian needs fixed sizes");
  constexpr int P = N + M;
  using Vector = Eigen::Matrix<double, N, 1>;
  using StateMatrix = Eigen::Matrix<double, N, N>;
  using ControlMatrix = Eigen::Matrix<double, N, M>;
  using StageJacobian = Eigen::Matrix<double, N, P>;
  const double offsets[3] = {0.5 * h, 0.5 * h, h};
  const double weights[4] = {h / 6.0, h / 3.0, h / 3.0, h / 6.0};
  StageJacobian identity_x = StageJacobian::Zero();  // d x / dz
  identity_x.template leftCols<N>().setIdentity();
  // Forward: the stages, their Jacobians S_i and Fx(s_i).
  Vector stages[4];
  StageJacobian stage_jacobians[4];
  StateMatrix Fxs[4];
  stages[0] = x;
  stage_jacobians[0] = identity_x;
  for (int i = 0; i < 4; ++i) {
    Vector k;
    ControlMatrix Fu;
    derivative(stages[i], u, k, Fxs[i], Fu);
    if (i == 3) break;
    StageJacobian k_jacobian = Fxs[i] * stage_jacobians[i];
    k_jacobian.template rightCols<M>() += Fu;
    stages[i + 1] = x + offsets[i] * k;
    stage_jacobians[i + 1] = identity_x + offsets[i] * k_jacobian;
  }
  // Backward: the adjoints a_i, and the sum of D_i' W_i D_i.
  Eigen::Matrix<double, P, P> H = Eigen::Matrix<double, P, P>::Zero();
  Vector adjoint = weights[3] * lambda;
  for (int i = 3; i >= 0; --i) {
    if (i < 3) adjoint = weights[i] * lambda + offsets[i] * Fxs[i + 1].transpose() * adjoint;
    Eigen::Matrix<double, P, P> D = Eigen::Matrix<double, P, P>::Zero();
    D.template topRows<N>() = stage_jacobians[i];
    D.template bottomRightCorner<M, M>().setIdentity();
    H.noalias() += D.transpose() * weighted_hessian(stages[i], u, adjoint) * D;
  }
  return H;
}

}  // namespace diffpills::trajopt
