// The QP module on its own: KKT conditions on thousands of random QPs, interior point against
// the box active-set solver, the backward pass against finite differences, caps and bad input.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <iostream>
#include <random>

#include "diffpills/qp/backward.hpp"
#include "diffpills/qp/box_active_set.hpp"
#include "diffpills/qp/interior_point.hpp"

namespace diffpills::qp {
namespace {

using Rng = std::mt19937_64;

struct Qp {
  Eigen::MatrixXd P, G;
  Eigen::VectorXd c, h;
};

// A random feasible, bounded QP: P = A'A of random rank (often singular), rows G that include a
// box |x_i| <= 10 so the feasible set is bounded, h = G x0 + slack with some slacks zero so that
// several constraints pass through one point (degenerate vertices).
Qp random_qp(Rng& rng, int n, int m) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const int rank = std::uniform_int_distribution<int>(0, n)(rng);
  Eigen::MatrixXd A(rank, n);
  for (int i = 0; i < rank; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = normal(rng);
  Qp qp;
  qp.P = A.transpose() * A;
  qp.c.resize(n);
  for (int j = 0; j < n; ++j) qp.c(j) = 3.0 * normal(rng);
  qp.G.resize(m + 2 * n, n);
  qp.h.resize(m + 2 * n);
  Eigen::VectorXd x0(n);
  for (int j = 0; j < n; ++j) x0(j) = normal(rng);
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < n; ++j) qp.G(i, j) = normal(rng);
    qp.h(i) = qp.G.row(i).dot(x0) + (unit(rng) < 0.2 ? 0.0 : unit(rng));
  }
  for (int j = 0; j < n; ++j) {
    qp.G.row(m + 2 * j).setZero();
    qp.G.row(m + 2 * j + 1).setZero();
    qp.G(m + 2 * j, j) = 1.0;
    qp.G(m + 2 * j + 1, j) = -1.0;
    qp.h(m + 2 * j) = 10.0;
    qp.h(m + 2 * j + 1) = 10.0;
  }
  return qp;
}

TEST(InteriorPoint, SatisfiesKktOnThousandsOfRandomQps) {
  Rng rng(11);
  int polished = 0, total = 0, max_iterations = 0;
  double worst = 0.0;
  for (int trial = 0; trial < 3000; ++trial) {
    const int n = std::uniform_int_distribution<int>(1, 6)(rng);
    const int m = std::uniform_int_distribution<int>(1, 10)(rng);
    const Qp qp = random_qp(rng, n, m);
    InteriorPointSolver solver;
    const InteriorPointResult& result = solver.solve(qp.P, qp.c, qp.G, qp.h);
    ASSERT_EQ(result.status, Status::kSolved) << "trial " << trial;
    const double scale = 1.0 + qp.c.cwiseAbs().maxCoeff() + qp.h.cwiseAbs().maxCoeff();
    const Eigen::VectorXd slack = qp.h - qp.G * result.x;
    const double primal = std::max(0.0, -slack.minCoeff());
    const double dual = std::max(0.0, -result.lambda.minCoeff());
    const double stationarity =
        (qp.P * result.x + qp.c + qp.G.transpose() * result.lambda).cwiseAbs().maxCoeff();
    const double complementarity =
        (slack.cwiseMax(0.0).array() * result.lambda.array()).abs().maxCoeff();
    const double error = std::max({primal, dual, stationarity, complementarity}) / scale;
    worst = std::max(worst, error);
    ASSERT_LE(error, 1e-9) << "trial " << trial;
    polished += result.polished;
    max_iterations = std::max(max_iterations, result.iterations);
    ++total;
  }
  std::cout << "[qp] " << total << " random QPs solved, " << polished << " polished, max KKT error "
            << worst << ", max iterations " << max_iterations << "\n";
}

