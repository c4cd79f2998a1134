#include "arm_shelf.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace diffpills::examples {
namespace {

// Local attitudes: a capsule's axis (body x) along its frame's z, or its y; a polygon's plane
// (body x-y) on its frame's y-z plane (x to y, y to z), or a board's on the world's x-z plane.
// (Functions, not globals: a static initializer elsewhere may build a scenario first.)
Eigen::Vector4d identity() { return {1, 0, 0, 0}; }
Eigen::Vector4d x_to_z() { return {std::sqrt(0.5), 0, -std::sqrt(0.5), 0}; }  // -90 deg about y
Eigen::Vector4d x_to_y() { return {std::sqrt(0.5), 0, 0, std::sqrt(0.5)}; }   // 90 deg about z
Eigen::Vector4d xy_to_yz() { return {0.5, 0.5, 0.5, 0.5}; }  // x to y, y to z, z to x
Eigen::Vector4d xy_to_xz() { return {std::sqrt(0.5), std::sqrt(0.5), 0, 0}; }  // 90 deg about x

BodyShape capsule(double length, double radius, const Eigen::Vector3d& centre,
                  const Eigen::Vector4d& attitude) {
  return {Capsule(length, radius), Pose(centre, attitude)};
}

// A rectangle of half-sides (hx, hy) in its body x-y plane, padded by `radius`.
PaddedPolygon rectangle(double hx, double hy, double radius) {
  Eigen::MatrixX2d C(4, 2);
  C << 1, 0, 0, 1, -1, 0, 0, -1;
  return PaddedPolygon(C, Eigen::Vector4d(hx, hy, hx, hy), radius);
}

Body board(const std::string& name, const Eigen::Vector3d& centre, double h1, double h2,
           const Eigen::Vector4d& attitude) {
  return Body(name, {{rectangle(h1, h2, 0.01), Pose(centre, attitude)}}, CollisionFilter{2, ~2u});
}

constexpr int kLinks = 9;  // frames 0 .. 8

// A knot's rows (ArmShelfProblem::constraints): the goal (last knot), the joint limits, the
// velocity limits (not at the last knot), then the collision rows.
int goal_rows(bool last) { return last ? 7 : 0; }
constexpr int kLimitRows = 14;
int velocity_rows(bool last) { return last ? 0 : 14; }
int collision_start(bool last) { return goal_rows(last) + kLimitRows + velocity_rows(last); }

}  // namespace

PandaArm panda_arm() {
  PandaArm arm;
  arm.chain.a = {0, 0, 0, 0.0825, -0.0825, 0, 0.088};
  arm.chain.d = {0.333, 0, 0.316, 0, 0.384, 0, 0};
  arm.chain.alpha = {0, -M_PI / 2, M_PI / 2, M_PI / 2, -M_PI / 2, M_PI / 2, M_PI / 2};
  arm.chain.flange_d = 0.107;
  arm.joint_limits << -2.8973, 2.8973, -1.7628, 1.7628, -2.8973, 2.8973, -3.0718, -0.0698, -2.8973,
      2.8973, -0.0175, 3.7525, -2.8973, 2.8973;
  arm.velocity_limits << 2.1750, 2.1750, 2.1750, 2.1750, 2.6100, 2.6100, 2.6100;
  arm.links = {
      {capsule(0.14, 0.10, {0, 0, 0.07}, x_to_z())},         // base column, up to 0.14 m
      {capsule(0.19, 0.08, {0, 0, -0.095}, x_to_z())},       // shoulder, from the column to joint 2
      {capsule(0.27, 0.08, {0, -0.135, 0}, x_to_y())},       // upper arm, along frame 2's -y
      {capsule(0.10, 0.07, {0, 0, -0.05}, x_to_z()),         // joint 3's housing
       capsule(0.0825, 0.07, {0.04125, 0, 0}, identity())},  // to the elbow
      {capsule(0.0825, 0.07, {-0.04125, 0, 0}, identity())},  // elbow
      {capsule(0.22, 0.06, {0, 0, -0.19}, x_to_z())},         // forearm, along frame 5's z
      {capsule(0.088, 0.06, {0.044, 0, 0}, identity())},      // wrist
      {capsule(0.107, 0.05, {0, 0, 0.0535}, x_to_z())},       // flange
      {{rectangle(0.1, 0.05, 0.02), Pose(Eigen::Vector3d(0, 0, 0.05), xy_to_yz())}},  // hand
  };
  for (int f = 0; f + 1 < kLinks; ++f) arm.excluded_link_pairs.emplace_back(f, f + 1);
  arm.excluded_link_pairs.emplace_back(2, 4);
  arm.excluded_link_pairs.emplace_back(3, 5);
  arm.excluded_link_pairs.emplace_back(5, 7);
  return arm;
}

