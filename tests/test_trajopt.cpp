// The trajectory optimizer: iLQR against the Riccati solution of an LQ problem, RK4 Jacobians
// against central differences, and a constrained car problem whose solution is checked knot by
// knot by independent computations.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <random>
#include <string>

#include "car_bus/car_bus.hpp"
#include "car_bus/car_bus_ipopt.hpp"
#include "diffpills/trajopt/altro.hpp"
#include "diffpills/trajopt/car.hpp"
#include "diffpills/trajopt/dynamic_problem.hpp"
#include "diffpills/trajopt/rk4.hpp"
#include "ipopt/problem_nlp.hpp"

namespace diffpills::trajopt {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// x+ = A x + B u, cost sum 1/2 x'Qx + 1/2 u'Ru + 1/2 x_N' Qf x_N, optionally with constraints;
// with the sizes fixed at compile time or not (problem.hpp).
template <int Nx, int Nu>
class LinearQuadraticOf : public ProblemOf<Nx, Nu> {
 public:
  using P = ProblemOf<Nx, Nu>;
  using typename P::Control;
  using typename P::ControlMatrix;
  using typename P::Cost;
  using typename P::State;
  using typename P::StateMatrix;

  LinearQuadraticOf(const MatrixXd& A, const MatrixXd& B, const MatrixXd& Q, const MatrixXd& R,
                    const MatrixXd& Qf, int knots)
      : A_(A), B_(B), Q_(Q), R_(R), Qf_(Qf), knots_(knots) {}
  int state_size() const override { return static_cast<int>(A_.rows()); }
  int control_size() const override { return static_cast<int>(B_.cols()); }
  int knots() const override { return knots_; }
  void dynamics(const State& x, const Control& u, State& next, StateMatrix& A,
                ControlMatrix& B) const override {
    next = A_ * x + B_ * u;
    A = A_;
    B = B_;
  }
  Cost stage_cost(int, const State& x, const Control& u) const override {
    return {0.5 * x.dot(Q_ * x) + 0.5 * u.dot(R_ * u),
            Q_ * x,
            R_ * u,
            Q_,
            R_,
            Eigen::Matrix<double, Nu, Nx>::Zero(u.size(), x.size())};
  }
  Cost terminal_cost(const State& x) const override {
    const Eigen::Index m = B_.cols();
    return {0.5 * x.dot(Qf_ * x),
            Qf_ * x,
            Control::Zero(m),
            Qf_,
            Eigen::Matrix<double, Nu, Nu>::Zero(m, m),
            Eigen::Matrix<double, Nu, Nx>::Zero(m, x.size())};
  }

 private:
  StateMatrix A_;
  ControlMatrix B_;
  StateMatrix Q_;
  Eigen::Matrix<double, Nu, Nu> R_;
  StateMatrix Qf_;
  int knots_;
};

using LinearQuadratic = LinearQuadraticOf<Eigen::Dynamic, Eigen::Dynamic>;

MatrixXd random_matrix(std::mt19937_64& rng, int rows, int cols) {
  std::normal_distribution<double> normal;
  MatrixXd m(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) m(i, j) = normal(rng);
  return m;
}

// A random discrete linear system x' = A x + B u: A near the identity, B small.
struct LinearSystem {
  MatrixXd A, B;
};
LinearSystem random_system(std::mt19937_64& rng, int n, int m) {
  LinearSystem system;  // A's entries drawn before B's
  system.A = MatrixXd::Identity(n, n) + 0.1 * random_matrix(rng, n, n);
  system.B = 0.1 * random_matrix(rng, n, m);
  return system;
}

// ALTRO on random LQ problems (4 states, 2 controls) against the Riccati recursion, written out
// here; Nx, Nu pick the solver's sizes, fixed or run-time.
template <int Nx, int Nu>
void expect_riccati_controls(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 4, m = 2, N = 30;
    const auto [A, B] = random_system(rng, n, m);
    const MatrixXd L = random_matrix(rng, n, n);
    const MatrixXd Q = L.transpose() * L + MatrixXd::Identity(n, n);
    const MatrixXd R = MatrixXd::Identity(m, m) * 0.5;
    const MatrixXd Qf = 10.0 * Q;
    const VectorXd x0 = random_matrix(rng, n, 1);
    // Riccati: P_N = Qf, K = -(R + B'PB)^-1 B'PA, P = Q + A'PA + A'PB K.
    std::vector<MatrixXd> gains(N - 1);
    MatrixXd P = Qf;
    for (int k = N - 2; k >= 0; --k) {
      gains[k] = -(R + B.transpose() * P * B).ldlt().solve(B.transpose() * P * A);
      P = Q + A.transpose() * P * A + A.transpose() * P * B * gains[k];
      P = 0.5 * (P + P.transpose());
    }
    VectorXd x = x0;
    std::vector<VectorXd> riccati(N - 1);
    for (int k = 0; k + 1 < N; ++k) {
      riccati[k] = gains[k] * x;
      x = A * x + B * riccati[k];
    }
    const LinearQuadraticOf<Nx, Nu> problem(A, B, Q, R, Qf, N);
    const AltroResult result = solve(problem, x0, std::vector<VectorXd>(N - 1, VectorXd::Zero(m)));
    ASSERT_EQ(result.status, AltroStatus::kSolved) << to_string(result.status);
    for (int k = 0; k + 1 < N; ++k) {
      ASSERT_LE((result.controls[k] - riccati[k]).norm(), 1e-6 * (1 + riccati[k].norm()))
          << "trial " << trial << " knot " << k;
    }
    EXPECT_LE(result.iterations, 5);  // LQ: one Newton step, then the convergence check
  }
}

