#include "quadrotor_window.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace diffpills::examples {

namespace {

// The rectangle |x| <= half_x, |y| <= half_y in the body xy-plane, padded by radius.
PaddedPolygon padded_rectangle(double half_x, double half_y, double radius) {
  Eigen::MatrixX2d C(4, 2);
  C << 1.0, 0.0, -1.0, 0.0, 0.0, 1.0, 0.0, -1.0;
  return PaddedPolygon(C, Eigen::Vector4d(half_x, half_x, half_y, half_y), radius);
}

// A rectangle [s0, s1] x [t0, t1] of the wall, padded by radius: s runs across the window, t
// along it, and the wall is the plane x = centre.x turned by tilt about the world x axis, so that
// before the tilt s is world y and t world z. The panel's body frame is the world's turned by +90
// degrees about y (body z = world x, body x = -t, body y = s), then by the tilt, centred on the
// rectangle so that the polygon contains its origin.
PosedPolygon wall_panel(const Eigen::Vector3d& centre, double tilt, double s0, double s1, double t0,
                        double t1, double radius) {
  const Eigen::Quaterniond rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX())) *
      Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * M_PI, Eigen::Vector3d::UnitY()));
  const Eigen::Vector3d offset = rotation * Eigen::Vector3d(-0.5 * (t0 + t1), 0.5 * (s0 + s1), 0.0);
  return {padded_rectangle(0.5 * (t1 - t0), 0.5 * (s1 - s0), radius),
          Pose(centre + offset,
               Eigen::Vector4d(rotation.w(), rotation.x(), rotation.y(), rotation.z()))};
}

// A vertical pole: the capsule's core (body x) turned by -90 degrees about y onto world z.
PosedCapsule pole(double x, double y, double height, double radius) {
  const double c = std::sqrt(0.5);
  return {Capsule(height, radius),
          Pose(Eigen::Vector3d(x, y, 0.5 * height), Eigen::Vector4d(c, 0.0, -c, 0.0))};
}

Eigen::VectorXd hover_state(double x, double y, double z) {
  Eigen::VectorXd state = Eigen::VectorXd::Zero(13);
  state.head<3>() << x, y, z;
  state(3) = 1.0;
  return state;
}

}  // namespace

// The wall is a 3 m square of four panels 0.3 m thick (radius 0.15) around the window, whose
// padded surfaces bound the window exactly: window_width across, window_height along, the whole
// turned by window_tilt about x. The body (half-side 0.2, radius 0.1) is 0.6 m wide and fits the
// 0.45 m gap only when its plane crosses the window steeply: rolled by alpha, its extent across
// the window is 0.4 |cos(alpha - tilt)| + 0.2 < 0.45, i.e. |alpha - tilt| > acos(0.625) ~ 51 deg,
// a roll beyond -21 deg for the 30 deg tilt.
// Two numerical choices make the problem well posed for a local method:
// - The tilt makes phi's derivative with respect to the roll nonzero when level; an upright slot
//   is a symmetric saddle there and iLQR never starts rolling.
// - phi's gradient vanishes once the cores intersect (proximity.hpp), which happens when an iterate
//   penetrates deeper than the sum of the radii; with 0.05 m panels and body padding, early AL
//   iterates got stuck at phi = -(R1 + R2)^2 for some horizons. The padding here (0.25 m in sum)
//   keeps every horizon from 31 to 81 knots solvable (measured). The signed distance as the
//   clearance (Clearance::kSignedDistance) keeps its slope there and solves thin walls too.
QuadrotorWindowScenario::QuadrotorWindowScenario()
    : body(padded_rectangle(body_half_side, body_half_side, body_radius)),
      x0(hover_state(0.0, 0.0, 1.5)),
      goal(hover_state(6.0, 0.0, 1.5)) {
  build();
}

