// A 7-joint arm with the published Franka Emika Panda kinematics moves its hand from one
// compartment of a shelf into the next, past the divider between them (issue 11's demo).
//
// The arm. Modified DH parameters (Craig's convention, serial_chain.hpp) from Franka's datasheet:
//   a     = [0, 0, 0, 0.0825, -0.0825, 0, 0.088]
//   d     = [0.333, 0, 0.316, 0, 0.384, 0, 0]
//   alpha = [0, -pi/2, pi/2, pi/2, -pi/2, pi/2, pi/2],  flange d = 0.107,
// joint limits [lo, hi] per joint from the same datasheet. Its collision model is capsules posed
// in the frames (frame 0 = base, i = after joint i, 8 = flange): the base column, the shoulder, the
// upper arm, the elbow, the forearm and the wrist, each about as wide as the link; the hand is a
// padded rectangle 0.2 m wide in the flange's y-z plane. Frames next to each other in the chain
// are never checked against each other (their shapes overlap at the joints), nor frames 2 and 4 or
// 3 and 5, whose capsules overlap at the elbow in every configuration (both pairs at all of
// 20,000 random joint angles within the limits), nor 5 and 7, whose crude capsules overlap when the
// wrist is bent back (q6 > ~3.3, 20% of those angles) where the real links clear each other by the
// wrist's 0.088 m offset; every other pair is a self-collision the solver avoids.
//
// The shelf: six padded-polygon boards (padding 0.01 m): bottom and top boards at heights 0.55 and
// 0.87 m, from 0.40 to 0.80 m in front of the base and 0.45 m to either side, a back board and two
// sides, and a divider at y = 0 that splits it into a left and a right compartment.
//
// The task: the hand starts inside the left compartment, flat, pointing into the shelf along the
// arm's vertical plane (its flange at (0.52, 0.22, 0.75), joint 1 at atan(0.22 / 0.52)), and ends
// in the same place in the right compartment (joint 1 negated). The configuration was found by
// inverse kinematics in the arm's plane (joints 1, 3, 5 at zero, then joint 1 turned); interpolated
// straight in joint space, only joint 1 moves, and the hand sweeps through the divider. The solver
// starts from a guess through two more such configurations with the hand pulled back out of either
// compartment (flange 0.26 m from the base's axis). The problem: states x = joint
// angles (7), controls u = joint velocities, x+ = x + dt u; minimize 1/2 sum |u|^2 dt; at every
// knot the joint limits, |u_i| below the joint's velocity limit, and for every pair of checked
// shapes the signed distance >= clearance (a pair more than query_margin apart, not reported by the
// scene's query, counts as query_margin apart), at each knot and at substeps between knots (a thin
// board could otherwise be jumped over between two knots: with knots alone, the solver from the
// straight line "solved" the problem by passing the hand through the divider between knots 21 and
// 22); the last state equal to the goal.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "diffpills/diffpills.hpp"
#include "diffpills/trajopt/altro.hpp"
#include "diffpills/trajopt/serial_chain.hpp"

namespace diffpills::examples {

struct PandaArm {
  trajopt::SerialChain chain;
  Eigen::Matrix<double, 7, 2> joint_limits;     // [lo, hi] per joint, radians
  Eigen::Matrix<double, 7, 1> velocity_limits;  // rad/s
  // links[f]: the shapes of frame f (0 .. 8), posed in it.
  std::vector<std::vector<BodyShape>> links;
  std::vector<std::pair<int, int>> excluded_link_pairs;  // frames, f < g
};

PandaArm panda_arm();

struct ArmShelfScenario {
  PandaArm arm = panda_arm();
  std::vector<Body> shelf;  // bodies at the identity pose: shapes posed in the world
  Eigen::Matrix<double, 7, 1> start, goal;
  // The hand pulled out in front of each compartment (IK too): the initial guess runs through them.
  Eigen::Matrix<double, 7, 1> retract_left, retract_right;
  int knots = 41;
  double dt = 0.1;
  double clearance = 0.01;    // signed distance kept at every knot, meters
  double query_margin = 0.1;  // pairs farther apart than this are not evaluated
  // Collision rows are evaluated at this many points of each step, x + (s / substeps) dt u for
  // s = 0 .. substeps - 1: a thin board could otherwise be passed between two knots.
  int substeps = 4;
  ArmShelfScenario();
};

// The scene of the links (bodies "link0" .. "link8", frame f's shapes) and the shelf's boards
// (category 2, not checked against each other), with the excluded link pairs.
Scene arm_shelf_scene(const ArmShelfScenario& scenario);

// The body poses of the scene at joint angles q: the link frames', then the identity for the
// shelf; with `frames` set, the chain's frames (with their Jacobians) are returned there.
std::vector<Pose> arm_shelf_poses(const ArmShelfScenario& scenario, const Eigen::VectorXd& q,
                                  trajopt::ChainFrames* frames = nullptr);

class ArmShelfProblem : public trajopt::ProblemOf<7, 7> {
 public:
  explicit ArmShelfProblem(ArmShelfScenario scenario);