TEST(Trajopt, UnconstrainedLinearQuadraticMatchesRiccati) {
  expect_riccati_controls<Eigen::Dynamic, Eigen::Dynamic>(7);
  expect_riccati_controls<4, 2>(7);
}

// The solver compiled for the car's sizes and the run-time-sized one (the same problem seen
// through DynamicProblem) take the same path: same status and iterations, and states that differ
// only by the rounding of products summed in another order.
TEST(Trajopt, FixedAndDynamicSizesSolveTheSame) {
  const examples::CarBusProblem problem{examples::CarBusScenario{}};
  const DynamicProblem<5, 2> dynamic(problem);
  const std::vector<VectorXd> guess = problem.straight_line_controls();
  const AltroResult fixed_result = solve(problem, problem.scenario().x0, guess);
  const AltroResult dynamic_result = solve(dynamic, problem.scenario().x0, guess);
  ASSERT_EQ(fixed_result.status, AltroStatus::kSolved);
  EXPECT_EQ(fixed_result.status, dynamic_result.status);
  EXPECT_EQ(fixed_result.iterations, dynamic_result.iterations);
  EXPECT_EQ(fixed_result.outer_iterations, dynamic_result.outer_iterations);
  EXPECT_NEAR(fixed_result.cost, dynamic_result.cost, 1e-9 * fixed_result.cost);
  for (std::size_t k = 0; k < fixed_result.states.size(); ++k) {
    EXPECT_LE((fixed_result.states[k] - dynamic_result.states[k]).norm(), 1e-7) << "knot " << k;
  }
}

// LinearQuadraticOf with equality rows that couple state and control, S x_k + T u_k = s at every
// stage knot and E x = t at the last, so that the constraint terms reach Qux in the backward pass.
template <int Nx, int Nu>
class CoupledLinearQuadraticOf : public LinearQuadraticOf<Nx, Nu> {
 public:
  using P = ProblemOf<Nx, Nu>;
  using typename P::Constraints;
  using typename P::Control;
  using typename P::State;

  CoupledLinearQuadraticOf(const LinearQuadraticOf<Nx, Nu>& base, const MatrixXd& S,
                           const MatrixXd& T, const VectorXd& s, const MatrixXd& E,
                           const VectorXd& t)
      : LinearQuadraticOf<Nx, Nu>(base), S_(S), T_(T), s_(s), E_(E), t_(t) {}
  Constraints constraints(int k, const State& x, const Control& u) const override {
    Constraints c;
    if (k + 1 < this->knots()) {
      c.value = S_ * x + T_ * u - s_;
      c.dx = S_;
      c.du = T_;
    } else {
      c.value = E_ * x - t_;
      c.dx = E_;
      c.du.setZero(E_.rows(), u.size());
    }
    c.equalities = static_cast<int>(c.value.size());
    return c;
  }

 private:
  MatrixXd S_, T_;
  VectorXd s_;
  MatrixXd E_;
  VectorXd t_;
};

// The same problem as one equality-constrained QP in z = [x_0 .. x_{N-1}, u_0 .. u_{N-2}], solved
// through its dense KKT system [H D'; D 0] [z; nu] = [0; b]: the controls.
std::vector<VectorXd> coupled_qp_controls(const MatrixXd& A, const MatrixXd& B, const MatrixXd& Q,
                                          const MatrixXd& R, const MatrixXd& Qf, const MatrixXd& S,
                                          const MatrixXd& T, const VectorXd& s, const MatrixXd& E,
                                          const VectorXd& t, const VectorXd& x0, int N) {
  const Eigen::Index n = A.rows(), m = B.cols(), p = S.rows(), q = E.rows();
  const Eigen::Index variables = N * n + (N - 1) * m;
  const Eigen::Index rows = N * n + (N - 1) * p + q;
  const auto xi = [&](int k) { return k * n; };
  const auto ui = [&](int k) { return N * n + k * m; };
  MatrixXd H = MatrixXd::Zero(variables, variables);
  MatrixXd D = MatrixXd::Zero(rows, variables);
  VectorXd b = VectorXd::Zero(rows);
  for (int k = 0; k + 1 < N; ++k) {
    H.block(xi(k), xi(k), n, n) = Q;
    H.block(ui(k), ui(k), m, m) = R;
  }
  H.block(xi(N - 1), xi(N - 1), n, n) = Qf;
  Eigen::Index row = 0;
  D.block(row, xi(0), n, n).setIdentity();
  b.segment(row, n) = x0;
  row += n;
  for (int k = 0; k + 1 < N; ++k, row += n) {  // x_{k+1} - A x_k - B u_k = 0
    D.block(row, xi(k + 1), n, n).setIdentity();
    D.block(row, xi(k), n, n) = -A;
    D.block(row, ui(k), n, m) = -B;
  }
  for (int k = 0; k + 1 < N; ++k, row += p) {
    D.block(row, xi(k), p, n) = S;
    D.block(row, ui(k), p, m) = T;
    b.segment(row, p) = s;
  }
  D.block(row, xi(N - 1), q, n) = E;
  b.segment(row, q) = t;
  MatrixXd kkt = MatrixXd::Zero(variables + rows, variables + rows);
  kkt.topLeftCorner(variables, variables) = H;
  kkt.topRightCorner(variables, rows) = D.transpose();
  kkt.bottomLeftCorner(rows, variables) = D;
  VectorXd rhs = VectorXd::Zero(variables + rows);
  rhs.tail(rows) = b;
  const VectorXd z = kkt.fullPivLu().solve(rhs);
  std::vector<VectorXd> controls(N - 1);
  for (int k = 0; k + 1 < N; ++k) controls[k] = z.segment(ui(k), m);
  return controls;
}