ArmShelfScenario::ArmShelfScenario() {
  const double x = 0.60, half_x = 0.20, half_y = 0.45;
  const double bottom = 0.55, top = 0.87, middle = 0.5 * (bottom + top),
               half_z = 0.5 * (top - bottom);
  shelf = {board("bottom", {x, 0, bottom}, half_x, half_y, identity()),
           board("top", {x, 0, top}, half_x, half_y, identity()),
           board("divider", {x, 0, middle}, half_x, half_z, xy_to_xz()),
           board("left", {x, half_y, middle}, half_x, half_z, xy_to_xz()),
           board("right", {x, -half_y, middle}, half_x, half_z, xy_to_xz()),
           board("back", {x + half_x, 0, middle}, half_y, half_z, xy_to_yz())};
  // Joint 1 turned by +-atan(0.22 / 0.52) = +-0.40024: the arm's plane through the middle of
  // either compartment, the hand pointing along it.
  const double yaw = std::atan2(0.22, 0.52);
  start << yaw, -0.055128, 0, -1.814802, 0, 3.33047, 0;
  goal << -yaw, -0.055128, 0, -1.814802, 0, 3.33047, 0;
  retract_left << yaw, -1.028344, 0, -2.565911, 0, 3.108363, 0;
  retract_right << -yaw, -1.028344, 0, -2.565911, 0, 3.108363, 0;
}

Scene arm_shelf_scene(const ArmShelfScenario& scenario) {
  std::vector<Body> bodies;
  bodies.reserve(kLinks + scenario.shelf.size());
  for (int f = 0; f < kLinks; ++f) {
    bodies.emplace_back("link" + std::to_string(f),
                        scenario.arm.links[static_cast<std::size_t>(f)]);
  }
  for (const Body& board : scenario.shelf) bodies.push_back(board);
  std::vector<std::pair<std::string, std::string>> exclude;
  for (const auto& [f, g] : scenario.arm.excluded_link_pairs) {
    exclude.emplace_back("link" + std::to_string(f), "link" + std::to_string(g));
  }
  return Scene(std::move(bodies), exclude);
}

namespace {

// arm_shelf_poses written into frames and poses, reusing their storage.
void pose_arm(const ArmShelfScenario& scenario, const Eigen::Ref<const Eigen::VectorXd>& q,
              bool derivatives, trajopt::ChainFrames& frames, std::vector<Pose>& poses) {
  trajopt::forward_kinematics(scenario.arm.chain, q, derivatives, frames);
  poses.resize(kLinks + scenario.shelf.size());  // the boards stay at the identity
  for (std::size_t f = 0; f < static_cast<std::size_t>(kLinks); ++f) {
    poses[f] = Pose(frames.origin[f], frames.attitude[f]);
  }
}

}  // namespace

std::vector<Pose> arm_shelf_poses(const ArmShelfScenario& scenario, const Eigen::VectorXd& q,
                                  trajopt::ChainFrames* frames) {
  trajopt::ChainFrames chain;
  std::vector<Pose> poses;
  pose_arm(scenario, q, frames != nullptr, chain, poses);
  if (frames != nullptr) *frames = std::move(chain);
  return poses;
}

ArmShelfProblem::ArmShelfProblem(ArmShelfScenario scenario)
    : scenario_(std::move(scenario)), scene_(arm_shelf_scene(scenario_)) {
  // One row per pair of shapes of two checked bodies of which at least one moves (link1 ..
  // link8): the base and the boards never move relative to each other.
  const auto moves = [](int body) { return body >= 1 && body < kLinks; };
  for (int i = 0; i < scene_.size(); ++i) {
    most_shapes_ = std::max(most_shapes_, static_cast<int>(scene_.body(i).shapes().size()));
  }
  row_of_.assign(static_cast<std::size_t>(pair_key(scene_.size(), 0, 0, 0)), -1);
  for (int i = 0; i < scene_.size(); ++i) {
    for (int j = i + 1; j < scene_.size(); ++j) {
      if (!scene_.checked(i, j) || (!moves(i) && !moves(j))) continue;
      for (int a = 0; a < static_cast<int>(scene_.body(i).shapes().size()); ++a) {
        for (int b = 0; b < static_cast<int>(scene_.body(j).shapes().size()); ++b) {
          row_of_[static_cast<std::size_t>(pair_key(i, j, a, b))] = static_cast<int>(pairs_.size());
          pairs_.push_back({i, j, a, b});
        }
      }
    }
  }
}

