#include "diffpills/trajopt/quadrotor.hpp"

#include <Eigen/Geometry>

#include "diffpills/trajopt/rk4.hpp"

namespace diffpills::trajopt {

namespace {

// [a]x b = a x b.
Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0.0, -a(2), a(1), a(2), 0.0, -a(0), -a(1), a(0), 0.0;
  return m;
}

// The rotor thrusts' effect on the body torque, tau = dtau_du u.
Eigen::Matrix<double, 3, 4> torque_matrix(double arm, double torque_per_thrust) {
  Eigen::Matrix<double, 3, 4> dtau_du;
  dtau_du << 0.0, arm, 0.0, -arm,  //
      -arm, 0.0, arm, 0.0,         //
      torque_per_thrust, -torque_per_thrust, torque_per_thrust, -torque_per_thrust;
  return dtau_du;
}

// d c / dq for c = R(q) e_z = [2(xz + sy), 2(yz - sx), 1 - 2x^2 - 2y^2], q = [s x y z].
Eigen::Matrix<double, 3, 4> body_z_jacobian(double s, double qx, double qy, double qz) {
  Eigen::Matrix<double, 3, 4> dbody_z_dq;
  dbody_z_dq << 2.0 * qy, 2.0 * qz, 2.0 * s, 2.0 * qx,  //
      -2.0 * qx, -2.0 * s, 2.0 * qz, 2.0 * qy,          //
      0.0, -4.0 * qx, -4.0 * qy, 0.0;
  return dbody_z_dq;
}

// Fx S for the state Jacobian Fx of Quadrotor::derivative, whose nonzeros lie in four row blocks
// (the derivation below it): position rows 0-2 are the identity on the velocity (columns 7-9);
// attitude rows 3-6 depend on q and w (columns 3-6, 10-12); velocity rows 7-9 on q (3-6); rate
// rows 10-12 on w (10-12). 833 multiplications per 13 x 17 stage Jacobian instead of 2,873.
struct SparseStateProduct {
  template <int Cols>
  Eigen::Matrix<double, 13, Cols> operator()(const Quadrotor::StateMatrix& Fx,
                                             const Eigen::Matrix<double, 13, Cols>& S) const {
    Eigen::Matrix<double, 13, Cols> product;
    product.template middleRows<3>(0) = S.template middleRows<3>(7);
    product.template middleRows<4>(3).noalias() =
        Fx.block<4, 4>(3, 3) * S.template middleRows<4>(3) +
        Fx.block<4, 3>(3, 10) * S.template middleRows<3>(10);
    product.template middleRows<3>(7).noalias() =
        Fx.block<3, 4>(7, 3) * S.template middleRows<4>(3);
    product.template middleRows<3>(10).noalias() =
        Fx.block<3, 3>(10, 10) * S.template middleRows<3>(10);
    return product;
  }
};

}  // namespace