// ALTRO on random LQ problems with coupled equalities against the KKT solution. The augmented
// Lagrangian is exactly quadratic for fixed multipliers, so with exact Q terms (the constraint
// rows' C_u' mu C_x in Qux included) each inner solve is one Newton step and a convergence check.
template <int Nx, int Nu>
void expect_coupled_qp_controls(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  for (int trial = 0; trial < 10; ++trial) {
    const int n = 4, m = 2, N = 20;
    const auto [A, B] = random_system(rng, n, m);
    const MatrixXd Q = MatrixXd::Identity(n, n);
    const MatrixXd R = 0.5 * MatrixXd::Identity(m, m);
    const MatrixXd Qf = 10.0 * Q;
    const MatrixXd S = random_matrix(rng, 1, n), T = random_matrix(rng, 1, m);
    const VectorXd s = random_matrix(rng, 1, 1), t = random_matrix(rng, 1, 1);
    const MatrixXd E = random_matrix(rng, 1, n);
    const VectorXd x0 = random_matrix(rng, n, 1);
    const CoupledLinearQuadraticOf<Nx, Nu> problem(LinearQuadraticOf<Nx, Nu>(A, B, Q, R, Qf, N), S,
                                                   T, s, E, t);
    const AltroResult result = solve(problem, x0, std::vector<VectorXd>(N - 1, VectorXd::Zero(m)));
    ASSERT_EQ(result.status, AltroStatus::kSolved) << to_string(result.status);
    const std::vector<VectorXd> reference =
        coupled_qp_controls(A, B, Q, R, Qf, S, T, s, E, t, x0, N);
    for (int k = 0; k + 1 < N; ++k) {
      ASSERT_LE((result.controls[k] - reference[k]).norm(), 1e-5 * (1 + reference[k].norm()))
          << "trial " << trial << " knot " << k;
    }
    EXPECT_LE(result.iterations, 2 * result.outer_iterations) << "trial " << trial;
  }
}

TEST(Trajopt, CoupledEqualitiesMatchTheKktSolution) {
  expect_coupled_qp_controls<Eigen::Dynamic, Eigen::Dynamic>(11);
  expect_coupled_qp_controls<4, 2>(11);
}

// A problem whose constraints break problem.hpp's rules is refused by name instead of being read
// past: derivative rows that do not match the values (dx, or du at a stage knot, at either kind
// of size), a row count that changes between calls, and an equality count outside [0, rows].
enum class Flaw { kShortDx, kShortStageDu, kGrowingRows, kTooManyEqualities, kNegativeEqualities };

template <int Nx, int Nu>
class FlawedOf : public LinearQuadraticOf<Nx, Nu> {
 public:
  using P = ProblemOf<Nx, Nu>;
  using typename P::Constraints;
  using typename P::Control;
  using typename P::State;

  explicit FlawedOf(Flaw flaw)
      : LinearQuadraticOf<Nx, Nu>(MatrixXd::Identity(2, 2), MatrixXd::Identity(2, 1),
                                  MatrixXd::Identity(2, 2), MatrixXd::Identity(1, 1),
                                  MatrixXd::Identity(2, 2), 4),
        flaw_(flaw) {}
  Constraints constraints(int k, const State& x, const Control& u) const override {
    ++calls_;
    const bool stage = k + 1 < this->knots();
    Eigen::Index rows = 2;
    if (flaw_ == Flaw::kGrowingRows && calls_ > 4) rows = 3;  // after the first call per knot
    Constraints c;
    c.value = VectorXd::Constant(rows, -1.0);
    c.dx.setZero(flaw_ == Flaw::kShortDx ? rows - 1 : rows, x.size());
    c.du.setZero(flaw_ == Flaw::kShortStageDu && stage ? rows - 1 : rows, u.size());
    c.equalities = flaw_ == Flaw::kTooManyEqualities    ? 3
                   : flaw_ == Flaw::kNegativeEqualities ? -1
                                                        : 0;
    return c;
  }

 private:
  Flaw flaw_;
  mutable int calls_ = 0;
};

template <int Nx, int Nu>
void expect_refused(Flaw flaw, const std::string& message) {
  const FlawedOf<Nx, Nu> problem(flaw);
  try {
    solve(problem, VectorXd::Ones(2), std::vector<VectorXd>(3, VectorXd::Zero(1)));
    ADD_FAILURE() << message << ": no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(error.what(), message);
  }
}

TEST(Trajopt, RefusesConstraintsThatBreakTheRowRules) {
  const std::string knot0 = "trajopt: constraints(0) returned 2 values ";
  const std::string dx_short =
      knot0 + "(0 equalities) with a 1 x 2 dx and a 2 x 1 du: dx must be 2 x 2";
  const std::string du_short =
      knot0 + "(0 equalities) with a 2 x 2 dx and a 1 x 1 du: du must be 2 x 1";
  expect_refused<Eigen::Dynamic, Eigen::Dynamic>(Flaw::kShortDx, dx_short);
  expect_refused<2, 1>(Flaw::kShortDx, dx_short);
  expect_refused<Eigen::Dynamic, Eigen::Dynamic>(Flaw::kShortStageDu, du_short);
  expect_refused<2, 1>(Flaw::kShortStageDu, du_short);
  expect_refused<2, 1>(Flaw::kGrowingRows,
                       "trajopt: constraints(0) returned 3 values (0 equalities) with a 3 x 2 dx "
                       "and a 3 x 1 du: the knot has 2 rows, its first call's count");
  expect_refused<Eigen::Dynamic, Eigen::Dynamic>(
      Flaw::kTooManyEqualities,
      knot0 + "(3 equalities) with a 2 x 2 dx and a 2 x 1 du: equalities must lie in [0, rows]");
  expect_refused<2, 1>(
      Flaw::kNegativeEqualities,
      knot0 + "(-1 equalities) with a 2 x 2 dx and a 2 x 1 du: equalities must lie in [0, rows]");
}

