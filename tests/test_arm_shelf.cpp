// The arm among the shelves (examples/arm_shelf, issue 11): the Panda's forward kinematics against
// the modified-DH transforms multiplied out here, their Jacobians and the problem's constraint
// Jacobians against central differences, and the solved motion checked knot by knot and between
// knots with poses and distances computed here from the transforms and signed_distance() directly,
// not through the problem or the scene; Ipopt's solution of the same problem agrees.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "arm_shelf/arm_shelf.hpp"
#include "diffpills/diffpills.hpp"
#include "ipopt/problem_nlp.hpp"

namespace diffpills::examples {
namespace {

using Transform = Eigen::Isometry3d;

// T_i = RotX(alpha_i) TransX(a_i) RotZ(q_i) TransZ(d_i), then the flange's TransZ(d): frames 0..8.
std::vector<Transform> dh_frames(const PandaArm& arm, const Eigen::VectorXd& q) {
  std::vector<Transform> frames{Transform::Identity()};
  for (int i = 0; i < 7; ++i) {
    const auto j = static_cast<std::size_t>(i);
    Transform step = Transform::Identity();
    step.rotate(Eigen::AngleAxisd(arm.chain.alpha[j], Eigen::Vector3d::UnitX()));
    step.translate(Eigen::Vector3d(arm.chain.a[j], 0, 0));
    step.rotate(Eigen::AngleAxisd(q(i), Eigen::Vector3d::UnitZ()));
    step.translate(Eigen::Vector3d(0, 0, arm.chain.d[j]));
    frames.push_back(frames.back() * step);
  }
  frames.push_back(frames.back() * Eigen::Translation3d(0, 0, arm.chain.flange_d));
  return frames;
}

Eigen::VectorXd random_joints(std::mt19937_64& rng, const PandaArm& arm) {
  Eigen::VectorXd q(7);
  for (int i = 0; i < 7; ++i) {
    q(i) =
        std::uniform_real_distribution<double>(arm.joint_limits(i, 0), arm.joint_limits(i, 1))(rng);
  }
  return q;
}

TEST(ArmShelf, ForwardKinematicsIsTheDhProduct) {
  const PandaArm arm = panda_arm();
  std::mt19937_64 rng(1);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::VectorXd q = random_joints(rng, arm);
    const trajopt::ChainFrames frames = trajopt::forward_kinematics(arm.chain, q);
    const std::vector<Transform> expected = dh_frames(arm, q);
    ASSERT_EQ(frames.origin.size(), 9u);
    for (std::size_t f = 0; f < 9; ++f) {
      EXPECT_LE((frames.origin[f] - expected[f].translation()).norm(), 1e-14);
      EXPECT_LE((rotation_matrix(frames.attitude[f]) - expected[f].rotation()).norm(), 1e-14);
      EXPECT_NEAR(frames.attitude[f].norm(), 1.0, 1e-15);
    }
  }
  // The published home configuration puts the flange at (0.307, 0, 0.590), pointing down.
  Eigen::VectorXd home(7);
  home << 0, -M_PI / 4, 0, -3 * M_PI / 4, 0, M_PI / 2, M_PI / 4;
  const trajopt::ChainFrames frames = trajopt::forward_kinematics(arm.chain, home);
  EXPECT_NEAR(frames.origin[8].x(), 0.30689, 1e-5);
  EXPECT_NEAR(frames.origin[8].y(), 0.0, 1e-12);
  EXPECT_NEAR(frames.origin[8].z(), 0.59028, 1e-5);
  EXPECT_NEAR(rotation_matrix(frames.attitude[8]).col(2).z(), -1.0, 1e-12);
}

// Posing a chain into the frames of another configuration, or of another chain (the in-place
// forward_kinematics, which reuses their storage) gives the frames posed into fresh storage, bit
// for bit; without derivatives, the Jacobians it keeps are this chain's sizes, or none.
TEST(ArmShelf, ForwardKinematicsIntoUsedFramesEqualsFresh) {
  const PandaArm arm = panda_arm();
  trajopt::SerialChain shoulder = arm.chain;  // the Panda's first three joints
  for (std::vector<double>* list : {&shoulder.a, &shoulder.d, &shoulder.alpha}) list->resize(3);
  std::mt19937_64 rng(4);
  trajopt::ChainFrames used;
  for (int trial = 0; trial < 60; ++trial) {
    const bool short_chain = trial % 4 == 3 || trial % 5 == 4;
    const trajopt::SerialChain& chain = short_chain ? shoulder : arm.chain;
    const Eigen::VectorXd q = random_joints(rng, arm).head(chain.joints());
    const bool derivatives = trial % 3 != 1;
    trajopt::forward_kinematics(chain, q, derivatives, used);
    const trajopt::ChainFrames fresh = trajopt::forward_kinematics(chain, q, derivatives);
    EXPECT_EQ(used.origin, fresh.origin);
    EXPECT_EQ(used.attitude, fresh.attitude);
    EXPECT_EQ(used.axis, fresh.axis);
    if (!derivatives) {
      EXPECT_TRUE(used.d_origin.empty() || (used.d_origin.size() == fresh.origin.size() &&
                                            used.d_origin[0].cols() == chain.joints()))
          << trial;
      EXPECT_EQ(used.d_attitude.size(), used.d_origin.size()) << trial;
      continue;
    }
    ASSERT_EQ(used.d_origin.size(), fresh.d_origin.size());
    for (std::size_t f = 0; f < fresh.d_origin.size(); ++f) {
      EXPECT_EQ(used.d_origin[f], fresh.d_origin[f]) << f;
      EXPECT_EQ(used.d_attitude[f], fresh.d_attitude[f]) << f;
    }
  }
}

TEST(ArmShelf, ForwardKinematicsJacobiansMatchCentralDifferences) {
  const PandaArm arm = panda_arm();
  std::mt19937_64 rng(2);
  const double h = 1e-6;
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::VectorXd q = random_joints(rng, arm);
    const trajopt::ChainFrames frames = trajopt::forward_kinematics(arm.chain, q);
    for (int j = 0; j < 7; ++j) {
      Eigen::VectorXd plus = q, minus = q;
      plus(j) += h;
      minus(j) -= h;
      const trajopt::ChainFrames up = trajopt::forward_kinematics(arm.chain, plus, false);
      const trajopt::ChainFrames down = trajopt::forward_kinematics(arm.chain, minus, false);
      for (std::size_t f = 0; f < 9; ++f) {
        const Eigen::Vector3d d_origin = (up.origin[f] - down.origin[f]) / (2 * h);
        const Eigen::Vector4d d_attitude = (up.attitude[f] - down.attitude[f]) / (2 * h);
        EXPECT_LE((frames.d_origin[f].col(j) - d_origin).norm(), 1e-8) << f << " " << j;
        EXPECT_LE((frames.d_attitude[f].col(j) - d_attitude).norm(), 1e-8) << f << " " << j;
      }
    }
  }
}

