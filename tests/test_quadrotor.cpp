// The quadrotor of the motion-planning demo: its RK4 step's exact Jacobians, its physics, the
// window problem's constraint gradients, and the solved flight checked knot by knot against
// computations written apart from the solver and the library (a brute-force closest-point
// reference on corners computed here, and a separate RK4 of the equations of motion).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <iostream>
#include <random>

#include "diffpills/trajopt/altro.hpp"
#include "diffpills/trajopt/quadrotor.hpp"
#include "quadrotor_window/quadrotor_window.hpp"
#include "support/reference.hpp"

namespace diffpills::trajopt {
namespace {

using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;
using State = Quadrotor::State;
using Control = Quadrotor::Control;

State random_state(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  State x;
  for (int i = 0; i < 13; ++i) x(i) = normal(rng);
  x.segment<4>(3).normalize();
  return x;
}

Control random_thrusts(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> thrust(0.0, 4.0);
  return Control(thrust(rng), thrust(rng), thrust(rng), thrust(rng));
}

State step(const Quadrotor& model, const State& x, const Control& u, double h) {
  State next;
  Quadrotor::StateMatrix A;
  Quadrotor::ControlMatrix B;
  model.step(h, x, u, next, A, B);
  return next;
}

// A and B of the step (RK4, then q normalized) against central differences of the step itself,
// at random states (unit attitudes; the perturbed q is not unit, which the step's normalization
// and its Jacobian both cover).
TEST(Quadrotor, StepJacobiansMatchCentralDifferences) {
  const Quadrotor model;
  std::mt19937_64 rng(21);
  const double h = 0.06, e = 1e-6;
  double worst = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    const State x = random_state(rng);
    const Control u = random_thrusts(rng);
    State next;
    Quadrotor::StateMatrix A;
    Quadrotor::ControlMatrix B;
    model.step(h, x, u, next, A, B);
    EXPECT_NEAR(next.segment<4>(3).norm(), 1.0, 1e-15);
    for (int j = 0; j < 13; ++j) {
      State plus = x, minus = x;
      plus(j) += e;
      minus(j) -= e;
      const State column = (step(model, plus, u, h) - step(model, minus, u, h)) / (2 * e);
      worst = std::max(worst, (column - A.col(j)).norm() / (1.0 + A.col(j).norm()));
    }
    for (int j = 0; j < 4; ++j) {
      Control plus = u, minus = u;
      plus(j) += e;
      minus(j) -= e;
      const State column = (step(model, x, plus, h) - step(model, x, minus, h)) / (2 * e);
      worst = std::max(worst, (column - B.col(j)).norm() / (1.0 + B.col(j).norm()));
    }
  }
  EXPECT_LE(worst, 1e-7);
  std::cout << "[quadrotor] step Jacobians vs central differences: max error " << worst << "\n";
}

// The step multiplies Fx only through its known nonzero blocks (SparseStateProduct in
// quadrotor.cpp): at random states every other entry of Fx is exactly zero, and the position rows
// are exactly the identity on the velocity.
TEST(Quadrotor, StateJacobianIsZeroOutsideTheBlocksTheStepMultiplies) {
  const Quadrotor model;
  std::mt19937_64 rng(22);
  Eigen::Matrix<bool, 13, 13> read = Eigen::Matrix<bool, 13, 13>::Constant(false);
  read.block<3, 3>(0, 7).setConstant(true);
  read.block<4, 4>(3, 3).setConstant(true);
  read.block<4, 3>(3, 10).setConstant(true);
  read.block<3, 4>(7, 3).setConstant(true);
  read.block<3, 3>(10, 10).setConstant(true);
  for (int trial = 0; trial < 100; ++trial) {
    State xdot;
    Quadrotor::StateMatrix Fx;
    Quadrotor::ControlMatrix Fu;
    model.derivative(random_state(rng), random_thrusts(rng), xdot, Fx, Fu);
    for (int i = 0; i < 13; ++i) {
      for (int j = 0; j < 13; ++j) {
        if (!read(i, j)) {
          EXPECT_EQ(Fx(i, j), 0.0) << "Fx(" << i << ", " << j << ")";
        }
      }
    }
    EXPECT_TRUE((Fx.block<3, 3>(0, 7).array() == Eigen::Matrix3d::Identity().array()).all());
  }
}

// Physics: level hover thrust balances gravity; rolled about +x, the thrust pushes towards -y;
// more thrust on the +y rotor than on the -y rotor spins the body about +x, on the -x rotor than
// the +x rotor about +y; rotors 1 and 3 (spinning one way) against 2 and 4 yaw it about +z.
TEST(Quadrotor, HoverBalancesGravityAndRotorsTurnTheRightWay) {
  const Quadrotor model;
  State level = State::Zero();
  level(3) = 1.0;
  const Control hover = Control::Constant(model.hover_thrust());
  EXPECT_LE((step(model, level, hover, 0.06) - level).norm(), 1e-15);

  State rolled = level;
  rolled.segment<4>(3) << std::cos(0.25), std::sin(0.25), 0.0, 0.0;  // 0.5 rad about +x
  State xdot;
  Quadrotor::StateMatrix Fx;
  Quadrotor::ControlMatrix Fu;
  model.derivative(rolled, hover, xdot, Fx, Fu);
  EXPECT_NEAR(xdot(8), -4.0 * model.hover_thrust() / model.mass * std::sin(0.5), 1e-12);

  const double d = 0.5;
  model.derivative(level, hover + Control(0.0, d, 0.0, -d), xdot, Fx, Fu);
  EXPECT_GT(xdot(10), 0.0);
  EXPECT_NEAR(xdot(10), 2.0 * d * model.arm / model.inertia(0), 1e-12);
  model.derivative(level, hover + Control(-d, 0.0, d, 0.0), xdot, Fx, Fu);
  EXPECT_NEAR(xdot(11), 2.0 * d * model.arm / model.inertia(1), 1e-12);
  model.derivative(level, hover + Control(d, -d, d, -d), xdot, Fx, Fu);
  EXPECT_NEAR(xdot(12), 4.0 * d * model.torque_per_thrust / model.inertia(2), 1e-12);
  EXPECT_NEAR(xdot(9), 0.0, 1e-15);  // no net torque about x
}

// The constraint rows' state Jacobian (-phi's pose gradient: position and the quaternion, the
// polygon-polygon and polygon-capsule paths) against central differences of the values, at
// random states around the window and the poles. A state whose difference quotient straddles an
// active-set change (phi is C1 but its gradient kinks there) may differ; at most 1% may.
// Both clearances: phi and the signed distance (a kink there is a change of nearest facet).
class WindowConstraintGradients : public ::testing::TestWithParam<examples::Clearance> {};

TEST_P(WindowConstraintGradients, MatchCentralDifferences) {
  examples::QuadrotorWindowScenario scenario;
  scenario.clearance = GetParam();
  const examples::QuadrotorWindowProblem problem{scenario};
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double e = 1e-6;
  const Control u = Control::Constant(1.0);
  int checked = 0, mismatched = 0;
  for (int trial = 0; trial < 500; ++trial) {
    State x = random_state(rng);
    const double along = trial % 3 == 0 ? 1.5 : (trial % 3 == 1 ? 3.0 : 4.5);
    x.head<3>() = Vector3d(along, 0.0, 1.5) + 0.6 * Vector3d(unit(rng), unit(rng), unit(rng));
    const examples::QuadrotorWindowProblem::Constraints c = problem.constraints(0, x, u);
    MatrixXd numeric(c.value.size(), 13);
    for (int j = 0; j < 13; ++j) {
      State plus = x, minus = x;
      plus(j) += e;
      minus(j) -= e;
      numeric.col(j) = (problem.constraint_values(0, plus, u).value -
                        problem.constraint_values(0, minus, u).value) /
                       (2 * e);
    }
    for (int row = 0; row < problem.obstacle_count(); ++row) {
      ++checked;
      const double error = (numeric.row(row) - c.dx.row(row)).norm();
      if (error > 1e-6 * (1.0 + c.dx.row(row).norm())) ++mismatched;
    }
  }
  EXPECT_LE(mismatched, checked / 100);
  std::cout << "[quadrotor] constraint gradients: " << mismatched << " of " << checked
            << " rows off (active-set changes)\n";
}
INSTANTIATE_TEST_SUITE_P(Quadrotor, WindowConstraintGradients,
                         ::testing::Values(examples::Clearance::kProximity,
                                           examples::Clearance::kSignedDistance));

// The world corners of a rectangle [s0, s1] x [t0, t1] of the tilted wall, from its definition:
// s runs across the window (world y turned by the tilt about x), t along it (world z turned).
testing::WorldCore wall_rectangle(const examples::QuadrotorWindowScenario& s, double s0, double s1,
                                  double t0, double t1) {
  const Vector3d across(0.0, std::cos(s.window_tilt), std::sin(s.window_tilt));
  const Vector3d along(0.0, -std::sin(s.window_tilt), std::cos(s.window_tilt));
  testing::WorldCore core;
  for (const auto& [a, b] : {std::pair{s0, t0}, {s1, t0}, {s1, t1}, {s0, t1}}) {
    core.vertices.emplace_back((s.window_centre + a * across + b * along).cast<long double>());
  }
  return core;
}

// The body's square in the world, through Eigen's quaternion.
testing::WorldCore body_square(const examples::QuadrotorWindowScenario& s, const VectorXd& x) {
  const Eigen::Quaterniond q(x(3), x(4), x(5), x(6));
  const double a = s.body_half_side;
  testing::WorldCore core;
  for (const auto& [bx, by] : {std::pair{a, a}, {-a, a}, {-a, -a}, {a, -a}}) {
    core.vertices.emplace_back(
        (x.head<3>() + q.normalized() * Vector3d(bx, by, 0.0)).cast<long double>());
  }
  return core;
}

// The smallest phi over the obstacles at state x, and the smallest gap between the padded shapes
// (distance of the cores minus the radii), by the brute-force reference on the world cores built
// here from the scenario's fields (not the library's shapes).
struct BruteForceClearance {
  double phi = INFINITY, gap = INFINITY;
};
BruteForceClearance brute_force_clearance(const examples::QuadrotorWindowScenario& s,
                                          const VectorXd& x) {
  const double half_gap = 0.5 * s.window_width + s.wall_radius,
               half_height = 0.5 * s.window_height + s.wall_radius, w = s.wall_half_size;
  std::vector<std::pair<testing::WorldCore, double>> obstacles = {
      {wall_rectangle(s, -w, -half_gap, -w, w), s.wall_radius},
      {wall_rectangle(s, half_gap, w, -w, w), s.wall_radius},
      {wall_rectangle(s, -half_gap, half_gap, -w, -half_height), s.wall_radius},
      {wall_rectangle(s, -half_gap, half_gap, half_height, w), s.wall_radius}};
  for (const auto& pole : s.poles) {  // vertical segments from the ground, by construction
    const Vector3d foot(pole.pose.r()(0), pole.pose.r()(1), 0.0);
    obstacles.push_back({{{foot.cast<long double>(),
                           (foot + Vector3d(0, 0, pole.shape.length())).cast<long double>()}},
                         pole.shape.radius()});
  }
  const testing::WorldCore body = body_square(s, x);
  BruteForceClearance out;
  for (const auto& [core, radius] : obstacles) {
    const double d = static_cast<double>(testing::brute_force_closest(body, core).distance);
    const double sum = s.body_radius + radius;
    out.phi = std::min(out.phi, d * d - sum * sum);
    out.gap = std::min(out.gap, d - sum);
  }
  return out;
}

// x' of the documented model, written out again with Eigen's quaternion algebra.
State rate(const Quadrotor& m, const State& x, const Control& u) {
  const Eigen::Quaterniond q(x(3), x(4), x(5), x(6));
  const Vector3d w = x.segment<3>(10);
  const Eigen::Quaterniond q_dot = q * Eigen::Quaterniond(0.0, w(0), w(1), w(2));
  const Vector3d J = m.inertia;
  const Vector3d tau(m.arm * (u(1) - u(3)), m.arm * (u(2) - u(0)),
                     m.torque_per_thrust * (u(0) - u(1) + u(2) - u(3)));
  State out;
  out.head<3>() = x.segment<3>(7);
  out.segment<4>(3) << 0.5 * q_dot.w(), 0.5 * q_dot.x(), 0.5 * q_dot.y(), 0.5 * q_dot.z();
  out.segment<3>(7) = q.toRotationMatrix().col(2) * u.sum() / m.mass - Vector3d(0, 0, m.gravity);
  out.segment<3>(10) = (tau - w.cross(J.asDiagonal() * w)).cwiseQuotient(J);
  return out;
}

TEST(Quadrotor, FliesThroughTheTiltedWindow) {
  const examples::QuadrotorWindowProblem problem{examples::QuadrotorWindowScenario{}};
  const examples::QuadrotorWindowScenario& s = problem.scenario();

  // The level body slid along the straight line cannot pass.
  double level_min_phi = INFINITY;
  for (int i = 0; i <= 100; ++i) {
    const double t = i / 100.0;
    level_min_phi =
        std::min(level_min_phi, examples::quadrotor_min_phi(s, (1 - t) * s.x0 + t * s.goal));
  }
  EXPECT_LT(level_min_phi, 0.0);

  const AltroResult result = solve(problem, s.x0, problem.hover_controls());
  ASSERT_EQ(result.status, AltroStatus::kSolved) << to_string(result.status);
  EXPECT_LE(result.max_violation, 1e-6);

  double min_phi = INFINITY, largest_tilt = 0.0;
  for (int k = 0; k < s.knots; ++k) {
    const VectorXd& x = result.states[k];
    min_phi = std::min(min_phi, brute_force_clearance(s, x).phi);
    largest_tilt = std::max(largest_tilt, std::acos(1.0 - 2.0 * (x(4) * x(4) + x(5) * x(5))));
    EXPECT_NEAR(x.segment<4>(3).norm(), 1.0, 1e-9) << "knot " << k;
    if (k + 1 < s.knots) {
      const State xk = x;
      const Control u = result.controls[k];
      EXPECT_GE(u.minCoeff(), -1e-6) << "knot " << k;
      EXPECT_LE(u.maxCoeff(), s.thrust_max + 1e-6) << "knot " << k;
      const State k1 = rate(s.model, xk, u), k2 = rate(s.model, xk + 0.5 * s.dt * k1, u),
                  k3 = rate(s.model, xk + 0.5 * s.dt * k2, u),
                  k4 = rate(s.model, xk + s.dt * k3, u);
      State next = xk + s.dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
      next.segment<4>(3).normalize();
      EXPECT_LE((next - result.states[k + 1]).norm(), 1e-9) << "knot " << k;
    }
  }
  EXPECT_GE(min_phi, -1e-6);
  EXPECT_GT(largest_tilt * 180.0 / M_PI, 20.0);  // it had to tilt to pass
  EXPECT_LE((result.states.back().head<3>() - s.goal.head<3>()).cwiseAbs().maxCoeff(), 1e-6);
  std::cout << "[quadrotor] iterations " << result.iterations << " (outer "
            << result.outer_iterations << "), cost " << result.cost << ", max violation "
            << result.max_violation << ", smallest phi (brute force) " << min_phi
            << ", largest tilt " << largest_tilt * 180.0 / M_PI << " deg, level straight line "
            << level_min_phi << "\n";
}

// A thin wall (panels and body padded by 0.025 m each, 0.05 in sum) for horizons of 31 to 81
// knots: with phi as the clearance, augmented-Lagrangian iterates that cross an obstacle's core
// stay stuck where phi is flat (measured: all six horizons end at the iteration cap, inside a
// pole); with the signed distance, whose slope leads out of the crossing (the body's square and a
// panel or pole are not coplanar, so their Minkowski difference has depth), every horizon is
// solved. Checked by brute force: every knot clear, the goal reached.
TEST(Quadrotor, ThinWallIsSolvedWithTheSignedDistance) {
  for (int knots = 31; knots <= 81; knots += 10) {
    SCOPED_TRACE(knots);
    examples::QuadrotorWindowScenario scenario;
    scenario.wall_radius = 0.025;
    scenario.body_radius = 0.025;
    scenario.knots = knots;
    scenario.clearance = examples::Clearance::kSignedDistance;
    scenario.build();
    const examples::QuadrotorWindowProblem problem{scenario};
    const examples::QuadrotorWindowScenario& s = problem.scenario();
    const AltroResult result = solve(problem, s.x0, problem.hover_controls());
    ASSERT_EQ(result.status, AltroStatus::kSolved) << to_string(result.status);
    double smallest_gap = INFINITY;
    for (const VectorXd& x : result.states) {
      smallest_gap = std::min(smallest_gap, brute_force_clearance(s, x).gap);
    }
    EXPECT_GE(smallest_gap, -1e-6);
    EXPECT_LE((result.states.back().head<3>() - s.goal.head<3>()).cwiseAbs().maxCoeff(), 1e-6);
  }
}

}  // namespace
}  // namespace diffpills::trajopt