// constraint_values is read where no derivatives follow: the polish's trial steps (the line search
// evaluates constraints). Values with more rows than the knot's are refused there too.
// CarBusProblem writes its rows in place, so a class changing constraint_values takes the default
// write_constraints back (problem.hpp).
class CarBusWithExtraValues : public examples::CarBusProblem {
 public:
  using CarBusProblem::CarBusProblem;
  Constraints constraint_values(int k, const State& x, const Control& u) const override {
    Constraints c = CarBusProblem::constraint_values(k, x, u);
    c.value.conservativeResize(c.value.size() + 3);
    c.value.tail(3).setConstant(-1.0);
    return c;
  }
  void write_constraints(int k, const State& x, const Control& u, bool derivatives,
                         Constraints& out) const override {
    // The default, skipping CarBusProblem's in-place rows on purpose.
    // NOLINTNEXTLINE(bugprone-parent-virtual-call)
    ProblemOf<5, 2>::write_constraints(k, x, u, derivatives, out);
  }
};

TEST(Trajopt, RefusesExtraConstraintValuesInThePolish) {
  const CarBusWithExtraValues problem{examples::CarBusScenario{}};
  const examples::CarBusScenario& s = problem.scenario();
  const auto c = problem.constraints(0, s.x0, examples::CarBusProblem::Control::Zero());
  const std::string rows = std::to_string(c.value.size());
  AltroSettings loose;  // stops with a violation left for the polish (see the polish test)
  loose.constraint_tolerance = 1e-3;
  try {
    solve(problem, s.x0, problem.straight_line_controls(), loose);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(error.what(), "trajopt: constraint_values(0) returned " +
                                std::to_string(c.value.size() + 3) + " values (" +
                                std::to_string(c.equalities) + " equalities): the knot has " +
                                rows + " rows, its first call's count");
  }
}

// rows_written_by (problem.hpp): a problem that writes its rows in place and answers
// constraints() and constraint_values() with them. Rows: x <= 1 entry by entry.
class InPlaceBound : public LinearQuadratic {
 public:
  using LinearQuadratic::LinearQuadratic;
  Constraints constraints(int k, const State& x, const Control& u) const override {
    return rows_written_by<InPlaceBound>(*this, k, x, u, true);
  }
  Constraints constraint_values(int k, const State& x, const Control& u) const override {
    return rows_written_by<InPlaceBound>(*this, k, x, u, false);
  }
  void write_constraints(int, const State& x, const Control& u, bool derivatives,
                         Constraints& out) const override {
    out.value = x.array() - 1.0;
    out.equalities = 0;
    if (derivatives) {
      out.dx = MatrixXd::Identity(x.size(), x.size());
      out.du = MatrixXd::Zero(x.size(), u.size());
    }
  }
};

// ... and a class derived from it that takes the default write_constraints back, which calls
// constraints() and constraint_values(): they must reach InPlaceBound's rows, not recurse (a
// virtual call there would end this test in a stack overflow, which ctest reports as a failure).
class InPlaceBoundDefaultWriter : public InPlaceBound {
 public:
  using InPlaceBound::InPlaceBound;
  void write_constraints(int k, const State& x, const Control& u, bool derivatives,
                         Constraints& out) const override {
    // NOLINTNEXTLINE(bugprone-parent-virtual-call): the default, on purpose
    Problem::write_constraints(k, x, u, derivatives, out);
  }
};

TEST(Trajopt, RowsWrittenByReturnTheClassOwnRows) {
  const MatrixXd A = (MatrixXd(2, 2) << 1.0, 0.1, 0.0, 1.0).finished();
  const MatrixXd B = (MatrixXd(2, 1) << 0.0, 0.1).finished();
  const MatrixXd I = MatrixXd::Identity(2, 2);
  const InPlaceBound bound(A, B, I, 0.01 * MatrixXd::Identity(1, 1), 100.0 * I, 21);
  const InPlaceBoundDefaultWriter derived(A, B, I, 0.01 * MatrixXd::Identity(1, 1), 100.0 * I, 21);
  const VectorXd x = (VectorXd(2) << 0.25, 3.0).finished();
  const VectorXd u = VectorXd::Constant(1, 0.5);
  for (const Problem* problem :
       {static_cast<const Problem*>(&bound), static_cast<const Problem*>(&derived)}) {
    const KnotConstraints rows = problem->constraints(3, x, u);
    ASSERT_EQ(rows.value.size(), 2);
    ASSERT_EQ(rows.dx.rows(), 2);
    ASSERT_EQ(rows.dx.cols(), 2);
    ASSERT_EQ(rows.du.rows(), 2);
    ASSERT_EQ(rows.du.cols(), 1);
    EXPECT_EQ(rows.value, (VectorXd(2) << -0.75, 2.0).finished());
    EXPECT_EQ(rows.dx, I);
    EXPECT_EQ(rows.du, MatrixXd::Zero(2, 1));
    EXPECT_EQ(rows.equalities, 0);
    // Values only: written without derivatives into fresh storage, so dx and du stay empty.
    const KnotConstraints values = problem->constraint_values(3, x, u);
    ASSERT_EQ(values.value.size(), 2);
    EXPECT_EQ(values.value, rows.value);
    EXPECT_EQ(values.equalities, 0);
    EXPECT_EQ(values.dx.size(), 0);
    EXPECT_EQ(values.du.size(), 0);
  }
  // From x0 = (-3, 0.5) towards the origin in 2 s, the speed bound x_1 <= 1 binds; both solve it
  // alike, through write_constraints or through the default's two calls.
  const VectorXd x0 = (VectorXd(2) << -3.0, 0.5).finished();
  const std::vector<VectorXd> guess(20, VectorXd::Zero(1));
  const AltroResult in_place = solve(bound, x0, guess);
  const AltroResult by_default = solve(derived, x0, guess);
  ASSERT_EQ(in_place.status, AltroStatus::kSolved);
  ASSERT_EQ(by_default.status, AltroStatus::kSolved);
  EXPECT_LE(in_place.max_violation, 1e-9);
  double fastest = 0.0;
  for (int k = 0; k < 21; ++k) {
    EXPECT_EQ(by_default.states[k], in_place.states[k]) << "knot " << k;
    EXPECT_LE(in_place.states[k].maxCoeff(), 1.0 + 1e-9) << "knot " << k;
    fastest = std::max(fastest, in_place.states[k](1));
  }
  EXPECT_GT(fastest, 1.0 - 1e-6);  // the bound binds
}

