// The second derivatives the exact-Hessian Ipopt cross-check uses (problem.hpp): the car's and the
// quadrotor's weighted model Hessians and RK4 step Hessians (rk4.hpp, the quadrotor's
// renormalization included), and the example problems' dynamics and constraint Hessians, each
// against central differences of the exact first derivatives (lambda' A, lambda' B and mu' dc)
// on seeded random points, with kinks (a change of closest features or of the contacts within
// the arm's query margin inside the step) detected by two step sizes and skipped.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>

#include "arm_shelf/arm_shelf.hpp"
#include "car_bus/car_bus.hpp"
#include "diffpills/trajopt/car.hpp"
#include "diffpills/trajopt/dynamic_problem.hpp"
#include "diffpills/trajopt/quadrotor.hpp"
#include "ipopt/ipopt_run.hpp"
#include "quadrotor_window/quadrotor_window.hpp"

namespace diffpills::trajopt {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using Gradient = std::function<VectorXd(const VectorXd&)>;
using Rng = std::mt19937_64;

// Central differences of `gradient` at z with steps h and h / 4: false where a column disagrees
// between the two (a kink within the step).
bool differences(const Gradient& gradient, const VectorXd& z, double h, MatrixXd& out) {
  out.resize(z.size(), z.size());
  for (Eigen::Index j = 0; j < z.size(); ++j) {
    const auto column = [&](double step) {
      VectorXd plus = z, minus = z;
      plus(j) += step;
      minus(j) -= step;
      return VectorXd((gradient(plus) - gradient(minus)) / (2 * step));
    };
    const VectorXd coarse = column(h), fine = column(h / 4);
    if ((coarse - fine).cwiseAbs().maxCoeff() > 1e-5 * (1.0 + fine.cwiseAbs().maxCoeff())) {
      return false;
    }
    out.col(j) = fine;
  }
  return true;
}

// |exact - numeric| relative to the Hessian's size; exact must be symmetric.
double error_of(const MatrixXd& exact, const MatrixXd& numeric) {
  EXPECT_LE((exact - exact.transpose()).cwiseAbs().maxCoeff(),
            1e-12 * (1.0 + exact.cwiseAbs().maxCoeff()));
  return (exact - numeric).cwiseAbs().maxCoeff() / (1.0 + exact.cwiseAbs().maxCoeff());
}

VectorXd normal_vector(Rng& rng, int size, double scale = 1.0) {
  std::normal_distribution<double> normal(0.0, scale);
  VectorXd v(size);
  for (int i = 0; i < size; ++i) v(i) = normal(rng);
  return v;
}

double uniform(Rng& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

// A model's weighted_hessian and step_hessian (step h) against central differences of a' [Fx Fu]
// and a' [A B] at `trials` points (x, u, a) drawn by `draw`; the worst error of each.
template <class Model>
std::pair<double, double> check_model(
    const Model& model, double h, int trials,
    const std::function<void(int, typename Model::State&, typename Model::Control&,
                             typename Model::State&)>& draw) {
  using State = typename Model::State;
  using Control = typename Model::Control;
  constexpr int n = State::RowsAtCompileTime, m = Control::RowsAtCompileTime;
  using StateMatrix = Eigen::Matrix<double, n, n>;
  using ControlMatrix = Eigen::Matrix<double, n, m>;
  double worst_model = 0.0, worst_step = 0.0;
  for (int trial = 0; trial < trials; ++trial) {
    State x, a;
    Control u;
    draw(trial, x, u, a);
    VectorXd z(n + m);
    z << x, u;
    const auto transposed = [&a](const StateMatrix& Fx, const ControlMatrix& Fu) {
      VectorXd g(n + m);
      g << Fx.transpose() * a, Fu.transpose() * a;
      return g;
    };
    const Gradient rate = [&](const VectorXd& at) {
      State xdot;
      StateMatrix Fx;
      ControlMatrix Fu;
      model.derivative(at.head<n>(), at.tail<m>(), xdot, Fx, Fu);
      return transposed(Fx, Fu);
    };
    const Gradient step = [&](const VectorXd& at) {
      State next;
      StateMatrix A;
      ControlMatrix B;
      model.step(h, at.head<n>(), at.tail<m>(), next, A, B);
      return transposed(A, B);
    };
    MatrixXd numeric;
    EXPECT_TRUE(differences(rate, z, 1e-5, numeric)) << "trial " << trial;
    worst_model = std::max(worst_model, error_of(model.weighted_hessian(x, u, a), numeric));
    EXPECT_TRUE(differences(step, z, 1e-5, numeric)) << "trial " << trial;
    worst_step = std::max(worst_step, error_of(model.step_hessian(h, x, u, a), numeric));
  }
  return {worst_model, worst_step};
}

TEST(ModelHessian, CarMatchesDifferencesOfTheJacobians) {
  Rng rng(41);
  const auto [worst_model, worst_step] =
      check_model(Car{2.5}, 0.1, 300, [&](int, Car::State& x, Car::Control& u, Car::State& a) {
        // Steering up to 1.4 rad (tan 5.8), where the heading rate's derivatives grow fast; with
        // |u2| <= 1 and h = 0.1 the RK4 stages stay below 1.5 rad, short of tan's pole.
        x << uniform(rng, -5, 5), uniform(rng, -5, 5), uniform(rng, -M_PI, M_PI),
            uniform(rng, -5, 10), uniform(rng, -1.4, 1.4);
        u << uniform(rng, -4, 4), uniform(rng, -1, 1);
        a = normal_vector(rng, 5);
      });
  EXPECT_LE(worst_model, 1e-7);
  EXPECT_LE(worst_step, 1e-7);
  std::printf("car: worst model %.2g, worst RK4 step %.2g\n", worst_model, worst_step);
}

TEST(ModelHessian, QuadrotorMatchesDifferencesOfTheJacobians) {
  Rng rng(42);
  const auto [worst_model, worst_step] = check_model(
      Quadrotor{}, 0.06, 200,
      [&](int trial, Quadrotor::State& x, Quadrotor::Control& u, Quadrotor::State& a) {
        x = normal_vector(rng, 13);
        // Unit and non-unit quaternions: Ipopt's iterates leave the unit sphere between steps.
        x.segment<4>(3) *= std::array<double, 3>{1.0, 1.7, 0.4}[trial % 3] / x.segment<4>(3).norm();
        x.segment<3>(10) *= 3.0;  // angular velocities of a few rad/s
        u << uniform(rng, 0, 4), uniform(rng, 0, 4), uniform(rng, 0, 4), uniform(rng, 0, 4);
        a = normal_vector(rng, 13);
      });
  EXPECT_LE(worst_model, 1e-7);
  EXPECT_LE(worst_step, 1e-7);
  std::printf("quadrotor: worst model %.2g, worst RK4 step %.2g\n", worst_model, worst_step);
}

// A problem's dynamics_hessian and constraint_hessian against central differences of lambda' [A B]
// and mu' [dx du] at the given knots and points. Returns the number of knots whose constraint
// Hessian was checked and not zero.
int check_problem(const Problem& problem, const std::vector<std::pair<int, VectorXd>>& points,
                  Rng& rng, const char* name) {
  const int n = problem.state_size(), m = problem.control_size();
  int nonzero = 0, kinks = 0;
  double worst_dynamics = 0.0, worst_constraints = 0.0;
  for (const auto& point : points) {
    // Named, not a structured binding: the lambdas below capture k, which C++17 allows only for
    // a variable (clang refuses the binding; GCC accepts it as an extension).
    const int k = point.first;
    const VectorXd& z = point.second;
    const bool last = k == problem.knots() - 1;
    const VectorXd x = z.head(n), u = last ? VectorXd() : VectorXd(z.tail(m));
    const VectorXd at = last ? x : z;
    MatrixXd numeric;
    if (!last) {
      const VectorXd lambda = normal_vector(rng, n);
      const Gradient dynamics = [&](const VectorXd& p) {
        VectorXd next;
        MatrixXd A, B;
        problem.dynamics(p.head(n), p.tail(m), next, A, B);
        VectorXd g(n + m);
        g << A.transpose() * lambda, B.transpose() * lambda;
        return g;
      };
      EXPECT_TRUE(differences(dynamics, z, 1e-5, numeric)) << name << " knot " << k;
      worst_dynamics =
          std::max(worst_dynamics, error_of(problem.dynamics_hessian(x, u, lambda), numeric));
    }
    const int rows = static_cast<int>(problem.constraint_values(k, x, u).value.size());
    const VectorXd mu = normal_vector(rng, rows).cwiseAbs();
    const Gradient constraints = [&](const VectorXd& p) {
      const KnotConstraints c = problem.constraints(k, p.head(n), last ? VectorXd() : p.tail(m));
      VectorXd g(p.size());
      g.head(n) = c.dx.transpose() * mu;
      if (!last) g.tail(m) = c.du.transpose() * mu;
      return g;
    };
    if (!differences(constraints, at, 1e-6, numeric)) {
      ++kinks;
      continue;
    }
    const MatrixXd exact = problem.constraint_hessian(k, x, u, mu);
    worst_constraints = std::max(worst_constraints, error_of(exact, numeric));
    nonzero += exact.cwiseAbs().maxCoeff() > 0.0;
  }
  EXPECT_LE(worst_dynamics, 1e-6) << name;
  EXPECT_LE(worst_constraints, 1e-5) << name;
  std::printf(
      "%s: %zu points, %d at kinks, %d with curvature; worst dynamics %.2g, constraints %.2g\n",
      name, points.size(), kinks, nonzero, worst_dynamics, worst_constraints);
  return nonzero;
}

TEST(ProblemHessian, CarBus) {
  for (const examples::Clearance clearance :
       {examples::Clearance::kProximity, examples::Clearance::kSignedDistance}) {
    examples::CarBusScenario scenario;
    scenario.clearance = clearance;
    const examples::CarBusProblem problem(scenario);
    ASSERT_TRUE(problem.has_second_derivatives());
    Rng rng(43);
    std::vector<std::pair<int, VectorXd>> points;
    for (int trial = 0; trial < 200; ++trial) {
      VectorXd z(7);  // around the bus (x 6 .. 14, y -2): apart, touching and overlapping
      z << uniform(rng, 2, 18), uniform(rng, -7, 3), uniform(rng, -M_PI, M_PI), uniform(rng, -3, 8),
          uniform(rng, -0.8, 0.8), uniform(rng, -4, 4), uniform(rng, -1, 1);
      points.emplace_back(trial % 10 == 0 ? scenario.knots - 1 : trial % scenario.knots, z);
    }
    const bool phi = clearance == examples::Clearance::kProximity;
    EXPECT_GE(check_problem(DynamicProblem<5, 2>(problem), points, rng,
                            phi ? "car-bus, phi" : "car-bus, distance"),
              150);
  }
}

TEST(ProblemHessian, QuadrotorWindow) {
  for (const examples::Clearance clearance :
       {examples::Clearance::kProximity, examples::Clearance::kSignedDistance}) {
    examples::QuadrotorWindowScenario scenario;
    scenario.clearance = clearance;
    const examples::QuadrotorWindowProblem problem(scenario);
    Rng rng(44);
    std::vector<std::pair<int, VectorXd>> points;
    for (int trial = 0; trial < 100; ++trial) {
      VectorXd z = normal_vector(rng, 17, 0.5);  // near the wall (x = 3) and the poles
      z.head<3>() += Eigen::Vector3d(uniform(rng, 1, 5), 0.0, 1.5);
      z.segment<4>(3) = normal_vector(rng, 4).normalized();
      z.tail<4>() = Eigen::Vector4d::Constant(1.2) + normal_vector(rng, 4, 0.3);
      points.emplace_back(trial % 10 == 0 ? scenario.knots - 1 : trial % scenario.knots, z);
    }
    const bool phi = clearance == examples::Clearance::kProximity;
    EXPECT_GE(check_problem(DynamicProblem<13, 4>(problem), points, rng,
                            phi ? "quadrotor, phi" : "quadrotor, distance"),
              60);
  }
}

TEST(ProblemHessian, ArmShelf) {
  const examples::ArmShelfProblem problem{examples::ArmShelfScenario{}};
  const std::vector<VectorXd> guess = problem.retreat_controls();
  const std::vector<VectorXd> states = examples::rollout(problem, problem.scenario().start, guess);
  Rng rng(45);
  std::vector<std::pair<int, VectorXd>> points;
  for (int trial = 0; trial < 60; ++trial) {
    const int k = trial % problem.knots();
    VectorXd z(14);
    const bool last = k == problem.knots() - 1;
    z << states[static_cast<std::size_t>(k)] + normal_vector(rng, 7, 0.03),
        last ? VectorXd::Zero(7)
             : VectorXd(guess[static_cast<std::size_t>(k)] + normal_vector(rng, 7, 0.1));
    points.emplace_back(k, z);
  }
  EXPECT_GE(check_problem(DynamicProblem<7, 7>(problem), points, rng, "arm-shelf"), 30);
}

// Vectors of the wrong size are refused with the field named: by the fixed-size problems seen
// through DynamicProblem (which would otherwise read past them), and mu by the problems.
TEST(ProblemHessian, RefusesVectorsOfTheWrongSize) {
  const examples::CarBusProblem car_bus_problem{examples::CarBusScenario{}};
  const examples::QuadrotorWindowProblem quadrotor_problem{examples::QuadrotorWindowScenario{}};
  const examples::ArmShelfProblem arm_problem{examples::ArmShelfScenario{}};
  const DynamicProblem<5, 2> car_bus(car_bus_problem);
  const DynamicProblem<13, 4> quadrotor(quadrotor_problem);
  const DynamicProblem<7, 7> arm(arm_problem);
  const std::array<std::pair<const Problem*, VectorXd>, 3> problems = {
      std::pair{static_cast<const Problem*>(&car_bus), car_bus_problem.scenario().x0},
      std::pair{static_cast<const Problem*>(&quadrotor), quadrotor_problem.scenario().x0},
      std::pair{static_cast<const Problem*>(&arm), VectorXd(arm_problem.scenario().start)}};
  for (const auto& entry : problems) {  // valid states: a zero quaternion is refused
    const Problem* problem = entry.first;
    const VectorXd& x = entry.second;
    const int n = problem->state_size(), m = problem->control_size();
    const VectorXd u = VectorXd::Zero(m);
    const auto rows = problem->constraint_values(0, x, u).value.size();
    EXPECT_NO_THROW(problem->dynamics_hessian(x, u, VectorXd::Zero(n)));
    EXPECT_NO_THROW(problem->constraint_hessian(0, x, u, VectorXd::Zero(rows)));
    const auto message = [](const auto& call) {
      try {
        call();
      } catch (const std::invalid_argument& error) {
        return std::string(error.what());
      }
      return std::string("no exception");
    };
    EXPECT_EQ(message([&] {
                problem->dynamics_hessian(x, u, VectorXd::Zero(n - 1));
              }).rfind("lambda: expected", 0),
              0u);
    EXPECT_EQ(message([&] {
                problem->dynamics_hessian(VectorXd::Zero(n + 1), u, x);
              }).rfind("x: expected", 0),
              0u);
    EXPECT_EQ(
        message([&] { problem->constraint_hessian(0, x, u, VectorXd()); }).rfind("mu: expected", 0),
        0u);
    EXPECT_EQ(message([&] {
                problem->constraint_hessian(0, x, VectorXd(), VectorXd::Zero(rows));
              }).rfind("u: expected", 0),
              0u);
  }
}

}  // namespace
}  // namespace diffpills::trajopt
