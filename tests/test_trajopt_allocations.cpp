// The fixed-size solver's inner loops allocate nothing (issue 13): this binary counts every heap
// allocation (support/allocation_counter.hpp) and compares whole solves that differ only in how
// many iLQR iterations they run, the demo's car-bus and quadrotor problems among them. Skipped
// under AddressSanitizer (labelled no_sanitize).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <vector>

#include "car_bus/car_bus.hpp"
#include "diffpills/trajopt/altro.hpp"
#include "diffpills/trajopt/car.hpp"
#include "diffpills/trajopt/dynamic_problem.hpp"
#include "diffpills/trajopt/serial_chain.hpp"
#include "quadrotor_window/quadrotor_window.hpp"
#include "support/allocation_counter.hpp"

namespace diffpills::trajopt {
namespace {

// The kinematic car (car.hpp) driven from rest to a point 10 m ahead and 3 m aside, quadratic
// costs, no constraints: nonlinear, so iLQR takes several iterations.
class CarToAPoint : public ProblemOf<5, 2> {
 public:
  int state_size() const override { return 5; }
  int control_size() const override { return 2; }
  int knots() const override { return 41; }
  void dynamics(const State& x, const Control& u, State& next, StateMatrix& A,
                ControlMatrix& B) const override {
    car_.step(0.1, x, u, next, A, B);
  }
  Cost stage_cost(int, const State& x, const Control& u) const override {
    return {0.5 * 0.01 * (x - goal_).squaredNorm() + 0.5 * 0.1 * u.squaredNorm(),
            0.01 * (x - goal_),
            0.1 * u,
            0.01 * StateMatrix::Identity(),
            0.1 * Eigen::Matrix2d::Identity(),
            Eigen::Matrix<double, 2, 5>::Zero()};
  }
  Cost terminal_cost(const State& x) const override {
    return {0.5 * 100.0 * (x - goal_).squaredNorm(),
            100.0 * (x - goal_),
            Control::Zero(),
            100.0 * StateMatrix::Identity(),
            Eigen::Matrix2d::Zero(),
            Eigen::Matrix<double, 2, 5>::Zero()};
  }

 private:
  Car car_{2.5};
  State goal_ = (State() << 10.0, 3.0, 0.0, 0.0, 0.0).finished();
};

// CarToAPoint with its speed (state 3) held within +-3 m/s: two inequality rows per knot, each
// evaluation into fresh storage (the default write_constraints assigns what constraints returns).
class SpeedLimitedCar : public CarToAPoint {
 public:
  Constraints constraints(int, const State& x, const Control&) const override {
    Constraints rows;
    write_rows(x, rows);
    return rows;
  }