void QuadrotorWindowScenario::build() {
  body = padded_rectangle(body_half_side, body_half_side, body_radius);
  const double radius = wall_radius, half_wall = wall_half_size;
  const double half_gap = 0.5 * window_width + radius, half_height = 0.5 * window_height + radius;
  wall = {
      wall_panel(window_centre, window_tilt, -half_wall, -half_gap, -half_wall, half_wall, radius),
      wall_panel(window_centre, window_tilt, half_gap, half_wall, -half_wall, half_wall, radius),
      wall_panel(window_centre, window_tilt, -half_gap, half_gap, -half_wall, -half_height, radius),
      wall_panel(window_centre, window_tilt, -half_gap, half_gap, half_height, half_wall, radius)};
  poles = {pole(1.5, 0.2, 3.0, 0.1), pole(4.5, -0.2, 3.0, 0.1)};
}

Pose quadrotor_pose(const Eigen::Ref<const Eigen::VectorXd>& x) {
  return Pose(x.head<3>(), x.segment<4>(3));
}

double quadrotor_min_phi(const QuadrotorWindowScenario& scenario, const Eigen::VectorXd& x) {
  const Pose pose = quadrotor_pose(x);
  double smallest = INFINITY;
  for (const PosedPolygon& panel : scenario.wall) {
    smallest = std::min(smallest, proximity(scenario.body, pose, panel.shape, panel.pose).phi);
  }
  for (const PosedCapsule& p : scenario.poles) {
    smallest = std::min(smallest, proximity(scenario.body, pose, p.shape, p.pose).phi);
  }
  return smallest;
}

QuadrotorWindowProblem::QuadrotorWindowProblem(QuadrotorWindowScenario scenario)
    : scenario_(std::move(scenario)) {
  trajopt::require_size(scenario_.goal, 13, "scenario.goal");
  goal_ = scenario_.goal;
  hover_ = Control::Constant(scenario_.model.hover_thrust());
  Q_ = 0.01 * StateMatrix::Identity();
  State qf = State::Constant(10.0);
  qf.tail<3>().setConstant(1.0);  // angular velocity weighs less at the end
  Qf_ = qf.asDiagonal();
  R_ = 0.1 * Eigen::Matrix4d::Identity();
}

int QuadrotorWindowProblem::obstacle_count() const {
  return static_cast<int>(scenario_.wall.size() + scenario_.poles.size());
}

void QuadrotorWindowProblem::dynamics(const State& x, const Control& u, State& next, StateMatrix& A,
                                      ControlMatrix& B) const {
  scenario_.model.step(scenario_.dt, x, u, next, A, B);
}

QuadrotorWindowProblem::Cost QuadrotorWindowProblem::stage_cost(int, const State& x,
                                                                const Control& u) const {
  const State e = x - goal_;
  const Control du = u - hover_;
  return {0.5 * e.dot(Q_ * e) + 0.5 * du.dot(R_ * du), Q_ * e, R_ * du, Q_, R_,
          Eigen::Matrix<double, 4, 13>::Zero()};
}

QuadrotorWindowProblem::Cost QuadrotorWindowProblem::terminal_cost(const State& x) const {
  const State e = x - goal_;
  return {0.5 * e.dot(Qf_ * e),    Qf_ * e,
          Control::Zero(),         Qf_,
          Eigen::Matrix4d::Zero(), Eigen::Matrix<double, 4, 13>::Zero()};
}

QuadrotorWindowProblem::Constraints QuadrotorWindowProblem::constraints(int k, const State& x,
                                                                        const Control& u) const {
  return rows_written_by<QuadrotorWindowProblem>(*this, k, x, u, true);
}

QuadrotorWindowProblem::Constraints QuadrotorWindowProblem::constraint_values(
    int k, const State& x, const Control& u) const {
  return rows_written_by<QuadrotorWindowProblem>(*this, k, x, u, false);
}

