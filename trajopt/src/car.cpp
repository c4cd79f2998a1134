#include "diffpills/trajopt/car.hpp"

#include <cmath>

#include "diffpills/trajopt/rk4.hpp"

namespace diffpills::trajopt {

// Jacobians of F: d/dtheta (v cos, v sin) = (-v sin, v cos); d/dv gives (cos, sin, tan(gamma)/l);
// d/dgamma of v tan(gamma)/l is v / (l cos^2 gamma).
void Car::derivative(const State& x, const Control& u, State& xdot, Eigen::Matrix<double, 5, 5>& Fx,
                     Eigen::Matrix<double, 5, 2>& Fu) const {
  const double theta = x(2), v = x(3), gamma = x(4);
  const double c = std::cos(theta), s = std::sin(theta), t = std::tan(gamma);
  const double cos_gamma = std::cos(gamma);
  xdot << v * c, v * s, v * t / wheelbase, u(0), u(1);
  Fx.setZero();
  Fx(0, 2) = -v * s;
  Fx(0, 3) = c;
  Fx(1, 2) = v * c;
  Fx(1, 3) = s;
  Fx(2, 3) = t / wheelbase;
  Fx(2, 4) = v / (wheelbase * cos_gamma * cos_gamma);
  Fu.setZero();
  Fu(3, 0) = 1.0;
  Fu(4, 1) = 1.0;
}

void Car::step(double h, const State& x, const Control& u, State& next,
               Eigen::Matrix<double, 5, 5>& A, Eigen::Matrix<double, 5, 2>& B) const {
  rk4_step<5, 2>(
      [this](const State& s, const Control& c, State& sdot, Eigen::Matrix<double, 5, 5>& Fx,
             Eigen::Matrix<double, 5, 2>& Fu) { derivative(s, c, sdot, Fx, Fu); },
      h, x, u, next, A, B);
}

// a' F = a0 v cos(theta) + a1 v sin(theta) + a2 v tan(gamma) / l + a3 u1 + a4 u2, whose only
// nonzero second derivatives are in (theta, v, gamma):
//   d2/dtheta2   = -v (a0 cos(theta) + a1 sin(theta))
//   d2/dtheta dv = -a0 sin(theta) + a1 cos(theta)
//   d2/dv dgamma = a2 / (l cos^2 gamma)
//   d2/dgamma2   = 2 a2 v tan(gamma) / (l cos^2 gamma)      (d/dgamma sec^2 = 2 sec^2 tan).
Eigen::Matrix<double, 7, 7> Car::weighted_hessian(const State& x, const Control&,
                                                  const State& a) const {
  const double theta = x(2), v = x(3), gamma = x(4);
  const double c = std::cos(theta), s = std::sin(theta), cos_gamma = std::cos(gamma);
  const double secant_squared = 1.0 / (cos_gamma * cos_gamma);
  Eigen::Matrix<double, 7, 7> H = Eigen::Matrix<double, 7, 7>::Zero();
  H(2, 2) = -v * (a(0) * c + a(1) * s);
  H(2, 3) = H(3, 2) = -a(0) * s + a(1) * c;
  H(3, 4) = H(4, 3) = a(2) * secant_squared / wheelbase;
  H(4, 4) = 2.0 * a(2) * v * std::tan(gamma) * secant_squared / wheelbase;
  return H;
}

Eigen::Matrix<double, 7, 7> Car::step_hessian(double h, const State& x, const Control& u,
                                              const State& lambda) const {
  return rk4_hessian<5, 2>(
      [this](const State& s, const Control& c, State& sdot, Eigen::Matrix<double, 5, 5>& Fx,
             Eigen::Matrix<double, 5, 2>& Fu) { derivative(s, c, sdot, Fx, Fu); },
      [this](const State& s, const Control& c, const State& a) {
        return weighted_hessian(s, c, a);
      },
      h, x, u, lambda);
}

}  // namespace diffpills::trajopt