TEST(InteriorPoint, AgreesWithBoxActiveSetOnBoxQps) {
  Rng rng(12);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd G(4, 2);
  G << 1, 0, 0, 1, -1, 0, 0, -1;
  const Eigen::Vector4d h(1, 1, 0, 0);
  for (int trial = 0; trial < 3000; ++trial) {
    Eigen::Matrix2d F;
    F << normal(rng), normal(rng), normal(rng), normal(rng);
    if (trial % 3 == 0) F.col(1) = normal(rng) * F.col(0);  // singular: parallel segments
    const Eigen::Matrix2d P = F.transpose() * F;
    const Eigen::Vector2d c = F.transpose() * Eigen::Vector2d(normal(rng), normal(rng));
    const BoxQpResult box = solve_box_qp(P, c);
    InteriorPointSolver solver;
    const InteriorPointResult& ipm = solver.solve(P, c, G, h);
    ASSERT_EQ(ipm.status, Status::kSolved);
    const auto cost = [&](const Eigen::Vector2d& x) { return 0.5 * x.dot(P * x) + c.dot(x); };
    const double scale = 1.0 + P.cwiseAbs().maxCoeff() + c.cwiseAbs().maxCoeff();
    ASSERT_NEAR(cost(box.x), cost(ipm.x), 1e-12 * scale) << "trial " << trial;
    ASSERT_TRUE((box.x.array() >= 0.0).all() && (box.x.array() <= 1.0).all());
    const double det = P.determinant();
    if (det > 1e-6 * P(0, 0) * P(1, 1)) {  // unique minimizer: the points agree too
      ASSERT_LE((box.x - ipm.x).cwiseAbs().maxCoeff(), 1e-8) << "trial " << trial;
      ASSERT_LE((box.lambda - ipm.lambda).cwiseAbs().maxCoeff(), 1e-8 * scale);
    }
  }
}

// Two parallel unit segments, the second shifted by 0.3 along the first and 1 aside:
// |p1 - p2|^2 = |(t1 - t2 - 0.3) u + w|^2, minimized on the whole segment t1 - t2 = 0.3 of the
// box, from (0.3, 0) to (1, 0.7); the solver returns its midpoint (0.65, 0.35).
TEST(BoxActiveSet, ReturnsMidpointOfOptimalSegmentWhenSingular) {
  const Eigen::Matrix2d P = (Eigen::Matrix2d() << 1, -1, -1, 1).finished();
  const Eigen::Vector2d c(-0.3, 0.3);
  const BoxQpResult result = solve_box_qp(P, c);
  EXPECT_NEAR(result.x(0), 0.65, 1e-14);
  EXPECT_NEAR(result.x(1), 0.35, 1e-14);
  EXPECT_TRUE(result.lambda.isZero());
  // Zero P, zero c: every point is optimal, and the box's centre is returned.
  const BoxQpResult flat = solve_box_qp(Eigen::Matrix2d::Zero(), Eigen::Vector2d::Zero());
  EXPECT_EQ(flat.x, Eigen::Vector2d(0.5, 0.5));
}

TEST(BoxActiveSet, RecoversDualsOfActiveBounds) {
  // minimize 1/2 |x - (2, -1)|^2: x = (1, 0), pushed by x1 <= 1 with 1 and by -x2 <= 0 with 1.
  const BoxQpResult result = solve_box_qp(Eigen::Matrix2d::Identity(), Eigen::Vector2d(-2, 1));
  EXPECT_EQ(result.x, Eigen::Vector2d(1, 0));
  EXPECT_NEAR(result.lambda(0), 1.0, 1e-15);
  EXPECT_NEAR(result.lambda(1), 0.0, 1e-15);
  EXPECT_NEAR(result.lambda(2), 0.0, 1e-15);
  EXPECT_NEAR(result.lambda(3), 1.0, 1e-15);
}