// Rows: [equalities: r - goal position (last knot only)], -clearance per obstacle (wall panels,
// then poles), then u - thrust_max and -u. d(-phi)/dx takes the measure's gradient's first seven
// entries (d/dr, d/dq of the body, the first shape) as they are: q is the state's own quaternion,
// and the library's gradient already includes the normalization of q. setZero(rows) reallocates
// only when the size changes; without derivatives dx and du are left as they are (not read).
void QuadrotorWindowProblem::write_constraints(int k, const State& x, const Control& u,
                                               bool derivatives, Constraints& c) const {
  const bool last = k == scenario_.knots - 1;
  const int equalities = last ? 3 : 0;
  const int obstacles = obstacle_count();
  const int rows = equalities + obstacles + (last ? 0 : 8);
  c.equalities = equalities;
  c.value.setZero(rows);
  if (derivatives) {
    c.dx.setZero(rows, 13);
    c.du.setZero(rows, 4);
  }
  if (last) {
    c.value.head<3>() = x.head<3>() - goal_.head<3>();
    if (derivatives) c.dx.topLeftCorner<3, 3>().setIdentity();
  }
  const Pose pose = quadrotor_pose(x);
  int row = equalities;
  const auto add = [&](const auto& obstacle) {
    const bool phi = scenario_.clearance == Clearance::kProximity;
    if (phi) {
      const Proximity p = proximity(scenario_.body, pose, obstacle.shape, obstacle.pose);
      c.value(row) = -p.phi;
      if (derivatives) c.dx.row(row).head<7>() = -p.gradient.head<7>().transpose();
    } else {
      const SignedDistance s = signed_distance(scenario_.body, pose, obstacle.shape, obstacle.pose);
      c.value(row) = -s.distance;
      if (derivatives) c.dx.row(row).head<7>() = -s.gradient.head<7>().transpose();
    }
    ++row;
  };
  for (const PosedPolygon& panel : scenario_.wall) add(panel);
  for (const PosedCapsule& p : scenario_.poles) add(p);
  if (!last) {
    for (int i = 0; i < 4; ++i) {
      c.value(row + i) = u(i) - scenario_.thrust_max;
      c.value(row + 4 + i) = -u(i);
      if (derivatives) {
        c.du(row + i, i) = 1.0;
        c.du(row + 4 + i, i) = -1.0;
      }
    }
  }
}

Eigen::MatrixXd QuadrotorWindowProblem::dynamics_hessian(const State& x, const Control& u,
                                                         const State& lambda) const {
  return scenario_.model.step_hessian(scenario_.dt, x, u, lambda);
}

// The obstacle rows are the only nonlinear ones: each adds -mu times its measure's Hessian with
// respect to the body's pose, which is the state's first seven entries as they are.
Eigen::MatrixXd QuadrotorWindowProblem::constraint_hessian(int k, const State& x, const Control&,
                                                           const Eigen::VectorXd& mu) const {
  const bool last = k == scenario_.knots - 1;
  trajopt::require_size(mu, (last ? 3 : 0) + obstacle_count() + (last ? 0 : 8), "mu");
  const int size = last ? 13 : 17;
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(size, size);
  const Pose pose = quadrotor_pose(x);
  int row = last ? 3 : 0;
  const auto add = [&](const auto& obstacle) {
    const double weight = mu(row++);
    if (weight == 0.0) return;
    const Eigen::Matrix<double, 14, 14> measure =
        scenario_.clearance == Clearance::kProximity
            ? proximity_with_hessian(scenario_.body, pose, obstacle.shape, obstacle.pose).hessian
            : signed_distance_hessian(scenario_.body, pose, obstacle.shape, obstacle.pose).hessian;
    H.topLeftCorner<7, 7>() -= weight * measure.topLeftCorner<7, 7>();
  };
  for (const PosedPolygon& panel : scenario_.wall) add(panel);
  for (const PosedCapsule& p : scenario_.poles) add(p);
  return H;
}

std::vector<Eigen::VectorXd> QuadrotorWindowProblem::hover_controls() const {
  return std::vector<Eigen::VectorXd>(scenario_.knots - 1, Eigen::VectorXd(hover_));
}

}  // namespace diffpills::examples
