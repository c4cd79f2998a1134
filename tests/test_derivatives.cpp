// Derivatives against central finite differences (1,000 seeded random cases per pair type), the
// envelope-theorem gradient against the paper's OptNet route, and the attitude-gradient helper.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iostream>

#include "diffpills/diffpills.hpp"
#include "proximity/pair_problem.hpp"
#include "proximity/parametric_core.hpp"
#include "support/random_shapes.hpp"

namespace diffpills::testing {
namespace {

using Vector14 = Eigen::Matrix<double, 14, 1>;
using Outputs = Eigen::Matrix<double, 13, 1>;  // [phi, p1, p2, p~1, p~2]

Vector14 pack(const Pose& a, const Pose& b) {
  Vector14 x;
  x << a.r(), a.q(), b.r(), b.q();
  return x;
}

Outputs evaluate(const Shape& a, const Shape& b, const Vector14& x) {
  const Proximity result = proximity(a, Pose(x.segment<3>(0), x.segment<4>(3)), b,
                                     Pose(x.segment<3>(7), x.segment<4>(10)));
  Outputs out;
  out << result.phi, result.core_points[0], result.core_points[1], result.points[0],
      result.points[1];
  return out;
}

Eigen::Matrix<double, 13, 14> central_differences(const Shape& a, const Shape& b, const Vector14& x,
                                                  const Vector14& steps) {
  Eigen::Matrix<double, 13, 14> jacobian;
  for (int j = 0; j < 14; ++j) {
    Vector14 plus = x, minus = x;
    plus(j) += steps(j);
    minus(j) -= steps(j);
    jacobian.col(j) = (evaluate(a, b, plus) - evaluate(a, b, minus)) / (2.0 * steps(j));
  }
  return jacobian;
}

// Entries compared in dimensionless form: a column's unit is the scene scale S for positions
// and 1 for quaternion entries; a row's unit is S^2 for phi and S for points.
Eigen::Matrix<double, 13, 14> dimensionless(const Eigen::Matrix<double, 13, 14>& jacobian,
                                            double scale) {
  Eigen::Matrix<double, 13, 14> out = jacobian;
  for (int j : {0, 1, 2, 7, 8, 9}) out.col(j) *= scale;
  out.row(0) /= scale * scale;
  out.bottomRows<12>() /= scale;
  return out;
}

struct PairType {
  bool polygon_a, polygon_b;
  const char* name;
};

class Derivatives : public ::testing::TestWithParam<PairType> {};

TEST_P(Derivatives, GradientAndJacobiansMatchCentralDifferences) {
  const PairType type = GetParam();
  Rng rng(4242 + 2 * type.polygon_a + type.polygon_b);
  int checked = 0, kinks = 0, intersecting = 0;
  double worst = 0.0;
  const int cases = 1000;
  for (int i = 0; i < cases; ++i) {
    const double scale = std::pow(10.0, std::uniform_int_distribution<int>(-3, 3)(rng));
    const TestShape a =
        type.polygon_a ? random_polygon(rng, scale) : random_capsule(rng, scale, 0.05);
    const TestShape b =
        type.polygon_b ? random_polygon(rng, scale) : random_capsule(rng, scale, 0.05);
    const Pose pose_a = random_pose(rng, 1.5 * scale);
    const Pose pose_b = random_pose(rng, 1.5 * scale);
    const ProximityJacobian analytic = proximity_jacobian(a.shape, pose_a, b.shape, pose_b);
    if (analytic.cores_intersect) {
      // Inside the intersecting set phi is flat: the gradient 2 (p1 - p2)' J vanishes up to
      // |p1 - p2| <= 1e-12 (scale + |p|), i.e. ~1e-11 scale for positions, scale^2 for q.
      const Eigen::Matrix<double, 14, 1> gradient = analytic.gradient;
      ASSERT_LE(gradient.segment<3>(0).norm() + gradient.segment<3>(7).norm(), 1e-10 * scale);
      ASSERT_LE(gradient.segment<4>(3).norm() + gradient.segment<4>(10).norm(),
                1e-10 * scale * scale)
          << gradient.transpose();
      ++intersecting;
      continue;
    }
    const Vector14 x = pack(pose_a, pose_b);
    Vector14 steps;
    steps << Eigen::Vector3d::Constant(1e-6 * scale), Eigen::Vector4d::Constant(1e-6),
        Eigen::Vector3d::Constant(1e-6 * scale), Eigen::Vector4d::Constant(1e-6);
    const auto fd = dimensionless(central_differences(a.shape, b.shape, x, steps), scale);
    const auto fd_half =
        dimensionless(central_differences(a.shape, b.shape, x, 0.5 * steps), scale);
    if ((fd - fd_half).cwiseAbs().maxCoeff() > 1e-6) {
      ++kinks;  // an active set changes within the step: the derivative is one-sided there
      continue;
    }
    Eigen::Matrix<double, 13, 14> exact;
    exact << analytic.gradient.transpose(), analytic.core_points_jacobian, analytic.points_jacobian;
    const double error = (dimensionless(exact, scale) - fd).cwiseAbs().maxCoeff();
    worst = std::max(worst, error);
    ++checked;
    ASSERT_LE(error, 1e-5) << type.name << " case " << i << "\nanalytic\n"
                           << dimensionless(exact, scale) << "\nfinite differences\n"
                           << fd;
  }
  std::cout << "[derivatives] " << type.name << ": " << checked << " checked, " << kinks
            << " skipped at an active-set change, " << intersecting
            << " intersecting; max dimensionless error " << worst << "\n";
  EXPECT_LE(kinks, cases / 50);
  EXPECT_GE(checked, cases / 2);
}

INSTANTIATE_TEST_SUITE_P(AllPairTypes, Derivatives,
                         ::testing::Values(PairType{false, false, "capsule-capsule"},
                                           PairType{false, true, "capsule-polygon"},
                                           PairType{true, false, "polygon-capsule"},
                                           PairType{true, true, "polygon-polygon"}),
                         [](const auto& info) {
                           std::string name = info.param.name;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

// The paper's route (eqs. caps_deriv_1-2, polygon_deriv_1-2): phi as a function of the QP data,
// phi/s^2 = x'Px + 2c'x + g'g - (R1+R2)^2/s^2, differentiated through the solver with
// qp::backward for dl/dx = 2(Px + c), plus the explicit dependence on P, c and g. The data's
// derivatives with respect to a pose coordinate come from central differences of the (smooth)
// assembly. The sum must equal the library's envelope-theorem gradient.
TEST(Derivatives, EnvelopeGradientEqualsOptNetRoute) {
  Rng rng(77);
  double worst = 0.0;
  int checked = 0;
  for (int i = 0; i < 400; ++i) {
    const int ordering = i % 4;
    const TestShape a = (ordering & 2) ? random_polygon(rng, 1.0) : random_capsule(rng, 1.0);
    const TestShape b = (ordering & 1) ? random_polygon(rng, 1.0) : random_capsule(rng, 1.0);
    const Pose pose_a = random_pose(rng, 1.5);
    const Pose pose_b = random_pose(rng, 1.5);
    const Proximity envelope = proximity(a.shape, pose_a, b.shape, pose_b);
    if (envelope.cores_intersect) continue;

    // The QP in the inputs' own units (a frame of scale 1 at the world origin).
    const auto core_of = [](const Shape& shape) {
      if (const auto* capsule = std::get_if<Capsule>(&shape)) {
        return detail::make_parametric_capsule(capsule->length());
      }
      return detail::make_parametric_polygon(
          detail::PolygonView(std::get<PaddedPolygon>(shape), 1.0));
    };
    const detail::ParametricCore core_a = core_of(a.shape);
    const detail::ParametricCore core_b = core_of(b.shape);
    const auto posed = [](const Eigen::Vector3d& r, const Eigen::Vector4d& q) {
      return detail::PosedCore{r, detail::UnitQuaternion(q), 0.0, 0.0};
    };
    const auto problem_at = [&](const Vector14& x) {
      return detail::make_pair_problem(core_a, posed(x.segment<3>(0), x.segment<4>(3)), core_b,
                                       posed(x.segment<3>(7), x.segment<4>(10)));
    };
    const Vector14 x0 = pack(pose_a, pose_b);
    const detail::PairProblem problem = problem_at(x0);
    const Eigen::MatrixXd P = problem.F.transpose() * problem.F;
    const Eigen::VectorXd c = problem.F.transpose() * problem.g;
    qp::InteriorPointSolver solver;
    const qp::InteriorPointResult& solution = solver.solve(P, c, problem.G, problem.h);
    ASSERT_EQ(solution.status, qp::Status::kSolved);
    const Eigen::VectorXd& x = solution.x;
    const qp::QpGradient through = qp::backward(solver, 2.0 * (P * x + c));

    Vector14 optnet;
    for (int j = 0; j < 14; ++j) {
      const double step = 1e-6;
      Vector14 plus = x0, minus = x0;
      plus(j) += step;
      minus(j) -= step;
      const detail::PairProblem up = problem_at(plus), down = problem_at(minus);
      const Eigen::MatrixXd dP =
          (up.F.transpose() * up.F - down.F.transpose() * down.F) / (2 * step);
      const Eigen::VectorXd dc =
          (up.F.transpose() * up.g - down.F.transpose() * down.g) / (2 * step);
      const double dgg = (up.g.squaredNorm() - down.g.squaredNorm()) / (2 * step);
      const double explicit_part = x.dot(dP * x) + 2.0 * dc.dot(x) + dgg;
      const double through_solver = (through.P.array() * dP.array()).sum() + through.c.dot(dc);
      optnet(j) = problem.scale * problem.scale * (explicit_part + through_solver);
    }
    const double error = (optnet - envelope.gradient).cwiseAbs().maxCoeff() /
                         (1.0 + envelope.gradient.cwiseAbs().maxCoeff());
    worst = std::max(worst, error);
    ++checked;
    ASSERT_LE(error, 1e-6) << "ordering " << ordering << "\noptnet   " << optnet.transpose()
                           << "\nenvelope " << envelope.gradient.transpose();
  }
  std::cout << "[optnet] " << checked << " pairs, max relative |optnet - envelope| " << worst
            << "\n";
  EXPECT_GT(checked, 200);
}

// dphi/dtheta for the body-frame perturbation q (x) exp(theta) against central differences.
TEST(Derivatives, AttitudeGradientMatchesBodyRotationDifferences) {
  Rng rng(5);
  for (int i = 0; i < 200; ++i) {
    const TestShape a = random_capsule(rng, 1.0);
    const TestShape b = random_polygon(rng, 1.0);
    const Pose pose_a = random_pose(rng, 1.5);
    const Pose pose_b = random_pose(rng, 1.5);
    const Proximity result = proximity(a.shape, pose_a, b.shape, pose_b);
    const Eigen::Matrix<double, 12, 1> reduced =
        reduce_pose_gradient(pose_a.q(), pose_b.q(), result.gradient);
    for (int j = 0; j < 3; ++j) {
      const double step = 1e-6;
      const auto rotated = [&](const Pose& pose, double angle) {
        const Eigen::Quaterniond q(pose.q()(0), pose.q()(1), pose.q()(2), pose.q()(3));
        const Eigen::Quaterniond turned =
            q * Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::Unit(j)));
        return Pose(pose.r(), Eigen::Vector4d(turned.w(), turned.x(), turned.y(), turned.z()));
      };
      const double fd_a = (proximity(a.shape, rotated(pose_a, step), b.shape, pose_b).phi -
                           proximity(a.shape, rotated(pose_a, -step), b.shape, pose_b).phi) /
                          (2 * step);
      const double fd_b = (proximity(a.shape, pose_a, b.shape, rotated(pose_b, step)).phi -
                           proximity(a.shape, pose_a, b.shape, rotated(pose_b, -step)).phi) /
                          (2 * step);
      EXPECT_NEAR(reduced(3 + j), fd_a, 1e-6 * (1 + std::abs(fd_a)));
      EXPECT_NEAR(reduced(9 + j), fd_b, 1e-6 * (1 + std::abs(fd_b)));
    }
    EXPECT_EQ(reduced.segment<3>(0), result.gradient.segment<3>(0));
    EXPECT_EQ(reduced.segment<3>(6), result.gradient.segment<3>(7));
  }
}

}  // namespace
}  // namespace diffpills::testing
