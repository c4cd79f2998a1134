// Properties every answer must have whatever the algorithm: swapping the shapes, moving both by
// one rigid motion, scaling the quaternions, and choosing the other solver change nothing (or
// change the outputs in the exactly predictable way).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "diffpills/diffpills.hpp"
#include "support/random_shapes.hpp"

namespace diffpills::testing {
namespace {

struct RandomPair {
  TestShape a, b;
  Pose pose_a, pose_b;
  double scale;
};

RandomPair random_pair(Rng& rng, int ordering) {
  const double scale = std::pow(10.0, std::uniform_int_distribution<int>(-3, 3)(rng));
  TestShape a = (ordering & 2) ? random_polygon(rng, scale) : random_capsule(rng, scale, 0.05);
  TestShape b = (ordering & 1) ? random_polygon(rng, scale) : random_capsule(rng, scale, 0.05);
  return {std::move(a), std::move(b), random_pose(rng, 1.5 * scale), random_pose(rng, 1.5 * scale),
          scale};
}

TEST(Symmetry, SwappingTheShapesSwapsTheResults) {
  Rng rng(31);
  for (int i = 0; i < 4000; ++i) {
    const RandomPair p = random_pair(rng, i % 4);
    const Proximity ab = proximity(p.a.shape, p.pose_a, p.b.shape, p.pose_b);
    const Proximity ba = proximity(p.b.shape, p.pose_b, p.a.shape, p.pose_a);
    const double s = p.scale;
    ASSERT_NEAR(ab.phi, ba.phi, 1e-12 * s * s + 1e-12 * std::abs(ab.phi));
    if (ab.cores_intersect) {
      ASSERT_TRUE(ba.cores_intersect);
      continue;
    }
    ASSERT_LE((ab.core_points[0] - ba.core_points[1]).norm(), 1e-9 * s);
    ASSERT_LE((ab.core_points[1] - ba.core_points[0]).norm(), 1e-9 * s);
    ASSERT_LE((ab.normal + ba.normal).norm(), 1e-9);
    ASSERT_LE((ab.gradient.head<7>() - ba.gradient.tail<7>()).norm(), 1e-9 * s * (1 + s));
    ASSERT_LE((ab.gradient.tail<7>() - ba.gradient.head<7>()).norm(), 1e-9 * s * (1 + s));
  }
}

// Two polygons are solved with the same one as A in both orders (pair_setup.hpp, solve_b_as_a),
// so the orders agree to the rounding of the results, tied closest points too: the same polygon
// twice, one in three, and the same attitude, one in five (parallel faces, whose optimal sets are
// regions). Before, the orders kept tied points up to 2e-11 of the scene apart.
TEST(Symmetry, TwoPolygonsAgreeInBothOrdersToRounding) {
  Rng rng(35);
  for (int i = 0; i < 3000; ++i) {
    const double s = std::pow(10.0, std::uniform_int_distribution<int>(-3, 3)(rng));
    const TestShape a = random_polygon(rng, s);
    const TestShape b = i % 3 == 0 ? a : random_polygon(rng, s);
    const Pose pose_a = random_pose(rng, 1.5 * s);
    const Pose drawn = random_pose(rng, 1.5 * s);
    const Pose pose_b(drawn.r(), i % 5 == 0 ? pose_a.q() : drawn.q());
    const ProximityJacobian ab = proximity_jacobian(a.shape, pose_a, b.shape, pose_b);
    const ProximityJacobian ba = proximity_jacobian(b.shape, pose_b, a.shape, pose_a);
    ASSERT_LE((ab.core_points[0] - ba.core_points[1]).norm(), 1e-13 * s) << i;
    ASSERT_LE((ab.core_points[1] - ba.core_points[0]).norm(), 1e-13 * s) << i;
    ASSERT_LE((ab.gradient.head<7>() - ba.gradient.tail<7>()).norm(), 1e-13 * s * (1 + s)) << i;
    ASSERT_LE((ab.gradient.tail<7>() - ba.gradient.head<7>()).norm(), 1e-13 * s * (1 + s)) << i;
  }
}

// x -> R x + t applied to both bodies: r -> R r + t, q -> q_R (x) q.
TEST(Symmetry, RigidMotionOfBothShapesMovesTheResultsWithThem) {
  Rng rng(32);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 4000; ++i) {
    const RandomPair p = random_pair(rng, i % 4);
    const Eigen::Quaterniond motion =
        Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized();
    const Eigen::Matrix3d R = motion.toRotationMatrix();
    const Eigen::Vector3d t = p.scale * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    const auto moved = [&](const Pose& pose) {
      const Eigen::Quaterniond q =
          motion * Eigen::Quaterniond(pose.q()(0), pose.q()(1), pose.q()(2), pose.q()(3));
      return Pose(R * pose.r() + t, Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()));
    };
    const Proximity before = proximity(p.a.shape, p.pose_a, p.b.shape, p.pose_b);
    const Proximity after = proximity(p.a.shape, moved(p.pose_a), p.b.shape, moved(p.pose_b));
    const double s = p.scale;
    ASSERT_NEAR(before.phi, after.phi, 1e-11 * s * s + 1e-11 * std::abs(before.phi));
    if (before.cores_intersect) continue;
    ASSERT_LE((R * before.core_points[0] + t - after.core_points[0]).norm(), 1e-9 * s);
    ASSERT_LE((R * before.core_points[1] + t - after.core_points[1]).norm(), 1e-9 * s);
    ASSERT_LE((R * before.normal - after.normal).norm(), 1e-9);
    // Position gradients are world-frame vectors: they rotate with the motion.
    ASSERT_LE((R * before.gradient.segment<3>(0) - after.gradient.segment<3>(0)).norm(), 1e-9 * s);
    ASSERT_LE((R * before.gradient.segment<3>(7) - after.gradient.segment<3>(7)).norm(), 1e-9 * s);
  }
}