// Every constraint row (goal, limits, velocities, collisions at every substep) against central
// differences of the values, at states along the retreating guess perturbed at random, where many
// pairs are within the query margin.
TEST(ArmShelf, ConstraintJacobiansMatchCentralDifferences) {
  const ArmShelfProblem problem{ArmShelfScenario{}};
  const ArmShelfScenario& s = problem.scenario();
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.02);
  Eigen::VectorXd x = s.start;
  int checked = 0, near = 0;
  const std::vector<Eigen::VectorXd> guess = problem.retreat_controls();
  for (int k = 0; k < s.knots; ++k) {
    // The last knot has no control: the problem gets zero there and its du is not checked.
    const int control_columns = k + 1 < s.knots ? 7 : 0;
    Eigen::VectorXd state = x, control = Eigen::VectorXd::Zero(7);
    for (int i = 0; i < 7; ++i) state(i) += noise(rng);
    if (k + 1 < s.knots) {
      control = guess[static_cast<std::size_t>(k)];
      for (int i = 0; i < 7; ++i) control(i) += noise(rng);
    }
    const ArmShelfProblem::Constraints exact = problem.constraints(k, state, control);
    const double h = 1e-6;
    for (int column = 0; column < 7 + control_columns; ++column) {
      Eigen::VectorXd xp = state, xm = state, up = control, um = control;
      if (column < 7) {
        xp(column) += h, xm(column) -= h;
      } else {
        up(column - 7) += h, um(column - 7) -= h;
      }
      const Eigen::VectorXd numeric = (problem.constraint_values(k, xp, up).value -
                                       problem.constraint_values(k, xm, um).value) /
                                      (2 * h);
      const Eigen::VectorXd analytic = column < 7 ? Eigen::VectorXd(exact.dx.col(column))
                                                  : Eigen::VectorXd(exact.du.col(column - 7));
      for (Eigen::Index row = 0; row < numeric.size(); ++row) {
        // A row at the query margin's kink or a change of closest features within h: rare.
        if (std::abs(exact.value(row) - (s.clearance - s.query_margin)) < 1e-5) continue;
        EXPECT_NEAR(analytic(row), numeric(row), 1e-5 * (1 + std::abs(numeric(row))))
            << "knot " << k << " row " << row << " column " << column;
        ++checked;
      }
    }
    for (Eigen::Index row = 0; row < exact.value.size(); ++row) {
      near += exact.value(row) > s.clearance - s.query_margin ? 1 : 0;
    }
    if (k + 1 < s.knots) x += s.dt * guess[static_cast<std::size_t>(k)];
  }
  EXPECT_GT(near, 500);  // collision rows within the margin, with nonzero derivatives
  EXPECT_GT(checked, 20000);
}