// Jacobians, with q = [s, e] (scalar, vector part):
//   q' = 1/2 [-e.w; s w + e x w]      d/dq = 1/2 [0, -w'; w, -[w]x],  d/dw = 1/2 [-e'; s I + [e]x]
//   v' = c(q) T / m, c = R(q) e_z     d/dq = dc/dq T / m (the columns below),  d/du_i = c / m
//   w' = J^-1 (tau - w x J w)         d/dw = J^-1 ([J w]x - [w]x J),  d/du = J^-1 dtau/du
void Quadrotor::derivative(const State& x, const Control& u, State& xdot, StateMatrix& Fx,
                           ControlMatrix& Fu) const {
  const double s = x(3), qx = x(4), qy = x(5), qz = x(6);
  const Eigen::Vector3d e(qx, qy, qz);
  const Eigen::Vector3d v = x.segment<3>(7), w = x.segment<3>(10);
  const double thrust = u.sum();
  const Eigen::Vector3d body_z(2.0 * (qx * qz + s * qy), 2.0 * (qy * qz - s * qx),
                               1.0 - 2.0 * (qx * qx + qy * qy));
  const Eigen::Matrix3d J = inertia.asDiagonal();
  const Eigen::Vector3d J_inverse = inertia.cwiseInverse();
  const Eigen::Vector3d tau(arm * (u(1) - u(3)), arm * (u(2) - u(0)),
                            torque_per_thrust * (u(0) - u(1) + u(2) - u(3)));

  xdot.segment<3>(0) = v;
  xdot(3) = -0.5 * e.dot(w);
  xdot.segment<3>(4) = 0.5 * (s * w + e.cross(w));
  xdot.segment<3>(7) = body_z * (thrust / mass) - Eigen::Vector3d(0.0, 0.0, gravity);
  xdot.segment<3>(10) = J_inverse.cwiseProduct(tau - w.cross(J * w));

  Fx.setZero();
  Fx.block<3, 3>(0, 7).setIdentity();
  Fx.block<1, 3>(3, 4) = -0.5 * w.transpose();
  Fx.block<3, 1>(4, 3) = 0.5 * w;
  Fx.block<3, 3>(4, 4) = -0.5 * cross_matrix(w);
  Fx.block<1, 3>(3, 10) = -0.5 * e.transpose();
  Fx.block<3, 3>(4, 10) = 0.5 * (s * Eigen::Matrix3d::Identity() + cross_matrix(e));
  Fx.block<3, 4>(7, 3) = body_z_jacobian(s, qx, qy, qz) * (thrust / mass);
  Fx.block<3, 3>(10, 10) = J_inverse.asDiagonal() * (cross_matrix(J * w) - cross_matrix(w) * J);

  Fu.setZero();
  Fu.block<3, 4>(7, 0) = (body_z / mass).replicate<1, 4>();
  Fu.block<3, 4>(10, 0) = J_inverse.asDiagonal() * torque_matrix(arm, torque_per_thrust);
}

// Renormalization n(q) = q / |q| has Jacobian (I - n n') / |q|, applied to the rows of q in A, B.
void Quadrotor::step(double h, const State& x, const Control& u, State& next, StateMatrix& A,
                     ControlMatrix& B) const {
  rk4_step<13, 4>([this](const State& s, const Control& c, State& sdot, StateMatrix& Fx,
                         ControlMatrix& Fu) { derivative(s, c, sdot, Fx, Fu); },
                  h, x, u, next, A, B, SparseStateProduct{});
  const double norm = next.segment<4>(3).norm();
  const Eigen::Vector4d unit = next.segment<4>(3) / norm;
  const Eigen::Matrix4d projection = (Eigen::Matrix4d::Identity() - unit * unit.transpose()) / norm;
  next.segment<4>(3) = unit;
  A.middleRows<4>(3) = (projection * A.middleRows<4>(3)).eval();
  B.middleRows<4>(3) = (projection * B.middleRows<4>(3)).eval();
}