// phi does not depend on |q|, so dphi/d(kq) = dphi/dq / k.
TEST(Symmetry, NonUnitQuaternionsEqualTheUnitOnes) {
  Rng rng(33);
  for (int i = 0; i < 2000; ++i) {
    const RandomPair p = random_pair(rng, i % 4);
    const double k = i % 2 ? 1e-3 : 1e3;
    const Pose scaled_a(p.pose_a.r(), k * p.pose_a.q());
    const Pose unit_b(p.pose_b.r(), p.pose_b.q().normalized());
    const ProximityJacobian reference = proximity_jacobian(p.a.shape, p.pose_a, p.b.shape, unit_b);
    const ProximityJacobian scaled = proximity_jacobian(p.a.shape, scaled_a, p.b.shape, unit_b);
    const double s = p.scale;
    ASSERT_NEAR(reference.phi, scaled.phi, 1e-12 * s * s + 1e-12 * std::abs(reference.phi));
    ASSERT_LE((reference.core_points[0] - scaled.core_points[0]).norm(), 1e-9 * s);
    ASSERT_LE((reference.gradient.segment<4>(3) - k * scaled.gradient.segment<4>(3)).norm(),
              1e-9 * s * s);
    ASSERT_LE((reference.gradient.segment<3>(0) - scaled.gradient.segment<3>(0)).norm(), 1e-9 * s);
    if (!reference.cores_intersect) {
      ASSERT_LE((reference.core_points_jacobian.middleCols<4>(3) -
                 k * scaled.core_points_jacobian.middleCols<4>(3))
                    .cwiseAbs()
                    .maxCoeff(),
                1e-7 * s);
    }
    // At a unit quaternion the gradient has no component along q (normalization is built in).
    ASSERT_LE(std::abs(reference.gradient.segment<4>(10).dot(unit_b.q())), 1e-9 * s * s);
  }
}

TEST(Symmetry, InteriorPointAndAppendixAAgreeOnCapsulePairs) {
  Rng rng(34);
  for (int i = 0; i < 3000; ++i) {
    const RandomPair p = random_pair(rng, 0);
    const ProximityJacobian fast = proximity_jacobian(p.a.shape, p.pose_a, p.b.shape, p.pose_b);
    const ProximityJacobian reference =
        proximity_jacobian(p.a.shape, p.pose_a, p.b.shape, p.pose_b, {Method::kInteriorPoint});
    const double s = p.scale;
    ASSERT_NEAR(fast.phi, reference.phi, 1e-9 * s * s);
    if (fast.cores_intersect) continue;
    ASSERT_LE((fast.core_points[0] - reference.core_points[0]).norm(), 1e-9 * s);
    ASSERT_LE((fast.gradient - reference.gradient).norm(), 1e-9 * s * (1 + s));
    ASSERT_LE((fast.core_points_jacobian - reference.core_points_jacobian).cwiseAbs().maxCoeff(),
              1e-7 * (1 + s));
  }
}

}  // namespace
}  // namespace diffpills::testing
