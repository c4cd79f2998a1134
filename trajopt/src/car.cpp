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

}  // namespace diffpills::trajopt