double ArmShelfProblem::collision_row(double distance) const {
  return scenario_.clearance - std::min(distance, scenario_.query_margin);
}

int ArmShelfProblem::pair_key(int body_i, int body_j, int shape_a, int shape_b) const {
  return ((body_i * scene_.size() + body_j) * most_shapes_ + shape_a) * most_shapes_ + shape_b;
}

int ArmShelfProblem::row_of(const Contact& contact) const {
  return row_of_[static_cast<std::size_t>(
      pair_key(contact.bodies[0], contact.bodies[1], contact.shapes[0], contact.shapes[1]))];
}

void ArmShelfProblem::dynamics(const State& x, const Control& u, State& next, StateMatrix& A,
                               ControlMatrix& B) const {
  next = x + scenario_.dt * u;
  A.setIdentity();
  B = scenario_.dt * ControlMatrix::Identity();
}

ArmShelfProblem::Cost ArmShelfProblem::stage_cost(int, const State&, const Control& u) const {
  Cost cost;
  cost.value = 0.5 * scenario_.dt * u.squaredNorm();
  cost.x.setZero();
  cost.u = scenario_.dt * u;
  cost.xx.setZero();
  cost.uu = scenario_.dt * Eigen::Matrix<double, 7, 7>::Identity();
  cost.ux.setZero();
  return cost;
}

ArmShelfProblem::Cost ArmShelfProblem::terminal_cost(const State&) const {
  Cost cost;
  cost.x.setZero();
  cost.u.setZero();
  cost.xx.setZero();
  cost.uu.setZero();
  cost.ux.setZero();
  return cost;
}

ArmShelfProblem::Constraints ArmShelfProblem::constraints(int k, const State& x,
                                                          const Control& u) const {
  return rows_written_by<ArmShelfProblem>(*this, k, x, u, true);
}

ArmShelfProblem::Constraints ArmShelfProblem::constraint_values(int k, const State& x,
                                                                const Control& u) const {
  return rows_written_by<ArmShelfProblem>(*this, k, x, u, false);
}

void ArmShelfProblem::write_constraints(int k, const State& x, const Control& u, bool derivatives,
                                        Constraints& out) const {
  const bool last = k == knots() - 1;
  const int goals = goal_rows(last), first_collision = collision_start(last);
  const int rows =
      first_collision + (last ? 1 : scenario_.substeps) * static_cast<int>(pairs_.size());
  // A pair the margin or more apart (or not reported by the query) has the constant row `far`,
  // with zero derivatives.
  const double far = far_row();
  // Only a collision row whose value is not `far` has nonzero derivatives, and every result this
  // function writes keeps that. So where out holds one (of this shape), only those rows are
  // cleared, not all ~375 x 14 derivatives (that memset was 2-5% of the arm's solve); other
  // storage is cleared whole, or, for values only, emptied of derivatives that could break it.
  const bool ours = out.value.size() == rows && out.dx.rows() == rows && out.du.rows() == rows;
  if (ours) {
    for (Eigen::Index row = first_collision; row < rows; ++row) {
      if (out.value(row) == far) continue;
      out.dx.row(row).setZero();
      out.du.row(row).setZero();
    }
    if (derivatives) {
      out.dx.topRows(first_collision).setZero();
      out.du.topRows(first_collision).setZero();
    }
  } else {
    out.value.resize(rows);
    out.dx.setZero(derivatives ? rows : 0, 7);
    out.du.setZero(derivatives ? rows : 0, 7);
  }
  out.equalities = goals;
  const auto& limits = scenario_.arm.joint_limits;
  if (last) {
    out.value.head(7) = x - scenario_.goal;
    if (derivatives) out.dx.topRows(7).setIdentity();
  }
  out.value.segment(goals, 7) = x - limits.col(1);
  out.value.segment(goals + 7, 7) = limits.col(0) - x;
  if (derivatives) {
    out.dx.block(goals, 0, 7, 7).setIdentity();
    out.dx.block(goals + 7, 0, 7, 7) = -Eigen::MatrixXd::Identity(7, 7);
  }
  if (!last) {
    const int v = goals + kLimitRows;
    out.value.segment(v, 7) = u - scenario_.arm.velocity_limits;
    out.value.segment(v + 7, 7) = -scenario_.arm.velocity_limits - u;
    if (derivatives) {
      out.du.block(v, 0, 7, 7).setIdentity();
      out.du.block(v + 7, 0, 7, 7) = -Eigen::MatrixXd::Identity(7, 7);
    }
  }
  // Collision rows: clearance - min(distance, margin), at the knot and at the substeps between it
  // and the next knot, q = x + (s / S) dt u; `far` for the pairs the query does not report.
  const auto pair_count = static_cast<Eigen::Index>(pairs_.size());
  out.value.tail(rows - first_collision).setConstant(far);
  const int substeps = last ? 1 : scenario_.substeps;
  // The chain's frames and the scene's poses, kept from call to call by each thread (a solve makes
  // ~5,400 calls and ~21,000 poses, and posing the chain into fresh storage allocated ~20 vectors
  // and matrices each time: ~3% of the solve in malloc and free). Nothing is carried over between
  // calls but capacity: pose_arm overwrites every entry read below.
  thread_local trajopt::ChainFrames frames;
  thread_local std::vector<Pose> poses;
  for (int step = 0; step < substeps; ++step) {
    const double fraction = static_cast<double>(step) / scenario_.substeps;
    const State q = last ? x : State(x + fraction * scenario_.dt * u);
    pose_arm(scenario_, q, derivatives, frames, poses);
    const Eigen::Index first_row = first_collision + step * pair_count;
    for (const Contact& contact : scene_.contacts(poses, scenario_.query_margin)) {
      const int pair = row_of(contact);
      if (pair < 0) continue;  // two bodies that never move
      const Eigen::Index row = first_row + pair;
      out.value(row) = collision_row(contact.distance);
      if (!derivatives || out.value(row) == far) continue;
      // d distance / dq through the two bodies' frames (the boards and the base do not move),
      // then dq/dx = I and dq/du = (s / S) dt.
      Eigen::Matrix<double, 1, 7> dq = Eigen::Matrix<double, 1, 7>::Zero();
      for (int side = 0; side < 2; ++side) {
        const int body = contact.bodies[static_cast<std::size_t>(side)];
        if (body < 1 || body >= kLinks) continue;
        const auto f = static_cast<std::size_t>(body);
        const auto g = contact.gradient.segment<7>(Eigen::Index{7} * side);
        dq -= g.head<3>().transpose() * frames.d_origin[f] +
              g.tail<4>().transpose() * frames.d_attitude[f];
      }
      out.dx.row(row) = dq;
      if (!last) out.du.row(row) = fraction * scenario_.dt * dq;
    }
  }
}

