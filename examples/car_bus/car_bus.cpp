#include "car_bus.hpp"

#include <cmath>

namespace diffpills::examples {

Pose car_pose(const Eigen::Ref<const Eigen::VectorXd>& x) {
  return Pose(Eigen::Vector3d(x(0), x(1), 0.0),
              Eigen::Vector4d(std::cos(0.5 * x(2)), 0.0, 0.0, std::sin(0.5 * x(2))));
}

namespace {

// d/dx of a measure with pose gradient g (the car's 7 entries first): [dg/dr_x, dg/dr_y,
// dg/dq . dq/dtheta, 0, 0] with dq/dtheta = [-sin(theta/2), 0, 0, cos(theta/2)] / 2.
trajopt::Car::State state_gradient(const Eigen::Matrix<double, 14, 1>& g,
                                   const Eigen::Ref<const Eigen::VectorXd>& x) {
  const Eigen::Vector4d dq_dtheta(-0.5 * std::sin(0.5 * x(2)), 0.0, 0.0,
                                  0.5 * std::cos(0.5 * x(2)));
  trajopt::Car::State gradient = trajopt::Car::State::Zero();
  gradient(0) = g(0);
  gradient(1) = g(1);
  gradient(2) = g.segment<4>(3).dot(dq_dtheta);
  return gradient;
}

// The scenario's measure (phi when `phi` is set, else its clearance) with its state gradient when
// asked for: the problem's rows and the public helpers below.
double measure(const CarBusScenario& scenario, bool phi, const Eigen::Ref<const Eigen::VectorXd>& x,
               trajopt::Car::State* gradient) {
  if (phi || scenario.clearance == Clearance::kProximity) {
    const Proximity p = proximity(scenario.car, car_pose(x), scenario.bus, scenario.bus_pose);
    if (gradient != nullptr) *gradient = state_gradient(p.gradient, x);
    return p.phi;
  }
  const SignedDistance s =
      signed_distance(scenario.car, car_pose(x), scenario.bus, scenario.bus_pose);
  if (gradient != nullptr) *gradient = state_gradient(s.gradient, x);
  return s.distance;
}

double measure(const CarBusScenario& scenario, bool phi, const Eigen::Ref<const Eigen::VectorXd>& x,
               Eigen::VectorXd* gradient) {
  if (gradient == nullptr) {
    return measure(scenario, phi, x, static_cast<trajopt::Car::State*>(nullptr));
  }
  trajopt::Car::State fixed;
  const double value = measure(scenario, phi, x, &fixed);
  *gradient = fixed;
  return value;
}

// The chain rule once more: with J = d pose / dx as above (rows r_x, r_y and q's four) and
// d2q/dtheta2 = -q / 4, the state Hessian of a measure with pose Hessian H and gradient g is
//   J' H J + (g_q . (-q / 4)) e_theta e_theta'.
Eigen::Matrix<double, 5, 5> state_hessian(const Eigen::Matrix<double, 14, 14>& H,
                                          const Eigen::Matrix<double, 14, 1>& g,
                                          const Eigen::Ref<const Eigen::VectorXd>& x) {
  const Eigen::Vector4d q(std::cos(0.5 * x(2)), 0.0, 0.0, std::sin(0.5 * x(2)));
  Eigen::Matrix<double, 7, 5> J = Eigen::Matrix<double, 7, 5>::Zero();
  J(0, 0) = 1.0;
  J(1, 1) = 1.0;
  J.block<4, 1>(3, 2) = Eigen::Vector4d(-0.5 * q(3), 0.0, 0.0, 0.5 * q(0));  // dq/dtheta
  Eigen::Matrix<double, 5, 5> out = J.transpose() * H.topLeftCorner<7, 7>() * J;
  out(2, 2) -= 0.25 * g.segment<4>(3).dot(q);
  return out;
}

}  // namespace

Eigen::Matrix<double, 5, 5> car_bus_phi_hessian(const CarBusScenario& scenario,
                                                const Eigen::Ref<const Eigen::VectorXd>& x) {
  const ProximityWithHessian p =
      proximity_with_hessian(scenario.car, car_pose(x), scenario.bus, scenario.bus_pose);
  return state_hessian(p.hessian, p.gradient, x);
}

Eigen::Matrix<double, 5, 5> car_bus_clearance_hessian(const CarBusScenario& scenario,
                                                      const Eigen::Ref<const Eigen::VectorXd>& x) {
  if (scenario.clearance == Clearance::kProximity) return car_bus_phi_hessian(scenario, x);
  const SignedDistanceHessian s =
      signed_distance_hessian(scenario.car, car_pose(x), scenario.bus, scenario.bus_pose);
  return state_hessian(s.hessian, s.gradient, x);
}

double car_bus_phi(const CarBusScenario& scenario, const Eigen::Ref<const Eigen::VectorXd>& x,
                   Eigen::VectorXd* gradient) {
  return measure(scenario, true, x, gradient);
}

double car_bus_clearance(const CarBusScenario& scenario, const Eigen::Ref<const Eigen::VectorXd>& x,
                         Eigen::VectorXd* gradient) {
  return measure(scenario, false, x, gradient);
}

CarBusProblem::CarBusProblem(CarBusScenario scenario) : scenario_(std::move(scenario)) {
  trajopt::require_size(scenario_.goal, 5, "scenario.goal");
  goal_ = scenario_.goal;
  Q_ = 0.01 * StateMatrix::Identity();
  R_ = 0.1 * Eigen::Matrix2d::Identity();
  Qf_ = State(0.0, 0.0, 0.0, 10.0, 10.0).asDiagonal();
}

void CarBusProblem::dynamics(const State& x, const Control& u, State& next, StateMatrix& A,
                             ControlMatrix& B) const {
  scenario_.car_model.step(scenario_.dt, x, u, next, A, B);
}

Eigen::MatrixXd CarBusProblem::dynamics_hessian(const State& x, const Control& u,
                                                const State& lambda) const {
  return scenario_.car_model.step_hessian(scenario_.dt, x, u, lambda);
}

// Only the clearance row (after the last knot's three equalities) is nonlinear; at the last knot
// the Hessian is in x alone.
Eigen::MatrixXd CarBusProblem::constraint_hessian(int k, const State& x, const Control&,
                                                  const Eigen::VectorXd& mu) const {
  const bool last = k == scenario_.knots - 1;
  trajopt::require_size(mu, last ? 4 : 5, "mu");  // write_constraints' rows
  const int size = last ? 5 : 7;
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(size, size);
  H.topLeftCorner<5, 5>() = -mu(last ? 3 : 0) * car_bus_clearance_hessian(scenario_, x);
  return H;
}

CarBusProblem::Cost CarBusProblem::stage_cost(int, const State& x, const Control& u) const {
  const State e = x - goal_;
  return {0.5 * e.dot(Q_ * e) + 0.5 * u.dot(R_ * u), Q_ * e, R_ * u, Q_, R_,
          Eigen::Matrix<double, 2, 5>::Zero()};
}

CarBusProblem::Cost CarBusProblem::terminal_cost(const State& x) const {
  const State e = x - goal_;
  return {0.5 * e.dot(Qf_ * e),    Qf_ * e,
          Control::Zero(),         Qf_,
          Eigen::Matrix2d::Zero(), Eigen::Matrix<double, 2, 5>::Zero()};
}

double CarBusProblem::stage_cost_value(int, const State& x, const Control& u) const {
  const State e = x - goal_;
  return 0.5 * e.dot(Q_ * e) + 0.5 * u.dot(R_ * u);
}

double CarBusProblem::terminal_cost_value(const State& x) const {
  const State e = x - goal_;
  return 0.5 * e.dot(Qf_ * e);
}

CarBusProblem::Constraints CarBusProblem::constraints(int k, const State& x,
                                                      const Control& u) const {
  return rows_written_by<CarBusProblem>(*this, k, x, u, true);
}

CarBusProblem::Constraints CarBusProblem::constraint_values(int k, const State& x,
                                                            const Control& u) const {
  return rows_written_by<CarBusProblem>(*this, k, x, u, false);
}

// Rows: [equalities: px, py, theta - goal (last knot only)], -clearance, then u - limit,
// -u - limit. setZero(rows) reallocates only when the size changes; without derivatives dx and du
// are left as they are (not read).
void CarBusProblem::write_constraints(int k, const State& x, const Control& u, bool derivatives,
                                      Constraints& c) const {
  const bool last = k == scenario_.knots - 1;
  const int equalities = last ? 3 : 0;
  const int rows = equalities + 1 + (last ? 0 : 4);
  c.equalities = equalities;
  c.value.setZero(rows);
  if (derivatives) {
    c.dx.setZero(rows, 5);
    c.du.setZero(rows, 2);
  }
  if (last) {
    c.value.head<3>() = x.head<3>() - goal_.head<3>();
    if (derivatives) c.dx.topLeftCorner<3, 3>().setIdentity();
  }
  State gradient;
  c.value(equalities) = -measure(scenario_, false, x, derivatives ? &gradient : nullptr);
  if (derivatives) c.dx.row(equalities) = -gradient.transpose();
  if (!last) {
    for (int i = 0; i < 2; ++i) {
      c.value(equalities + 1 + i) = u(i) - scenario_.control_limit(i);
      c.value(equalities + 3 + i) = -u(i) - scenario_.control_limit(i);
      if (derivatives) {
        c.du(equalities + 1 + i, i) = 1.0;
        c.du(equalities + 3 + i, i) = -1.0;
      }
    }
  }
}

std::vector<Eigen::VectorXd> CarBusProblem::straight_line_controls() const {
  const int steps = scenario_.knots - 1;
  const double half = 0.5 * steps * scenario_.dt;
  const double acceleration = (scenario_.goal(0) - scenario_.x0(0)) / (half * half);
  std::vector<Eigen::VectorXd> controls(steps, Eigen::Vector2d::Zero());
  for (int k = 0; k < steps; ++k) controls[k](0) = k < steps / 2 ? acceleration : -acceleration;
  return controls;
}

}  // namespace diffpills::examples
