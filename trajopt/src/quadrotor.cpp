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
  Eigen::Matrix<double, 3, 4> dbody_z_dq;
  dbody_z_dq << 2.0 * qy, 2.0 * qz, 2.0 * s, 2.0 * qx,  //
      -2.0 * qx, -2.0 * s, 2.0 * qz, 2.0 * qy,          //
      0.0, -4.0 * qx, -4.0 * qy, 0.0;
  Fx.block<3, 4>(7, 3) = dbody_z_dq * (thrust / mass);
  Fx.block<3, 3>(10, 10) = J_inverse.asDiagonal() * (cross_matrix(J * w) - cross_matrix(w) * J);

  Eigen::Matrix<double, 3, 4> dtau_du;
  dtau_du << 0.0, arm, 0.0, -arm,  //
      -arm, 0.0, arm, 0.0,         //
      torque_per_thrust, -torque_per_thrust, torque_per_thrust, -torque_per_thrust;
  Fu.setZero();
  Fu.block<3, 4>(7, 0) = (body_z / mass).replicate<1, 4>();
  Fu.block<3, 4>(10, 0) = J_inverse.asDiagonal() * dtau_du;
}

// Renormalization n(q) = q / |q| has Jacobian (I - n n') / |q|, applied to the rows of q in A, B.
void Quadrotor::step(double h, const State& x, const Control& u, State& next, StateMatrix& A,
                     ControlMatrix& B) const {
  rk4_step<13, 4>([this](const State& s, const Control& c, State& sdot, StateMatrix& Fx,
                         ControlMatrix& Fu) { derivative(s, c, sdot, Fx, Fu); },
                  h, x, u, next, A, B);
  const double norm = next.segment<4>(3).norm();
  const Eigen::Vector4d unit = next.segment<4>(3) / norm;
  const Eigen::Matrix4d projection = (Eigen::Matrix4d::Identity() - unit * unit.transpose()) / norm;
  next.segment<4>(3) = unit;
  A.middleRows<4>(3) = (projection * A.middleRows<4>(3)).eval();
  B.middleRows<4>(3) = (projection * B.middleRows<4>(3)).eval();
}

}  // namespace diffpills::trajopt