// l(x) = w'x + 1/2 |x|^2 through the QP, against central differences of re-solved QPs.
TEST(Backward, MatchesFiniteDifferencesOfResolvedQps) {
  Rng rng(13);
  std::normal_distribution<double> normal;
  int checked = 0;
  double worst = 0.0;
  for (int trial = 0; trial < 300; ++trial) {
    const int n = std::uniform_int_distribution<int>(1, 4)(rng);
    const int m = std::uniform_int_distribution<int>(1, 6)(rng);
    Qp qp = random_qp(rng, n, m);
    qp.P += Eigen::MatrixXd::Identity(n, n);  // strictly convex: x* is a smooth function
    Eigen::VectorXd w(n);
    for (int j = 0; j < n; ++j) w(j) = normal(rng);
    const auto loss = [&](const Qp& q) {
      InteriorPointSolver solver;
      const InteriorPointResult& r = solver.solve(q.P, q.c, q.G, q.h);
      return w.dot(r.x) + 0.5 * r.x.squaredNorm();
    };
    InteriorPointSolver solver;
    const InteriorPointResult& result = solver.solve(qp.P, qp.c, qp.G, qp.h);
    ASSERT_EQ(result.status, Status::kSolved);
    // Skip degenerate solutions, where the solution map is not differentiable: a constraint
    // active with a zero multiplier (strict complementarity fails), or active rows that are
    // linearly dependent (LICQ fails; e.g. two rows pinning a one-variable QP to a point).
    const Eigen::VectorXd slack = qp.h - qp.G * result.x;
    bool degenerate = false;
    Eigen::MatrixXd active_rows(0, n);
    for (Eigen::Index i = 0; i < slack.size(); ++i) {
      degenerate = degenerate || (slack(i) < 1e-6 && result.lambda(i) < 1e-6);
      if (slack(i) < 1e-9) {
        active_rows.conservativeResize(active_rows.rows() + 1, n);
        active_rows.row(active_rows.rows() - 1) = qp.G.row(i);
      }
    }
    if (active_rows.rows() > 0) {
      degenerate =
          degenerate || Eigen::FullPivLU<Eigen::MatrixXd>(active_rows).rank() < active_rows.rows();
    }
    if (degenerate) continue;
    const QpGradient gradient = backward(solver, w + result.x);
    const double step = 1e-6;
    double error = 0.0;
    const auto check = [&](double analytic, const auto& perturb) {
      Qp up = qp, down = qp;
      perturb(up, step);
      perturb(down, -step);
      const double fd = (loss(up) - loss(down)) / (2 * step);
      error = std::max(error, std::abs(fd - analytic) / (1.0 + std::abs(fd)));
    };
    for (int i = 0; i < n; ++i) {
      check(gradient.c(i), [&](Qp& q, double e) { q.c(i) += e; });
      for (int j = 0; j < n; ++j) {  // a symmetric perturbation of entries (i, j) and (j, i)
        const double analytic = i == j ? gradient.P(i, i) : gradient.P(i, j) + gradient.P(j, i);
        check(analytic, [&](Qp& q, double e) {
          q.P(i, j) += e;
          if (i != j) q.P(j, i) += e;
        });
      }
    }
    for (Eigen::Index i = 0; i < qp.G.rows(); ++i) {
      check(gradient.h(i), [&](Qp& q, double e) { q.h(i) += e; });
      for (int j = 0; j < n; ++j) {
        check(gradient.G(i, j), [&](Qp& q, double e) { q.G(i, j) += e; });
      }
    }
    worst = std::max(worst, error);
    ++checked;
    ASSERT_LE(error, 1e-5) << "trial " << trial << " lambda " << result.lambda.transpose()
                           << " slack " << slack.transpose();
  }
  std::cout << "[backward] " << checked << " QPs, max relative error " << worst << "\n";
  EXPECT_GT(checked, 150);
}

TEST(InteriorPoint, ReportsFailureInsteadOfLooping) {
  // Infeasible: x <= -1 and -x <= -1.
  Eigen::MatrixXd G(2, 1);
  G << 1, -1;
  InteriorPointSolver solver;
  const InteriorPointResult& infeasible = solver.solve(
      Eigen::MatrixXd::Identity(1, 1), Eigen::VectorXd::Zero(1), G, Eigen::Vector2d(-1, -1));
  EXPECT_NE(infeasible.status, Status::kSolved);
  EXPECT_LE(infeasible.iterations, solver.settings().max_iterations);
  EXPECT_THROW(backward(solver, Eigen::VectorXd::Ones(1)), std::logic_error);

  // A cap of two iterations is honoured.
  InteriorPointSettings settings;
  settings.max_iterations = 2;
  settings.polish = false;
  InteriorPointSolver capped(settings);
  Rng rng(3);
  const Qp qp = random_qp(rng, 4, 6);
  const InteriorPointResult& result = capped.solve(qp.P, qp.c, qp.G, qp.h);
  EXPECT_EQ(result.status, Status::kMaxIterations);
  EXPECT_EQ(result.iterations, 2);
  EXPECT_STREQ(to_string(result.status), "max_iterations");
}

TEST(InteriorPoint, RejectsBadData) {
  InteriorPointSolver solver;
  const Eigen::MatrixXd P = Eigen::MatrixXd::Identity(2, 2);
  const Eigen::MatrixXd G = Eigen::MatrixXd::Identity(2, 2);
  EXPECT_THROW(solver.solve(P, Eigen::VectorXd::Zero(3), G, Eigen::VectorXd::Ones(2)),
               std::invalid_argument);
  EXPECT_THROW(solver.solve(P, Eigen::VectorXd::Zero(2), G, Eigen::VectorXd::Ones(3)),
               std::invalid_argument);
  Eigen::VectorXd bad = Eigen::VectorXd::Zero(2);
  bad(1) = std::nan("");
  EXPECT_THROW(solver.solve(P, bad, G, Eigen::VectorXd::Ones(2)), std::invalid_argument);
  EXPECT_THROW(solve_box_qp(Eigen::Matrix2d::Constant(INFINITY), Eigen::Vector2d::Zero()),
               std::invalid_argument);
}

}  // namespace
}  // namespace diffpills::qp