Eigen::MatrixXd ArmShelfProblem::dynamics_hessian(const State&, const Control&,
                                                  const State&) const {
  return Eigen::MatrixXd::Zero(14, 14);  // x + dt u is linear
}

// Each shape's world pose is fixed in its link's frame f (or in the world, for a board):
// p = o_f + Q(q_f) r_l, q_p = q_f^ (x) q_l / |q_l| (world_pose, scene.hpp: the scene's own
// composition, bit for bit, so the Hessian is taken at the contact's geometry). With J_s its
// Jacobian and C_s its curvature term for the distance's gradient (serial_chain.hpp), the Hessian
// of the distance in the joint angles is [J_1; J_2]' H [J_1; J_2] + C_1 + C_2, H the 14 x 14
// Hessian of signed_distance_hessian at the two world poses.
Eigen::MatrixXd ArmShelfProblem::contact_hessian(const Contact& contact,
                                                 const trajopt::ChainFrames& frames) const {
  std::array<Pose, 2> world;
  for (std::size_t side = 0; side < 2; ++side) {
    const BodyShape& shape = scene_.body(contact.bodies[side]).shapes()[contact.shapes[side]];
    if (contact.bodies[side] >= 1 && contact.bodies[side] < kLinks) {
      const auto f = static_cast<std::size_t>(contact.bodies[side]);
      world[side] = world_pose(Pose(frames.origin[f], frames.attitude[f]), shape.pose);
    } else {
      world[side] = world_pose(Pose(), shape.pose);  // the base and the boards stay put
    }
  }
  const auto& shape_of = [&](std::size_t side) -> const Shape& {
    return scene_.body(contact.bodies[side]).shapes()[contact.shapes[side]].shape;
  };
  const SignedDistanceHessian distance =
      signed_distance_hessian(shape_of(0), world[0], shape_of(1), world[1]);
  Eigen::Matrix<double, 14, 7> J = Eigen::Matrix<double, 14, 7>::Zero();
  Eigen::MatrixXd curvature = Eigen::MatrixXd::Zero(7, 7);
  for (std::size_t side = 0; side < 2; ++side) {
    const int body = contact.bodies[side];
    if (body < 1 || body >= kLinks) continue;
    const auto row = static_cast<Eigen::Index>(7 * side);
    const trajopt::AttachedPoseDerivatives pose = trajopt::attached_pose_derivatives(
        frames, body, world[side].r(), world[side].q(), distance.gradient.segment<7>(row));
    J.middleRows<7>(row) = pose.jacobian;
    curvature += pose.curvature;
  }
  return J.transpose() * distance.hessian * J + curvature;
}