// write_constraints into storage an earlier call left (the solver's way, which clears only the
// rows that were within the margin) gives what constraints() and constraint_values() give into
// fresh storage (cleared whole), value for value and derivative for derivative: along the guess,
// each knot's storage is handed from knot to knot (so pairs move into and out of the margin
// between calls) and alternates values-only and derivative calls, and the last knot's storage
// (another row count) is handed to the first.
TEST(ArmShelf, ConstraintsWrittenIntoUsedStorageEqualFreshOnes) {
  const ArmShelfProblem problem{ArmShelfScenario{}};
  const ArmShelfScenario& s = problem.scenario();
  const std::vector<Eigen::VectorXd> guess = problem.retreat_controls();
  std::vector<ArmShelfProblem::State> states{s.start};
  for (const Eigen::VectorXd& u : guess) states.emplace_back(states.back() + s.dt * u);
  const auto control = [&](int k) {
    return k + 1 < s.knots ? ArmShelfProblem::Control(guess[static_cast<std::size_t>(k)])
                           : ArmShelfProblem::Control::Zero();
  };
  const double far = s.clearance - s.query_margin;
  ArmShelfProblem::Constraints used;
  int left_the_margin = 0;  // rows within the margin in the storage, beyond it in the next call
  for (int round = 0; round < 3; ++round) {
    for (int k = (round == 0 ? s.knots - 1 : 0); k < s.knots; k += (round == 0 ? 1 : 3)) {
      const bool derivatives = (k + round) % 2 == 0;
      const Eigen::VectorXd before = used.value;
      problem.write_constraints(k, states[static_cast<std::size_t>(k)], control(k), derivatives,
                                used);
      const ArmShelfProblem::Constraints fresh =
          derivatives
              ? problem.constraints(k, states[static_cast<std::size_t>(k)], control(k))
              : problem.constraint_values(k, states[static_cast<std::size_t>(k)], control(k));
      ASSERT_EQ(used.value.size(), fresh.value.size()) << k;
      EXPECT_EQ(used.equalities, fresh.equalities) << k;
      EXPECT_EQ(used.value, fresh.value) << "knot " << k;
      if (derivatives) {
        EXPECT_EQ(used.dx, fresh.dx) << "knot " << k;
        EXPECT_EQ(used.du, fresh.du) << "knot " << k;
      }
      for (Eigen::Index row = 0; before.size() == used.value.size() && row < before.size(); ++row) {
        left_the_margin += before(row) > far && used.value(row) == far ? 1 : 0;
      }
    }
  }
  EXPECT_GT(left_the_margin, 50);  // the rows the reuse must clear were there
}