  int state_size() const override { return 7; }
  int control_size() const override { return 7; }
  int knots() const override { return scenario_.knots; }
  void dynamics(const State& x, const Control& u, State& next, StateMatrix& A,
                ControlMatrix& B) const override;
  Cost stage_cost(int k, const State& x, const Control& u) const override;
  Cost terminal_cost(const State& x) const override;
  // Rows: at the last knot the goal (7 equalities) first; then the joint limits (14), the
  // velocity limits (14, not at the last knot) and, for each substep (one at the last knot), one
  // row per checked shape pair, clearance - min(signed distance, query_margin) <= 0.
  Constraints constraints(int k, const State& x, const Control& u) const override;
  Constraints constraint_values(int k, const State& x, const Control& u) const override;
  // Both, written into out's storage (problem.hpp): what the solver calls.
  void write_constraints(int k, const State& x, const Control& u, bool derivatives,
                         Constraints& out) const override;
  // Exact second derivatives: the dynamics are linear and the cost quadratic; each collision row's
  // Hessian chains signed_distance_hessian through the shapes' poses and the arm's forward
  // kinematics (serial_chain.hpp's attached_pose_derivatives).
  bool has_second_derivatives() const override { return true; }
  Eigen::MatrixXd dynamics_hessian(const State& x, const Control& u,
                                   const State& lambda) const override;
  Eigen::MatrixXd constraint_hessian(int k, const State& x, const Control& u,
                                     const Eigen::VectorXd& mu) const override;

  const ArmShelfScenario& scenario() const { return scenario_; }
  const Scene& scene() const { return scene_; }
  // The checked shape pairs, one per collision row: scene body and shape indices.
  const std::vector<std::array<int, 4>>& pairs() const { return pairs_; }
  // ALTRO's settings for this problem: Altro.jl's defaults but the first penalty, 100 instead of
  // 1. With a penalty of 1 the first inner solves trade the constraints for a shorter path, pull
  // the guess into the shelf, and the solver stalls there with the hand half through a board
  // (measured: capped at 1,000 iterations, 0.05 m of violation, with 2 and 4 substeps).
  static trajopt::AltroSettings settings();
  // The joint-space straight line from start to goal at constant velocity (it collides).
  std::vector<Eigen::VectorXd> straight_line_controls() const;
  // The initial guess: straight lines in joint space from the start to retract_left (a quarter of
  // the steps), to retract_right (half) and to the goal (a quarter): the hand backs out of the left
  // compartment, passes in front of the divider and goes into the right one. Its segments still
  // graze the shelf; the solver makes them clear it.
  std::vector<Eigen::VectorXd> retreat_controls() const;

 private:
  // The Hessian of a contact's signed distance with respect to the joint angles (7 x 7).
  Eigen::MatrixXd contact_hessian(const Contact& contact, const trajopt::ChainFrames& frames) const;
  // A collision row's value, clearance - min(distance, margin); far_row() is that of a pair the
  // margin or more apart. Rows are differentiated (once and twice) only where they are not
  // far_row(): a contact within an ulp of the margin rounds to it and counts as beyond.
  double collision_row(double distance) const;
  double far_row() const { return collision_row(scenario_.query_margin); }
  // A contact's collision row among the pairs, or -1 for two bodies that never move: row_of_
  // holds it at pair_key(bodies, shapes) (bodies i < j, as the scene reports them), a flat table
  // (a std::map lookup per contact cost ~1.5% of the arm's solve).
  int row_of(const Contact& contact) const;
  int pair_key(int body_i, int body_j, int shape_a, int shape_b) const;

  ArmShelfScenario scenario_;
  Scene scene_;
  std::vector<std::array<int, 4>> pairs_;
  int most_shapes_ = 0;  // the most shapes a body has
  std::vector<int> row_of_;
};

// The smallest signed distance over the checked pairs at joint angles q (every pair, not only
// those within the query margin).
double arm_shelf_min_distance(const ArmShelfProblem& problem, const Eigen::VectorXd& q);

// The smallest signed distance along the path through `states`, straight in joint space between
// knots, sampled `samples` times per step (and at the last knot).
double arm_shelf_path_min_distance(const ArmShelfProblem& problem,
                                   const std::vector<Eigen::VectorXd>& states, int samples);

}  // namespace diffpills::examples