// The goal, limit and velocity rows are linear. A collision row at substep s, clearance -
// min(distance(q), margin) with q = x + c u, c = (s / S) dt, adds -mu times the distance's
// Hessian in q, [I; c I]' H_q [I, c I] in [x; u], where the contact is within the margin (beyond
// it the row is constant).
Eigen::MatrixXd ArmShelfProblem::constraint_hessian(int k, const State& x, const Control& u,
                                                    const Eigen::VectorXd& mu) const {
  const bool last = k == knots() - 1;
  const auto pair_count = static_cast<Eigen::Index>(pairs_.size());
  const int substeps = last ? 1 : scenario_.substeps;
  trajopt::require_size(mu, collision_start(last) + substeps * pair_count, "mu");
  const int size = last ? 7 : 14;
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(size, size);
  for (int step = 0; step < substeps; ++step) {
    const double c = static_cast<double>(step) / scenario_.substeps * scenario_.dt;
    const State q = last ? x : State(x + c * u);
    trajopt::ChainFrames frames;
    const std::vector<Pose> poses = arm_shelf_poses(scenario_, q, &frames);
    for (const Contact& contact : scene_.contacts(poses, scenario_.query_margin)) {
      const int pair = row_of(contact);
      if (pair < 0 || collision_row(contact.distance) == far_row()) continue;
      const double weight = mu(collision_start(last) + step * pair_count + pair);
      if (weight == 0.0) continue;
      const Eigen::MatrixXd H_q = -weight * contact_hessian(contact, frames);
      H.topLeftCorner<7, 7>() += H_q;
      if (last) continue;
      H.topRightCorner<7, 7>() += c * H_q;
      H.bottomLeftCorner<7, 7>() += c * H_q;
      H.bottomRightCorner<7, 7>() += c * c * H_q;
    }
  }
  return H;
}

std::vector<Eigen::VectorXd> ArmShelfProblem::straight_line_controls() const {
  const Eigen::VectorXd velocity =
      (scenario_.goal - scenario_.start) / (scenario_.dt * (scenario_.knots - 1));
  return std::vector<Eigen::VectorXd>(static_cast<std::size_t>(scenario_.knots - 1), velocity);
}

trajopt::AltroSettings ArmShelfProblem::settings() {
  trajopt::AltroSettings settings;
  settings.penalty_initial = 100.0;
  return settings;
}

std::vector<Eigen::VectorXd> ArmShelfProblem::retreat_controls() const {
  const int steps = scenario_.knots - 1;
  const int out = steps / 4, across = steps - 2 * out;
  const std::vector<std::pair<Eigen::VectorXd, int>> legs = {
      {scenario_.retract_left - scenario_.start, out},
      {scenario_.retract_right - scenario_.retract_left, across},
      {scenario_.goal - scenario_.retract_right, out}};
  std::vector<Eigen::VectorXd> controls;
  for (const auto& [change, count] : legs) {
    for (int i = 0; i < count; ++i) controls.emplace_back(change / (count * scenario_.dt));
  }
  return controls;
}

double arm_shelf_min_distance(const ArmShelfProblem& problem, const Eigen::VectorXd& q) {
  double smallest = std::numeric_limits<double>::infinity();
  const std::vector<Pose> poses = arm_shelf_poses(problem.scenario(), q);
  for (const Contact& contact : problem.scene().contacts(poses, 1e3)) {
    const bool moves = (contact.bodies[0] >= 1 && contact.bodies[0] < kLinks) ||
                       (contact.bodies[1] >= 1 && contact.bodies[1] < kLinks);
    if (moves) smallest = std::min(smallest, contact.distance);
  }
  return smallest;
}

double arm_shelf_path_min_distance(const ArmShelfProblem& problem,
                                   const std::vector<Eigen::VectorXd>& states, int samples) {
  double smallest = arm_shelf_min_distance(problem, states.back());
  for (std::size_t k = 0; k + 1 < states.size(); ++k) {
    for (int i = 0; i < samples; ++i) {
      const double t = static_cast<double>(i) / samples;
      smallest = std::min(
          smallest, arm_shelf_min_distance(problem, states[k] + t * (states[k + 1] - states[k])));
    }
  }
  return smallest;
}

}  // namespace diffpills::examples