// The smallest signed distance at joint angles q over every pair of shapes of two link frames that
// are not excluded, and of a link (but the base, which never moves) and a board: the poses from
// dh_frames, the distances from signed_distance(), no scene.
double independent_min_distance(const ArmShelfScenario& s, const Eigen::VectorXd& q) {
  const std::vector<Transform> frames = dh_frames(s.arm, q);
  struct Placed {
    int frame;
    Shape shape;
    Pose pose;
  };
  std::vector<Placed> shapes;
  for (int f = 0; f < 9; ++f) {
    for (const BodyShape& local : s.arm.links[static_cast<std::size_t>(f)]) {
      const Transform& T = frames[static_cast<std::size_t>(f)];
      const Eigen::Quaterniond attitude = Eigen::Quaterniond(T.rotation()) *
                                          Eigen::Quaterniond(local.pose.q()(0), local.pose.q()(1),
                                                             local.pose.q()(2), local.pose.q()(3));
      shapes.push_back({f, local.shape,
                        Pose(T * local.pose.r(), Eigen::Vector4d(attitude.w(), attitude.x(),
                                                                 attitude.y(), attitude.z()))});
    }
  }
  const auto excluded = [&](int f, int g) {
    for (const auto& [a, b] : s.arm.excluded_link_pairs) {
      if ((a == f && b == g) || (a == g && b == f)) return true;
    }
    return f == g;
  };
  double smallest = INFINITY;
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    for (std::size_t j = i + 1; j < shapes.size(); ++j) {
      if (excluded(shapes[i].frame, shapes[j].frame)) continue;
      smallest = std::min(smallest, signed_distance(shapes[i].shape, shapes[i].pose,
                                                    shapes[j].shape, shapes[j].pose)
                                        .distance);
    }
    if (shapes[i].frame == 0) continue;
    for (const Body& board : s.shelf) {
      for (const BodyShape& b : board.shapes()) {
        smallest = std::min(
            smallest, signed_distance(shapes[i].shape, shapes[i].pose, b.shape, b.pose).distance);
      }
    }
  }
  return smallest;
}

TEST(ArmShelf, SolvedMotionIsCheckedIndependently) {
  const ArmShelfProblem problem{ArmShelfScenario{}};
  const ArmShelfScenario& s = problem.scenario();
  // The joint-space straight line collides (the hand through the divider), the retreating guess
  // nearly clears the shelf.
  double line = INFINITY;
  for (int k = 0; k < s.knots; ++k) {
    line = std::min(
        line, independent_min_distance(s, s.start + (s.goal - s.start) * k / (s.knots - 1.0)));
  }
  EXPECT_LT(line, -0.1);
  EXPECT_GT(independent_min_distance(s, s.start), s.clearance);
  EXPECT_GT(independent_min_distance(s, s.goal), s.clearance);

  const trajopt::AltroResult result =
      trajopt::solve(problem, s.start, problem.retreat_controls(), ArmShelfProblem::settings());
  ASSERT_EQ(result.status, trajopt::AltroStatus::kSolved);
  EXPECT_LE(result.max_violation, 1e-6);
  ASSERT_EQ(result.states.size(), static_cast<std::size_t>(s.knots));
  EXPECT_LE((result.states.front() - s.start).norm(), 1e-9);
  EXPECT_LE((result.states.back() - s.goal).norm(), 1e-6);
  double at_knots = INFINITY, between = INFINITY;
  for (std::size_t k = 0; k < result.states.size(); ++k) {
    const Eigen::VectorXd& x = result.states[k];
    for (int i = 0; i < 7; ++i) {
      EXPECT_GE(x(i), s.arm.joint_limits(i, 0) - 1e-6);
      EXPECT_LE(x(i), s.arm.joint_limits(i, 1) + 1e-6);
    }
    at_knots = std::min(at_knots, independent_min_distance(s, x));
    if (k + 1 == result.states.size()) continue;
    const Eigen::VectorXd& u = result.controls[k];
    EXPECT_LE((result.states[k + 1] - (x + s.dt * u)).norm(), 1e-9);
    EXPECT_LE((u.cwiseAbs() - s.arm.velocity_limits).maxCoeff(), 1e-6);
    for (int i = 1; i < 20; ++i) {
      between = std::min(between, independent_min_distance(s, x + (i / 20.0) * s.dt * u));
    }
  }
  std::cout << "[arm_shelf] " << result.iterations << " iterations, smallest distance at the knots "
            << at_knots << ", between them " << between << "\n";
  EXPECT_GE(at_knots, s.clearance - 1e-6);
  // Between knots (20 samples a step) the substeps keep the motion out of the boards too.
  EXPECT_GE(between, 0.0);
  EXPECT_NEAR(at_knots, arm_shelf_path_min_distance(problem, result.states, 1), 1e-12);

  // Ipopt on the same problem from the same guess: feasible, the same cost within 0.5%.
  const IpoptRun ipopt = solve_problem_with_ipopt(problem, s.start, problem.retreat_controls());
  EXPECT_TRUE(ipopt.solved) << ipopt.status;
  EXPECT_LE(ipopt.max_violation, 1e-6);
  EXPECT_NEAR(ipopt.cost, result.cost, 5e-3 * result.cost);
}

}  // namespace
}  // namespace diffpills::examples