// Settings out of range are refused by name, before any work.
TEST(Trajopt, RefusesSettingsOutOfRange) {
  const LinearQuadratic problem(MatrixXd::Identity(2, 2), MatrixXd::Identity(2, 1),
                                MatrixXd::Identity(2, 2), MatrixXd::Identity(1, 1),
                                MatrixXd::Identity(2, 2), 6);
  const std::vector<VectorXd> guess(5, VectorXd::Zero(1));
  const auto message = [&](const AltroSettings& settings) -> std::string {
    try {
      solve(problem, VectorXd::Ones(2), guess, settings);
    } catch (const std::invalid_argument& error) {
      return error.what();
    }
    return "no exception";
  };
  AltroSettings settings;
  settings.penalty_initial = 0.0;
  EXPECT_EQ(message(settings),
            "trajopt: AltroSettings::penalty_initial must be finite and positive");
  settings = {};
  settings.regularization_initial = std::nan("");
  EXPECT_EQ(message(settings),
            "trajopt: AltroSettings::regularization_initial must be finite and positive");
  settings = {};
  settings.penalty_scaling = 0.5;
  EXPECT_EQ(message(settings),
            "trajopt: AltroSettings::penalty_scaling must be finite and at least 1");
  settings = {};
  settings.constraint_tolerance = std::nan("");
  EXPECT_EQ(message(settings),
            "trajopt: AltroSettings::constraint_tolerance must be zero or more (not NaN)");
  settings = {};
  settings.line_search_lower = 20.0;
  EXPECT_EQ(message(settings),
            "trajopt: AltroSettings::line_search_lower must be in [0, line_search_upper]");
  EXPECT_EQ(solve(problem, VectorXd::Ones(2), guess).status, AltroStatus::kSolved);
}

// NaN or infinity from the problem ends the solve as kNonFinite, never as kSolved: before the
// check, a NaN gradient gave NaN steps that std::max read as zero, "converged". A non-finite x0
// is refused.
enum class Poison { kNone, kGradient, kHessian, kConstraintValue, kDynamics, kSatisfiedMinusInf };

class PoisonedLinearQuadratic : public LinearQuadratic {
 public:
  explicit PoisonedLinearQuadratic(Poison poison)
      : LinearQuadratic(MatrixXd::Identity(2, 2), MatrixXd::Identity(2, 1),
                        MatrixXd::Identity(2, 2), MatrixXd::Identity(1, 1),
                        MatrixXd::Identity(2, 2), 6),
        poison_(poison) {}
  CostExpansion stage_cost(int k, const VectorXd& x, const VectorXd& u) const override {
    CostExpansion l = LinearQuadratic::stage_cost(k, x, u);
    if (poison_ == Poison::kGradient && k == 2) l.u(0) = std::nan("");
    if (poison_ == Poison::kHessian && k == 2) l.uu(0, 0) = -HUGE_VAL;
    return l;
  }
  KnotConstraints constraints(int k, const VectorXd& x, const VectorXd& u) const override {
    KnotConstraints c;
    c.value = VectorXd::Constant(
        1, poison_ == Poison::kConstraintValue && k == 3 ? std::nan("") : x(0) - 10.0);
    if (poison_ == Poison::kSatisfiedMinusInf && k == 3) c.value(0) = -HUGE_VAL;
    c.dx = MatrixXd::Zero(1, x.size());
    c.dx(0, 0) = 1.0;
    c.du = MatrixXd::Zero(1, u.size());
    return c;
  }
  void dynamics(const VectorXd& x, const VectorXd& u, VectorXd& next, MatrixXd& A,
                MatrixXd& B) const override {
    LinearQuadratic::dynamics(x, u, next, A, B);
    if (poison_ == Poison::kDynamics && x(1) > 0.5) next(1) = HUGE_VAL;
  }

 private:
  Poison poison_;
};

TEST(Trajopt, NonFiniteProblemValuesAreNotSolved) {
  const std::vector<VectorXd> guess(5, VectorXd::Zero(1));
  for (const Poison poison :
       {Poison::kGradient, Poison::kHessian, Poison::kConstraintValue, Poison::kDynamics}) {
    const PoisonedLinearQuadratic problem(poison);
    const AltroResult result = solve(problem, VectorXd::Ones(2), guess);
    EXPECT_EQ(result.status, AltroStatus::kNonFinite)
        << static_cast<int>(poison) << ": " << to_string(result.status);
    // At once, without growing the regularization to its cap first (-inf made the factorization
    // fail: 79 iterations before the check).
    EXPECT_LE(result.iterations, 1) << static_cast<int>(poison);
    if (poison == Poison::kConstraintValue || poison == Poison::kDynamics) {
      EXPECT_FALSE(std::isfinite(result.max_violation)) << static_cast<int>(poison);
    }
  }
  // The same problem without poison solves: the statuses above come from the NaN. So does one
  // whose inequality is -inf, satisfied, at a knot: the row carries no weight and no multiplier
  // and contributes nothing (0 * -inf would be NaN).
  for (const Poison poison : {Poison::kNone, Poison::kSatisfiedMinusInf}) {
    const AltroResult result = solve(PoisonedLinearQuadratic(poison), VectorXd::Ones(2), guess);
    EXPECT_EQ(result.status, AltroStatus::kSolved) << static_cast<int>(poison);
    EXPECT_LE(result.max_violation, 1e-6);
  }
  const PoisonedLinearQuadratic clean(Poison::kNone);
  VectorXd x0 = VectorXd::Ones(2);
  x0(1) = std::nan("");
  EXPECT_THROW(solve(clean, x0, guess), std::invalid_argument);
}

