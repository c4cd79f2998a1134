// The paper's section V scene: a car (capsule) drives from the left to a goal at the lower right
// past a parked bus (capsule) in between, with phi(car, bus) >= 0 at every knot.
#pragma once

#include <Eigen/Core>

#include "clearance.hpp"
#include "diffpills/diffpills.hpp"
#include "diffpills/trajopt/altro.hpp"
#include "diffpills/trajopt/car.hpp"

namespace diffpills::examples {

struct CarBusScenario {
  Clearance clearance = Clearance::kProximity;
  double dt = 0.1;
  int knots = 51;
  trajopt::Car car_model{2.5};
  Capsule car{2.0, 0.9};  // core length along the car's heading, radius
  Capsule bus{8.0, 1.3};
  Pose bus_pose{Eigen::Vector3d(10.0, -2.0, 0.0), Eigen::Vector4d(1.0, 0.0, 0.0, 0.0)};
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(5);
  Eigen::VectorXd goal = (Eigen::VectorXd(5) << 20.0, -4.0, 0.0, 0.0, 0.0).finished();
  Eigen::Vector2d control_limit{4.0, 1.0};  // |acceleration|, |steering rate|
};

// The car's pose at state x (5 entries): r = (px, py, 0), q = rotation by theta about z.
Pose car_pose(const Eigen::Ref<const Eigen::VectorXd>& x);

// phi(car at x, bus) and its gradient with respect to the state (through the pose).
double car_bus_phi(const CarBusScenario& scenario, const Eigen::Ref<const Eigen::VectorXd>& x,
                   Eigen::VectorXd* gradient = nullptr);
// The scenario's clearance measure (phi or the signed distance) and its state gradient.
double car_bus_clearance(const CarBusScenario& scenario, const Eigen::Ref<const Eigen::VectorXd>& x,
                         Eigen::VectorXd* gradient = nullptr);
// The Hessian with respect to the state (5 x 5, through the pose) of phi, or of the given measure.
Eigen::Matrix<double, 5, 5> car_bus_phi_hessian(const CarBusScenario& scenario,
                                                const Eigen::Ref<const Eigen::VectorXd>& x);
Eigen::Matrix<double, 5, 5> car_bus_clearance_hessian(const CarBusScenario& scenario,
                                                      const Eigen::Ref<const Eigen::VectorXd>& x);

// Costs 1/2 (x - goal)'Q(x - goal) + 1/2 u'Ru per knot and 1/2 (x - goal)'Qf(x - goal) at the
// end; constraints -clearance <= 0 at every knot (phi or the signed distance), |u| <= control_limit
// at every control, and the final position and heading equal to the goal's. With exact second
// derivatives of all of these (the costs are quadratic). Fixed sizes (problem.hpp): 5 states, 2
// controls.
class CarBusProblem : public trajopt::ProblemOf<5, 2> {
 public:
  explicit CarBusProblem(CarBusScenario scenario);

  int state_size() const override { return 5; }
  int control_size() const override { return 2; }
  int knots() const override { return scenario_.knots; }
  void dynamics(const State& x, const Control& u, State& next, StateMatrix& A,
                ControlMatrix& B) const override;
  Cost stage_cost(int k, const State& x, const Control& u) const override;
  Cost terminal_cost(const State& x) const override;
  Constraints constraints(int k, const State& x, const Control& u) const override;
  double stage_cost_value(int k, const State& x, const Control& u) const override;
  double terminal_cost_value(const State& x) const override;
  Constraints constraint_values(int k, const State& x, const Control& u) const override;
  // The rows written into out's own storage (problem.hpp), which ALTRO keeps per knot: no
  // allocation once each knot's rows exist.
  void write_constraints(int k, const State& x, const Control& u, bool derivatives,
                         Constraints& out) const override;
  bool has_second_derivatives() const override { return true; }
  Eigen::MatrixXd dynamics_hessian(const State& x, const Control& u,
                                   const State& lambda) const override;
  Eigen::MatrixXd constraint_hessian(int k, const State& x, const Control& u,
                                     const Eigen::VectorXd& mu) const override;

  const CarBusScenario& scenario() const { return scenario_; }
  // Straight ahead along the initial heading: accelerate for half the horizon, brake for the
  // other half, covering the distance to the goal's x. It drives through the bus.
  std::vector<Eigen::VectorXd> straight_line_controls() const;

 private:
  CarBusScenario scenario_;
  State goal_;  // scenario_.goal, checked to have 5 entries
  StateMatrix Q_, Qf_;
  Eigen::Matrix2d R_;
};

}  // namespace diffpills::examples
