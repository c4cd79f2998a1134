// Beyond the paper, in 3-D: a quadrotor whose body is a padded square flies through a window in a
// wall of padded polygons. The window is narrower than the quadrotor is wide, so it has to roll to
// pass, and the window is tilted, as in the aggressive-flight experiments this mimics; two capsule
// poles stand on the way, one before and one after the wall. Every knot carries
// phi(body, obstacle) >= 0 for each of the wall's four panels (polygon-polygon) and each pole
// (polygon-capsule), with gradients with respect to the body's quaternion, which is part of the
// state.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "clearance.hpp"
#include "diffpills/diffpills.hpp"
#include "diffpills/trajopt/altro.hpp"
#include "diffpills/trajopt/quadrotor.hpp"

namespace diffpills::examples {

struct PosedPolygon {
  PaddedPolygon shape;
  Pose pose;
};

struct PosedCapsule {
  Capsule shape;
  Pose pose;
};

struct QuadrotorWindowScenario {
  QuadrotorWindowScenario();
  // Rebuilds body, wall and poles from the fields above them (after changing a size).
  void build();

  Clearance clearance = Clearance::kProximity;  // the constraints' measure
  double dt = 0.06;
  int knots = 51;  // 3 s
  trajopt::Quadrotor model;
  double body_half_side = 0.2;  // the quadrotor's padded square in its body xy-plane
  double body_radius = 0.1;
  double wall_radius = 0.15;    // half the wall's thickness
  double wall_half_size = 1.5;  // the wall is a square of this half-size around the window
  Eigen::Vector3d window_centre{3.0, 0.0, 1.5};  // the wall is the plane x = 3 through it
  double window_width = 0.45;   // clear gap across the window, between the padded panels
  double window_height = 1.0;   // clear gap along the window
  double window_tilt = 0.5236;  // rad (30 deg) about the world x axis, from upright
  // Built by the constructor from the fields above.
  PaddedPolygon body;
  std::vector<PosedPolygon> wall;  // left, right, bottom, top panels
  std::vector<PosedCapsule> poles;
  Eigen::VectorXd x0, goal;  // hover states (13)
  double thrust_max = 4.0;   // per rotor, N; thrusts are >= 0
};

// The body's pose at state x (13 entries): r = x[0:3], q = x[3:7].
Pose quadrotor_pose(const Eigen::Ref<const Eigen::VectorXd>& x);

// The smallest phi over the obstacles at state x (whatever the scenario's clearance).
double quadrotor_min_phi(const QuadrotorWindowScenario& scenario, const Eigen::VectorXd& x);

// Costs 1/2 (x - goal)'Q(x - goal) + 1/2 (u - hover)'R(u - hover) per knot and
// 1/2 (x - goal)'Qf(x - goal) at the end; constraints -clearance <= 0 (phi or the signed
// distance) for every obstacle at every knot,
// 0 <= u <= thrust_max, and the final position equal to the goal's; with exact second derivatives
// (the costs are quadratic). Fixed sizes (problem.hpp): 13 states, 4 controls.
class QuadrotorWindowProblem : public trajopt::ProblemOf<13, 4> {
 public:
  explicit QuadrotorWindowProblem(QuadrotorWindowScenario scenario);

  int state_size() const override { return 13; }
  int control_size() const override { return 4; }
  int knots() const override { return scenario_.knots; }
  void dynamics(const State& x, const Control& u, State& next, StateMatrix& A,
                ControlMatrix& B) const override;
  Cost stage_cost(int k, const State& x, const Control& u) const override;
  Cost terminal_cost(const State& x) const override;
  Constraints constraints(int k, const State& x, const Control& u) const override;
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

  const QuadrotorWindowScenario& scenario() const { return scenario_; }
  int obstacle_count() const;
  // Hover thrust at every step: the quadrotor stays where it starts.
  std::vector<Eigen::VectorXd> hover_controls() const;

 private:
  QuadrotorWindowScenario scenario_;
  State goal_;  // scenario_.goal, checked to have 13 entries
  Control hover_;
  StateMatrix Q_, Qf_;
  Eigen::Matrix4d R_;
};

}  // namespace diffpills::examples