TEST(Trajopt, Rk4JacobiansMatchCentralDifferences) {
  const Car car{2.5};
  std::mt19937_64 rng(8);
  const auto step = [&](const Car::State& x, const Car::Control& u) {
    Car::State next;
    Eigen::Matrix<double, 5, 5> A;
    Eigen::Matrix<double, 5, 2> B;
    car.step(0.1, x, u, next, A, B);
    return next;
  };
  for (int trial = 0; trial < 200; ++trial) {
    const Car::State x = random_matrix(rng, 5, 1) * 0.5;
    const Car::Control u = random_matrix(rng, 2, 1);
    Car::State next;
    Eigen::Matrix<double, 5, 5> A;
    Eigen::Matrix<double, 5, 2> B;
    car.step(0.1, x, u, next, A, B);
    for (int j = 0; j < 5; ++j) {
      Car::State plus = x, minus = x;
      plus(j) += 1e-6;
      minus(j) -= 1e-6;
      EXPECT_LE(((step(plus, u) - step(minus, u)) / 2e-6 - A.col(j)).norm(), 1e-8);
    }
    for (int j = 0; j < 2; ++j) {
      Car::Control plus = u, minus = u;
      plus(j) += 1e-6;
      minus(j) -= 1e-6;
      EXPECT_LE(((step(x, plus) - step(x, minus)) / 2e-6 - B.col(j)).norm(), 1e-8);
    }
  }
}

// The collision constraint's gradient with respect to the car's state (phi's pose gradient
// chained through r = (px, py, 0), q = rotation by theta about z) against central differences.
TEST(Trajopt, CarBusPhiGradientMatchesCentralDifferences) {
  const examples::CarBusScenario s;
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> box(-1.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 500; ++trial) {
    VectorXd x(5);
    x << 10.0 + 8.0 * box(rng), -2.0 + 4.0 * box(rng), M_PI * box(rng), box(rng), box(rng);
    VectorXd gradient;
    examples::car_bus_phi(s, x, &gradient);
    VectorXd fd(5);
    for (int j = 0; j < 5; ++j) {
      VectorXd plus = x, minus = x;
      plus(j) += 1e-6;
      minus(j) -= 1e-6;
      fd(j) = (examples::car_bus_phi(s, plus) - examples::car_bus_phi(s, minus)) / 2e-6;
    }
    if (examples::car_bus_phi(s, x) <
        -(s.car.radius() + s.bus.radius()) * (s.car.radius() + s.bus.radius()) + 1e-9) {
      continue;  // cores intersect: phi is flat there
    }
    EXPECT_LE((gradient - fd).norm(), 1e-6 * (1.0 + fd.norm())) << "trial " << trial;
    ++checked;
  }
  EXPECT_GT(checked, 300);
}

// The signed distance as the clearance: its state gradient against central differences, apart
// and overlapping, skipping only points within the step of a kink (a change of the nearest facet
// or closest feature, where the one-sided gradient is documented). The car and the bus lie in one
// plane, so where their cores cross the cores' Minkowski difference is flat and the signed
// distance is -(R1 + R2) with no slope in the plane, like phi (signed_distance.hpp): the 3-D
// measure can leave in z. Those states count as checked too (both sides are flat).
TEST(Trajopt, CarBusSignedDistanceGradientMatchesCentralDifferences) {
  examples::CarBusScenario s;
  s.clearance = examples::Clearance::kSignedDistance;
  std::mt19937_64 rng(10);
  std::uniform_real_distribution<double> box(-1.0, 1.0);
  int checked = 0, overlapping = 0;
  for (int trial = 0; trial < 500; ++trial) {
    // Half the states near the bus's axis, where the shapes overlap.
    const double spread = trial % 2 == 0 ? 4.0 : 0.5;
    VectorXd x(5);
    x << 10.0 + 8.0 * box(rng), -2.0 + spread * box(rng), M_PI * box(rng), box(rng), box(rng);
    VectorXd gradient;
    const double value = examples::car_bus_clearance(s, x, &gradient);
    VectorXd fd(5), forward(5), backward(5);
    for (int j = 0; j < 5; ++j) {
      VectorXd plus = x, minus = x;
      plus(j) += 1e-6;
      minus(j) -= 1e-6;
      const double up = examples::car_bus_clearance(s, plus);
      const double down = examples::car_bus_clearance(s, minus);
      fd(j) = (up - down) / 2e-6;
      forward(j) = (up - value) / 1e-6;
      backward(j) = (value - down) / 1e-6;
    }
    if ((forward - backward).norm() > 1e-4 * (1.0 + fd.norm())) continue;  // a kink
    EXPECT_LE((gradient - fd).norm(), 1e-6 * (1.0 + fd.norm())) << "trial " << trial;
    ++checked;
    if (value < 0.0) ++overlapping;
  }
  EXPECT_GT(checked, 400);
  EXPECT_GT(overlapping, 50);
}