// a' F by parts, with a = [a_r, a_s, a_e, a_v, a_w] like the state and b = J^-1 a_w:
//   a_s (-1/2 e.w) + a_e' 1/2 (s w + e x w)   bilinear in (q, w): d2/ds dw = 1/2 a_e',
//       d2/de dw = -1/2 a_s I - 1/2 [a_e]x   (a_e . (e x w) = e' (w x a_e));
//   a_v' c(q) T / m, T = sum u                d2/dq2 = T / m times the constant Hessian of
//       a_v' c (below), d2/dq du_i = (dc/dq)' a_v / m for every rotor;
//   b' (tau(u) - w x J w)                     linear in u; b' (w1 x J w2) = w1' (-[b]x J) w2, so
//       d2/dw2 = [b]x J - J [b]x.
// a_v' c = 2 a0 (xz + sy) + 2 a1 (yz - sx) + a2 (1 - 2 x^2 - 2 y^2) has second derivatives
// (s, y): 2 a0, (s, x): -2 a1, (x, z): 2 a0, (y, z): 2 a1, (x, x) = (y, y): -4 a2.
Quadrotor::Hessian Quadrotor::weighted_hessian(const State& x, const Control& u,
                                               const State& a) const {
  const double s = x(3), qx = x(4), qy = x(5), qz = x(6);
  const Eigen::Vector3d a_e = a.segment<3>(4), a_v = a.segment<3>(7);
  const Eigen::Vector3d b = inertia.cwiseInverse().cwiseProduct(a.segment<3>(10));
  Hessian H = Hessian::Zero();
  // Attitude kinematics: q with w.
  H.block<1, 3>(3, 10) = 0.5 * a_e.transpose();
  H.block<3, 3>(4, 10) = -0.5 * a(3) * Eigen::Matrix3d::Identity() - 0.5 * cross_matrix(a_e);
  // Thrust along the body z axis: q with q and with u.
  Eigen::Matrix4d body_z_hessian = Eigen::Matrix4d::Zero();
  body_z_hessian(0, 2) = body_z_hessian(2, 0) = 2.0 * a_v(0);
  body_z_hessian(0, 1) = body_z_hessian(1, 0) = -2.0 * a_v(1);
  body_z_hessian(1, 3) = body_z_hessian(3, 1) = 2.0 * a_v(0);
  body_z_hessian(2, 3) = body_z_hessian(3, 2) = 2.0 * a_v(1);
  body_z_hessian(1, 1) = body_z_hessian(2, 2) = -4.0 * a_v(2);
  H.block<4, 4>(3, 3) = body_z_hessian * (u.sum() / mass);
  H.block<4, 4>(3, 13) =
      (body_z_jacobian(s, qx, qy, qz).transpose() * a_v / mass).replicate<1, 4>();
  // Euler's equation: w with w.
  const Eigen::Matrix3d J = inertia.asDiagonal();
  H.block<3, 3>(10, 10) = cross_matrix(b) * J - J * cross_matrix(b);
  // The blocks above are the upper ones of symmetric pairs (q-w, q-u): mirror them.
  H.block<3, 1>(10, 3) = H.block<1, 3>(3, 10).transpose();
  H.block<3, 3>(10, 4) = H.block<3, 3>(4, 10).transpose();
  H.block<4, 4>(13, 3) = H.block<4, 4>(3, 13).transpose();
  return H;
}

// L = lambda' next, next = [RK4's x~ with q~ replaced by n(q~) = q~ / |q~|]. With
// P = (I - n n') / |q~| (dn/dq~, symmetric), the RK4 part sees the adjoint lambda~ = lambda with
// P lambda_q in place of lambda_q, and the normalization adds G' N G, G = d q~ / d[x; u] (RK4's
// rows of q) and N the Hessian of lambda_q' n(q~):
//   N = [3 (lambda_q . n) n n' - (lambda_q . n) I - lambda_q n' - n lambda_q'] / |q~|^2
// (from grad = lambda_q / rho - (lambda_q . q~) q~ / rho^3, rho = |q~|, differentiated once more).
Quadrotor::Hessian Quadrotor::step_hessian(double h, const State& x, const Control& u,
                                           const State& lambda) const {
  const auto model = [this](const State& s, const Control& c, State& sdot, StateMatrix& Fx,
                            ControlMatrix& Fu) { derivative(s, c, sdot, Fx, Fu); };
  State raw;
  StateMatrix A;
  ControlMatrix B;
  rk4_step<13, 4>(model, h, x, u, raw, A, B);
  const double norm = raw.segment<4>(3).norm();
  const Eigen::Vector4d n = raw.segment<4>(3) / norm;
  const Eigen::Vector4d lambda_q = lambda.segment<4>(3);
  State adjoint = lambda;
  adjoint.segment<4>(3) = (lambda_q - n * n.dot(lambda_q)) / norm;
  const double along = lambda_q.dot(n);
  const Eigen::Matrix4d N = (3.0 * along * n * n.transpose() - along * Eigen::Matrix4d::Identity() -
                             lambda_q * n.transpose() - n * lambda_q.transpose()) /
                            (norm * norm);
  Eigen::Matrix<double, 4, 17> G;
  G << A.middleRows<4>(3), B.middleRows<4>(3);
  return rk4_hessian<13, 4>(
             model,
             [this](const State& s, const Control& c, const State& a) {
               return weighted_hessian(s, c, a);
             },
             h, x, u, adjoint) +
         G.transpose() * N * G;
}

}  // namespace diffpills::trajopt