 protected:
  static void write_rows(const State& x, Constraints& rows) {
    rows.value.resize(2);
    rows.dx.setZero(2, 5);
    rows.du.setZero(2, 2);
    rows.value << x(3) - 3.0, -x(3) - 3.0;
    rows.dx(0, 3) = 1.0;
    rows.dx(1, 3) = -1.0;
    rows.equalities = 0;
  }
};

// The same rows written into the solver's storage.
class SpeedLimitedCarInPlace : public SpeedLimitedCar {
 public:
  void write_constraints(int, const State& x, const Control&, bool,
                         Constraints& out) const override {
    write_rows(x, out);
  }
};

// Allocations of one solve from x0 and the guess capped at `iterations` iLQR iterations (the
// polish, whose sparse matrices and factorization have run-time sizes, off).
template <class Problem>
long allocations_of_solve(const Problem& problem, const Eigen::VectorXd& x0,
                          const std::vector<Eigen::VectorXd>& guess, int iterations, int* ran) {
  AltroSettings settings;
  settings.max_total_iterations = iterations;
  settings.polish = false;
  const long before = testing::heap_allocations();
  const AltroResult result = solve(problem, x0, guess, settings);
  const long used = testing::heap_allocations() - before;
  *ran = result.iterations;
  return used;
}

// Where the car problems above start: from rest at the origin, zero controls.
struct CarStart {
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(5);
  std::vector<Eigen::VectorXd> guess = std::vector<Eigen::VectorXd>(40, Eigen::VectorXd::Zero(2));
};

template <class Problem>
long allocations_of_solve(const Problem& problem, int iterations, int* ran) {
  const CarStart start;
  return allocations_of_solve(problem, start.x0, start.guess, iterations, ran);
}

// One solve of 1 and one of up to 1000 iterations allocate the same; the longer one runs at least
// `least` iterations. A warm-up solve first, so that one-time allocations (the C++ runtime's, a
// lazily built table) are not counted against the first measured solve alone.
template <class Problem>
void expect_no_allocation_per_iteration(const Problem& problem, const Eigen::VectorXd& x0,
                                        const std::vector<Eigen::VectorXd>& guess, int least) {
  int short_run = 0, long_run = 0;
  allocations_of_solve(problem, x0, guess, 1000, &long_run);  // warm-up
  const long one = allocations_of_solve(problem, x0, guess, 1, &short_run);
  const long many = allocations_of_solve(problem, x0, guess, 1000, &long_run);
  ASSERT_EQ(short_run, 1);
  ASSERT_GE(long_run, least);  // the extra iterations exist
  EXPECT_EQ(many, one) << long_run << " iterations";
  std::printf("%ld allocations for 1 iteration, %ld for %d\n", one, many, long_run);
}

// The same for the car problems above.
template <class Problem>
void expect_no_allocation_per_iteration(const Problem& problem, int least) {
  const CarStart start;
  expect_no_allocation_per_iteration(problem, start.x0, start.guess, least);
}

TEST(TrajoptAllocations, FixedSizeIterationsAllocateNothing) {
  if (!testing::kCountingAllocations) GTEST_SKIP() << "AddressSanitizer owns malloc";
  const CarToAPoint problem;
  expect_no_allocation_per_iteration(problem, 5);
  // The counter sees the run-time-sized solver's per-iteration allocations: the comparison above
  // could fail.
  int short_run = 0, long_run = 0;
  const DynamicProblem<5, 2> dynamic(problem);
  const long dynamic_one = allocations_of_solve(dynamic, 1, &short_run);
  const long dynamic_many = allocations_of_solve(dynamic, 1000, &long_run);
  EXPECT_GT(dynamic_many, dynamic_one + long_run);
  std::printf("run-time sizes: %ld allocations for 1 iteration, %ld for %d\n", dynamic_one,
              dynamic_many, long_run);
}

// A problem that writes its constraint rows in place (write_constraints) makes the solver's
// iterations allocate nothing; the same rows returned fresh by constraints() allocate per sweep.
TEST(TrajoptAllocations, ConstraintsWrittenInPlaceAllocateNothingPerIteration) {
  if (!testing::kCountingAllocations) GTEST_SKIP() << "AddressSanitizer owns malloc";
  expect_no_allocation_per_iteration(SpeedLimitedCarInPlace(), 5);
  const SpeedLimitedCar fresh;
  int short_run = 0, long_run = 0;
  const long fresh_one = allocations_of_solve(fresh, 1, &short_run);
  const long fresh_many = allocations_of_solve(fresh, 1000, &long_run);
  EXPECT_GT(fresh_many, fresh_one + long_run);
}

// The demo's car-bus and quadrotor-window problems, with either clearance (phi or the signed
// distance): they write their rows in place (write_constraints), and the library's proximity and
// signed distance allocate nothing, so their iterations allocate nothing. (Before they wrote
// their rows in place, a solve allocated ~270 and ~170 times per iteration.)
TEST(TrajoptAllocations, DemoProblemsAllocateNothingPerIteration) {
  if (!testing::kCountingAllocations) GTEST_SKIP() << "AddressSanitizer owns malloc";
  for (const examples::Clearance clearance :
       {examples::Clearance::kProximity, examples::Clearance::kSignedDistance}) {
    SCOPED_TRACE(clearance == examples::Clearance::kProximity ? "phi" : "signed distance");
    examples::CarBusScenario car_bus;
    car_bus.clearance = clearance;
    const examples::CarBusProblem car{car_bus};
    expect_no_allocation_per_iteration(car, car_bus.x0, car.straight_line_controls(), 20);
    examples::QuadrotorWindowScenario window;
    window.clearance = clearance;
    const examples::QuadrotorWindowProblem quadrotor{window};
    expect_no_allocation_per_iteration(quadrotor, window.x0, quadrotor.hover_controls(), 20);
  }
}

// Posing a chain into frames that hold an earlier pose of it allocates nothing (the arm's
// constraints pose its chain ~21,000 times per solve); into fresh frames it does, so the counter
// sees these allocations.
TEST(TrajoptAllocations, ForwardKinematicsIntoUsedFramesAllocatesNothing) {
  if (!testing::kCountingAllocations) GTEST_SKIP() << "AddressSanitizer owns malloc";
  const SerialChain chain{{0.0, 0.3, 0.2}, {0.4, 0.0, 0.1}, {0.0, 1.5707963267948966, 0.0}, 0.1};
  Eigen::Vector3d q(0.1, -0.4, 0.8);
  ChainFrames frames;
  const long first = testing::heap_allocations();
  forward_kinematics(chain, q, true, frames);
  const long fresh = testing::heap_allocations() - first;
  EXPECT_GT(fresh, 0);
  const long before = testing::heap_allocations();
  for (int i = 0; i < 10; ++i) {
    q *= 1.1;
    forward_kinematics(chain, q, i % 2 == 0, frames);
  }
  EXPECT_EQ(testing::heap_allocations() - before, 0);
}

}  // namespace
}  // namespace diffpills::trajopt