// The same problem with the signed distance as the clearance, from the same colliding straight
// line: solved, and every knot clear of the bus by the library's signed distance and proximity
// (recomputed here, not read from the solver).
TEST(Trajopt, CarPassesTheBusWithTheSignedDistance) {
  examples::CarBusScenario scenario;
  scenario.clearance = examples::Clearance::kSignedDistance;
  const examples::CarBusProblem problem{scenario};
  const examples::CarBusScenario& s = problem.scenario();
  const AltroResult result = solve(problem, s.x0, problem.straight_line_controls());
  ASSERT_EQ(result.status, AltroStatus::kSolved) << to_string(result.status);
  EXPECT_LE(result.max_violation, 1e-6);
  for (int k = 0; k < s.knots; ++k) {
    const Pose pose = examples::car_pose(result.states[k]);
    EXPECT_GE(signed_distance(s.car, pose, s.bus, s.bus_pose).distance, -1e-6) << "knot " << k;
    EXPECT_GE(proximity(s.car, pose, s.bus, s.bus_pose).phi, -1e-5) << "knot " << k;
  }
  EXPECT_LE((result.states.back().head<3>() - s.goal.head<3>()).cwiseAbs().maxCoeff(), 1e-6);
}

// The projected-Newton polish on its own: stop the augmented Lagrangian at a loose tolerance, and
// the polish must bring every constraint, dynamics included, to 1e-9 (checked independently).
TEST(Trajopt, ProjectedNewtonPolishFinishesFeasibility) {
  const examples::CarBusProblem problem{examples::CarBusScenario{}};
  const examples::CarBusScenario& s = problem.scenario();
  AltroSettings loose;
  loose.constraint_tolerance = 1e-3;
  loose.polish = false;
  const AltroResult rough = solve(problem, s.x0, problem.straight_line_controls(), loose);
  ASSERT_EQ(rough.status, AltroStatus::kSolved);
  loose.polish = true;
  const AltroResult polished = solve(problem, s.x0, problem.straight_line_controls(), loose);
  ASSERT_EQ(polished.status, AltroStatus::kSolved);
  EXPECT_GT(polished.polish_iterations, 0);
  EXPECT_GT(rough.max_violation, 1e-8);  // there was something left to polish
  EXPECT_LE(polished.max_violation, 1e-9);
  double worst = 0.0;
  for (int k = 0; k < s.knots; ++k) {
    const VectorXd& x = polished.states[k];
    worst = std::max(worst, -proximity(s.car, examples::car_pose(x), s.bus, s.bus_pose).phi);
    if (k + 1 < s.knots) {
      examples::CarBusProblem::State next;
      examples::CarBusProblem::StateMatrix A;
      examples::CarBusProblem::ControlMatrix B;
      problem.dynamics(x, polished.controls[k], next, A, B);
      worst = std::max(worst, (next - polished.states[k + 1]).lpNorm<Eigen::Infinity>());
      worst = std::max(worst, (polished.controls[k].cwiseAbs() - s.control_limit).maxCoeff());
    }
  }
  worst = std::max(worst,
                   (polished.states.back().head<3>() - s.goal.head<3>()).lpNorm<Eigen::Infinity>());
  EXPECT_LE(worst, 1e-9);
  std::cout << "[polish] violation " << rough.max_violation << " -> " << polished.max_violation
            << " in " << polished.polish_iterations << " steps\n";
}

// The car-bus scene: the straight-line guess drives through the bus; the solution must satisfy
// every constraint, checked here independently of the solver: phi recomputed from the library at
// each state, the control limits, the goal, and the states re-integrated by a separate RK4.
TEST(Trajopt, CarPassesTheBusAndReachesTheGoal) {
  const examples::CarBusProblem problem{examples::CarBusScenario{}};
  const examples::CarBusScenario& s = problem.scenario();
  const std::vector<VectorXd> guess = problem.straight_line_controls();
  VectorXd x = s.x0;
  double guess_min_phi = examples::car_bus_phi(s, x);
  for (const VectorXd& u : guess) {
    examples::CarBusProblem::State next;
    examples::CarBusProblem::StateMatrix A;
    examples::CarBusProblem::ControlMatrix B;
    problem.dynamics(x, u, next, A, B);
    x = next;
    guess_min_phi = std::min(guess_min_phi, examples::car_bus_phi(s, x));
  }
  EXPECT_LT(guess_min_phi, 0.0);  // the straight line collides

  const AltroResult result = solve(problem, s.x0, guess);
  ASSERT_EQ(result.status, AltroStatus::kSolved) << to_string(result.status);
  EXPECT_LE(result.max_violation, 1e-6);
  const auto car_rate = [&](const VectorXd& state, const VectorXd& u) {  // written out again
    VectorXd rate(5);
    rate << state(3) * std::cos(state(2)), state(3) * std::sin(state(2)),
        state(3) * std::tan(state(4)) / s.car_model.wheelbase, u(0), u(1);
    return rate;
  };
  for (int k = 0; k < s.knots; ++k) {
    const VectorXd& xk = result.states[k];
    const Proximity p = proximity(s.car, examples::car_pose(xk), s.bus, s.bus_pose);
    EXPECT_GE(p.phi, -1e-6) << "knot " << k;
    if (k + 1 < s.knots) {
      const VectorXd& u = result.controls[k];
      EXPECT_LE(u.cwiseAbs()(0), s.control_limit(0) + 1e-6);
      EXPECT_LE(u.cwiseAbs()(1), s.control_limit(1) + 1e-6);
      const VectorXd k1 = car_rate(xk, u), k2 = car_rate(xk + 0.5 * s.dt * k1, u),
                     k3 = car_rate(xk + 0.5 * s.dt * k2, u), k4 = car_rate(xk + s.dt * k3, u);
      const VectorXd next = xk + s.dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
      EXPECT_LE((next - result.states[k + 1]).norm(), 1e-12) << "knot " << k;
    }
  }
  EXPECT_LE((result.states.back().head<3>() - s.goal.head<3>()).cwiseAbs().maxCoeff(), 1e-6);
  // Ipopt on the same NLP from the same guess, with either Hessian, and the generic NLP of any
  // Problem (problem_nlp.hpp) with either: feasible, and the same cost within 1%.
  for (const examples::IpoptHessian hessian :
       {examples::IpoptHessian::kLimitedMemory, examples::IpoptHessian::kExact}) {
    for (const bool generic : {false, true}) {
      const examples::IpoptRun ipopt =
          generic ? examples::solve_problem_with_ipopt(problem, s.x0, guess, hessian)
                  : examples::solve_with_ipopt(problem, guess, hessian);
      const std::string name =
          std::string(examples::to_string(hessian)) + (generic ? ", generic NLP" : ", car-bus NLP");
      ASSERT_TRUE(ipopt.solved) << ipopt.status << " " << name;
      EXPECT_EQ(ipopt.hessian, hessian);
      EXPECT_LE(ipopt.max_violation, 1e-6) << name;
      for (const VectorXd& xk : ipopt.states) {
        EXPECT_GE(proximity(s.car, examples::car_pose(xk), s.bus, s.bus_pose).phi, -1e-6) << name;
      }
      EXPECT_LE(std::abs(ipopt.cost - result.cost), 0.01 * std::abs(ipopt.cost)) << name;
      std::cout << "[car-bus] Ipopt (" << name << "): " << ipopt.iterations << " iterations, cost "
                << ipopt.cost << ", ALTRO cost " << result.cost << "\n";
    }
  }
  std::cout << "[car-bus] iterations " << result.iterations << " (outer " << result.outer_iterations
            << "), cost " << result.cost << ", max violation " << result.max_violation
            << ", straight-line guess min phi " << guess_min_phi << "\n";
}

// The exact-Hessian Ipopt needs a problem's second derivatives: without them it refuses (the
// default dynamics_hessian and constraint_hessian throw std::logic_error if called anyway).
TEST(Ipopt, ExactHessianNeedsSecondDerivatives) {
  const LinearQuadratic problem(MatrixXd::Identity(1, 1), MatrixXd::Identity(1, 1),
                                MatrixXd::Identity(1, 1), MatrixXd::Identity(1, 1),
                                MatrixXd::Identity(1, 1), 3);
  EXPECT_FALSE(problem.has_second_derivatives());
  const std::vector<VectorXd> guess(2, VectorXd::Zero(1));
  EXPECT_THROW(examples::solve_problem_with_ipopt(problem, VectorXd::Ones(1), guess,
                                                  examples::IpoptHessian::kExact),
               std::invalid_argument);
  EXPECT_THROW(problem.dynamics_hessian(VectorXd::Zero(1), VectorXd::Zero(1), VectorXd::Zero(1)),
               std::logic_error);
  EXPECT_THROW(problem.constraint_hessian(0, VectorXd::Zero(1), VectorXd::Zero(1), VectorXd()),
               std::logic_error);
  // The limited-memory Hessian needs none.
  EXPECT_TRUE(examples::solve_problem_with_ipopt(problem, VectorXd::Ones(1), guess).solved);
}

// A run says what stopped it, by Ipopt's return code (IpReturnCodes_inc.h's values).
TEST(Ipopt, StatusNamesWhatStoppedTheRun) {
  EXPECT_EQ(examples::ipopt_status_text(0), "solved");
  EXPECT_EQ(examples::ipopt_status_text(1), "acceptable point (1)");
  EXPECT_EQ(examples::ipopt_status_text(2), "locally infeasible (2)");
  EXPECT_EQ(examples::ipopt_status_text(-1), "iteration limit (-1)");
  EXPECT_EQ(examples::ipopt_status_text(-4), "time limit (-4)");
  EXPECT_EQ(examples::ipopt_status_text(-199), "stopped (-199)");
}

// The demo's limit on a run's CPU time stops Ipopt and is reported; a limit that is not positive
// is refused (Ipopt would ignore it and run unlimited).
TEST(Ipopt, CpuTimeLimitStopsTheRun) {
  const examples::CarBusProblem problem{examples::CarBusScenario{}};
  const std::vector<VectorXd> guess = problem.straight_line_controls();
  const VectorXd& x0 = problem.scenario().x0;
  const examples::IpoptRun unlimited = examples::solve_problem_with_ipopt(problem, x0, guess);
  ASSERT_TRUE(unlimited.solved) << unlimited.status;
  const examples::IpoptRun stopped = examples::solve_problem_with_ipopt(
      problem, x0, guess, examples::IpoptHessian::kLimitedMemory, 1e-9);
  EXPECT_FALSE(stopped.solved);
  EXPECT_EQ(stopped.status, "time limit (-4)");
  EXPECT_LT(stopped.iterations, unlimited.iterations);
  EXPECT_TRUE(unlimited.has_point());
  // The point handed back is where Ipopt stopped, near the straight-line guess, which drives
  // through the bus (phi -0.84): its cost and violation are evaluated from it (Ipopt 3.11 hands
  // back zeros for both at the time limit).
  ASSERT_TRUE(stopped.has_point());
  std::cout << "[car-bus] stopped by the time limit: cost " << stopped.cost << ", max violation "
            << stopped.max_violation << "\n";
  EXPECT_GT(stopped.cost, 0.0);
  EXPECT_GT(stopped.max_violation, 0.1);
  for (const double limit : {0.0, -1.0, std::nan("")}) {
    EXPECT_THROW(examples::solve_problem_with_ipopt(problem, x0, guess,
                                                    examples::IpoptHessian::kLimitedMemory, limit),
                 std::invalid_argument)
        << limit;
  }
}

}  // namespace
}  // namespace diffpills::trajopt
