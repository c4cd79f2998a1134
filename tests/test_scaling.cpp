// Every magnitude the library accepts is answered correctly. Scaling every length of a scene by
// an exact power of two 2^k is exact in floating point, so the answers must scale exactly, bit for
// bit: phi by 2^(2k), points by 2^k, the gradient's position part by 2^k and its quaternion part
// by 2^(2k), the Jacobians' quaternion columns by 2^k, for every k with 2^|k| <= 1e100. Scenes at
// those scales, scenes that mix magnitudes, and polygons with tiny offsets are checked against the
// brute-force reference in long double (whose exponent range covers them all).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "diffpills/diffpills.hpp"
#include "support/random_shapes.hpp"
#include "support/reference.hpp"
#include "support/scene_helpers.hpp"

namespace diffpills::testing {
namespace {

// 2^332 ~ 8.7e99 is the largest power of two within kMaxMagnitude; the scenes below keep every
// input within 1.15 so that they stay accepted at that scale.
const std::vector<int> kExponents = {-332, -331, -257, -160, -100, -53, -1,
                                     1,    7,    100,  200,  331,  332};

TestShape scaled(const TestShape& shape, int k) {
  TestShape out = shape;
  if (const auto* capsule = std::get_if<Capsule>(&shape.shape)) {
    out.shape = Capsule(std::ldexp(capsule->length(), k), std::ldexp(capsule->radius(), k));
  } else {
    const auto& polygon = std::get<PaddedPolygon>(shape.shape);
    Eigen::VectorXd d = polygon.constraint_offsets();
    for (Eigen::Index i = 0; i < d.size(); ++i) d(i) = std::ldexp(d(i), k);
    out.shape = PaddedPolygon(polygon.constraint_matrix(), d, std::ldexp(polygon.radius(), k));
  }
  for (auto& v : out.body_vertices) {
    for (int i = 0; i < 3; ++i) v(i) = std::ldexp(v(i), k);
  }
  out.size = std::ldexp(shape.size, k);
  return out;
}

Pose scaled(const Pose& pose, int k) {
  return Pose({std::ldexp(pose.r()(0), k), std::ldexp(pose.r()(1), k), std::ldexp(pose.r()(2), k)},
              pose.q());
}

template <class Matrix>
Matrix ldexp(Matrix m, int k) {
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = std::ldexp(m.data()[i], k);
  return m;
}

struct Scene {
  TestShape a, b;
  Pose pose_a, pose_b;
};

// Random scenes of every ordering within |x| <= 1.15, and the degenerate configurations of the
// degenerate-case suite (parallel, crossing, stacked, coplanar, touching, a box edge on a table).
std::vector<Scene> scenes() {
  std::vector<Scene> out;
  Rng rng(2024);
  for (int i = 0; i < 240; ++i) {
    const int ordering = i % 4;
    out.push_back({(ordering & 2) ? random_polygon(rng, 0.25) : random_capsule(rng, 0.25, 0.1),
                   (ordering & 1) ? random_polygon(rng, 0.25) : random_capsule(rng, 0.25, 0.1),
                   random_pose(rng, 0.3), random_pose(rng, 0.3)});
  }
  const auto capsule = [](double length, double radius) {
    TestShape shape{Capsule(length, radius), {}, length};
    shape.body_vertices = {{-0.5 * length, 0, 0}, {0.5 * length, 0, 0}};
    return shape;
  };
  const auto square_shape = [](double half, double radius) {
    TestShape shape{square(half, radius), {}, half * std::sqrt(2.0)};
    shape.body_vertices = {{half, half, 0}, {-half, half, 0}, {-half, -half, 0}, {half, -half, 0}};
    return shape;
  };
  const Eigen::Vector4d quarter_x = about(M_PI / 2, 1, 0, 0);
  out.push_back(
      {capsule(0.5, 0.05), capsule(0.5, 0.05), Pose(), Pose({0.125, 0, 0.25}, kIdentity)});
  out.push_back({capsule(0.5, 0.05), capsule(0.5, 0.1), Pose({0.1, 0, 0}, kIdentity),
                 Pose({0, 0.05, 0}, about(M_PI / 2, 0, 0, 1))});
  out.push_back({square_shape(0.25, 0.05), square_shape(0.125, 0.05), Pose(),
                 Pose({0.1, -0.05, 0.25}, kIdentity)});
  out.push_back({square_shape(0.25, 0.05), square_shape(0.25, 0.05), Pose(),
                 Pose({0.5, 0.125, 0}, kIdentity)});
  out.push_back(
      {square_shape(0.25, 0.0), square_shape(0.25, 0.0), Pose({0.05, 0, 0.25}, quarter_x), Pose()});
  out.push_back({capsule(0.5, 0.0), square_shape(0.25, 0.0), Pose({0, 0.4, 0}, kIdentity), Pose()});
  return out;
}

void expect_scaled(const ProximityJacobian& base, const ProximityJacobian& big, int k) {
  ASSERT_EQ(big.phi, std::ldexp(base.phi, 2 * k)) << "k = " << k;
  ASSERT_EQ(big.cores_intersect, base.cores_intersect);
  ASSERT_EQ(big.normal, base.normal);
  for (int i = 0; i < 2; ++i) {
    ASSERT_EQ(big.core_points[i], ldexp(base.core_points[i], k)) << "k = " << k;
    ASSERT_EQ(big.points[i], ldexp(base.points[i], k)) << "k = " << k;
  }
  for (const int block : {0, 7}) {
    ASSERT_EQ(big.gradient.segment<3>(block),
              ldexp(Eigen::Vector3d(base.gradient.segment<3>(block)), k));
    ASSERT_EQ(big.gradient.segment<4>(block + 3),
              ldexp(Eigen::Vector4d(base.gradient.segment<4>(block + 3)), 2 * k));
    ASSERT_EQ(big.core_points_jacobian.middleCols<3>(block),
              base.core_points_jacobian.middleCols<3>(block));
    ASSERT_EQ(big.points_jacobian.middleCols<3>(block), base.points_jacobian.middleCols<3>(block));
    const Eigen::Matrix<double, 6, 4> q_columns = base.points_jacobian.middleCols<4>(block + 3);
    ASSERT_EQ(big.points_jacobian.middleCols<4>(block + 3), ldexp(q_columns, k));
    const Eigen::Matrix<double, 6, 4> core_q_columns =
        base.core_points_jacobian.middleCols<4>(block + 3);
    ASSERT_EQ(big.core_points_jacobian.middleCols<4>(block + 3), ldexp(core_q_columns, k));
  }
}

TEST(Scaling, PowerOfTwoScalingIsExact) {
  for (const Method method : {Method::kDefault, Method::kInteriorPoint}) {
    for (const Scene& scene : scenes()) {
      const ProximityJacobian base =
          proximity_jacobian(scene.a.shape, scene.pose_a, scene.b.shape, scene.pose_b, {method});
      for (const int k : kExponents) {
        const TestShape a = scaled(scene.a, k), b = scaled(scene.b, k);
        const ProximityJacobian big = proximity_jacobian(a.shape, scaled(scene.pose_a, k), b.shape,
                                                         scaled(scene.pose_b, k), {method});
        expect_scaled(base, big, k);
      }
    }
  }
}

// The reference in long double at every scale: phi to 1e-12 of the scene size squared, the
// distance vector p1 - p2 to 1e-12 of the scene size; the normal is unit to 1e-15.
TEST(Scaling, ExtremeScalesAgreeWithBruteForce) {
  for (const Scene& scene : scenes()) {
    for (const int k : kExponents) {
      const TestShape a = scaled(scene.a, k), b = scaled(scene.b, k);
      const Pose pa = scaled(scene.pose_a, k), pb = scaled(scene.pose_b, k);
      const Proximity result = proximity(a.shape, pa, b.shape, pb);
      const ClosestPair reference = brute_force_closest(to_world(a, pa), to_world(b, pb));
      const long double size = std::ldexp(2.0L, k);
      const long double radii =
          std::ldexp(static_cast<long double>(
                         std::visit([](const auto& s) { return s.radius(); }, scene.a.shape) +
                         std::visit([](const auto& s) { return s.radius(); }, scene.b.shape)),
                     k);
      const long double phi = reference.distance * reference.distance - radii * radii;
      ASSERT_LE(std::abs(result.phi - phi), 1e-12L * size * size) << "k = " << k;
      const Eigen::Matrix<long double, 3, 1> difference =
          (result.core_points[0] - result.core_points[1]).cast<long double>();
      ASSERT_LE((difference - (reference.p1 - reference.p2)).norm(), 1e-12L * size) << "k = " << k;
      ASSERT_LE(std::abs(result.normal.norm() - 1.0), 1e-15);
    }
  }
}

// The magnitudes of the issue: capsules of length 1e-100 .. 1e90 (and 2^255 ~ 5.8e76, where
// length^4 overflows) answer the same phi / length^2 as the unit scene.
TEST(Scaling, LongAndShortCapsules) {
  const auto phi_over_length2 = [](double length) {
    const Capsule a(length, 0.1 * length), b(length, 0.1 * length);
    const Pose pb(Eigen::Vector3d(0.2, 0.3, 0.5) * length, Eigen::Vector4d(0.9, 0.1, 0.3, 0.2));
    return proximity(a, Pose(), b, pb).phi / (length * length);
  };
  const double unit = phi_over_length2(1.0);
  EXPECT_TRUE(std::isfinite(unit));
  for (const int k : {-332, -300, 255, 256, 299, 332}) {
    EXPECT_EQ(phi_over_length2(std::ldexp(1.0, k)), unit) << "k = " << k;
  }
  for (const double length : {1e-100, 1e-60, 1e77, 1e90}) {
    EXPECT_NEAR(phi_over_length2(length), unit, 1e-14) << "length = " << length;
  }
}

// Scenes that mix magnitudes: a tiny shape beside a huge one. Errors are relative to the scene's
// size, the resolution of its coordinates.
TEST(Scaling, MixedMagnitudesAgreeWithBruteForce) {
  Rng rng(99);
  int checked = 0;
  for (int i = 0; i < 400; ++i) {
    const int ordering = i % 4;
    const double small = std::pow(10.0, -std::uniform_int_distribution<int>(5, 90)(rng));
    const double large = std::pow(10.0, std::uniform_int_distribution<int>(-5, 5)(rng));
    const TestShape a = (ordering & 2) ? random_polygon(rng, small) : random_capsule(rng, small);
    const TestShape b = (ordering & 1) ? random_polygon(rng, large) : random_capsule(rng, large);
    const Pose pa = random_pose(rng, large), pb = random_pose(rng, large);
    const Proximity result = proximity(a.shape, pa, b.shape, pb);
    ASSERT_TRUE(std::isfinite(result.phi));
    ASSERT_TRUE(result.gradient.allFinite());
    ASSERT_LE(std::abs(result.normal.norm() - 1.0), 1e-15);
    const ClosestPair reference = brute_force_closest(to_world(a, pa), to_world(b, pb));
    const long double scene = 4.0L * large;
    const Eigen::Matrix<long double, 3, 1> difference =
        (result.core_points[0] - result.core_points[1]).cast<long double>();
    ASSERT_LE((difference - (reference.p1 - reference.p2)).norm(), 1e-12L * scene)
        << "ordering " << ordering << " small " << small << " large " << large << "\n"
        << result.core_points[0].transpose() << " | " << result.core_points[1].transpose()
        << "\nreference " << reference.p1.transpose() << " | " << reference.p2.transpose();
    ++checked;
  }
  EXPECT_EQ(checked, 400);
}

// Offsets as small as 1e-95 (and 1e-300) next to offsets of 1: the body origin lies that close to
// an edge, and the polygon is still a square.
TEST(Scaling, PolygonsWithTinyOffsets) {
  Eigen::MatrixX2d C(4, 2);
  C << 1, 0, 0, 1, -1, 0, 0, -1;
  for (const double tiny : {1e-95, 1e-200, 1e-300}) {
    const PaddedPolygon polygon(C, Eigen::Vector4d(1, 1, 1, tiny), 0.1);
    ASSERT_EQ(polygon.vertices().rows(), 4);
    for (Eigen::Index i = 0; i < 4; ++i) {
      EXPECT_EQ(std::abs(polygon.vertices()(i, 0)), 1.0);
      EXPECT_TRUE(polygon.vertices()(i, 1) == 1.0 || polygon.vertices()(i, 1) == -tiny);
    }
    // A sphere 1 below the bottom edge y = -tiny: phi = 1 - 0.1^2 up to rounding of 1 + tiny.
    const Proximity below =
        proximity(Capsule(0.0, 0.0), Pose({0.3, -1.0, 0}, kIdentity), polygon, Pose());
    EXPECT_NEAR(below.phi, (1.0 - tiny) * (1.0 - tiny) - 0.01, 1e-15);
    EXPECT_NEAR(below.core_points[1].y(), -tiny, 1e-300);
  }
  // A whole polygon at 1e-95: its rows scale with it.
  const PaddedPolygon tiny_square(C, Eigen::Vector4d::Constant(1e-95), 0.0);
  EXPECT_NEAR(tiny_square.extent(), std::sqrt(2.0) * 1e-95, 1e-109);
}

// A polygon so small beside the scene that its extent underflows to zero in the pair's frame
// (found by fuzz_proximity): both methods answer it as the point it is there.
TEST(Scaling, PolygonBelowTheFramesResolution) {
  Eigen::MatrixX2d C(4, 2);
  C << 1, 0, 0, 1, -1, 0, 0, -1;
  const PaddedPolygon speck(C, Eigen::Vector4d::Constant(1e-300), 0.0);
  const Capsule capsule(2e-283, 6e10);
  const Pose far(Eigen::Vector3d(3.8e53, 0, 0), kIdentity);
  for (const Method method : {Method::kDefault, Method::kInteriorPoint}) {
    const Proximity result = proximity(speck, far, capsule, Pose(), {method});
    EXPECT_DOUBLE_EQ(result.phi, 3.8e53 * 3.8e53 - 6e10 * 6e10);
    EXPECT_TRUE(result.gradient.allFinite());
    EXPECT_EQ(result.core_points[0], far.r());
  }
  // A capsule whose length is subnormal beside a sphere (found by fuzz_proximity: the reference
  // QP divided by that length).
  const Capsule needle(2.6e-314, 41402.0), sphere(0.0, 1e-115);
  const Pose near(Eigen::Vector3d(0.5, 3e-115, 3e-115), kIdentity);
  for (const Method method : {Method::kDefault, Method::kInteriorPoint}) {
    const Proximity result = proximity(needle, near, sphere, Pose(), {method});
    EXPECT_DOUBLE_EQ(result.phi, 0.25 - 41402.0 * 41402.0);
    EXPECT_EQ(result.core_points[0], near.r());
  }
}

// Coplanar polygons, one 1e-84 the size of the other and beside it (found by fuzz_proximity):
// the small one's rows in the large one's frame are a bundle of lines through one point, and the
// half-plane sweep took that bundle for an overlap in one order of the shapes.
TEST(Scaling, CoplanarSpeckBesideAHugePolygon) {
  Eigen::MatrixX2d C(51, 2);
  for (int k = 0; k < 51; ++k) C.row(k) << std::cos(2 * M_PI * k / 51), std::sin(2 * M_PI * k / 51);
  const PaddedPolygon huge(C, Eigen::VectorXd::Constant(51, 1e70), 1e70);
  const PaddedPolygon speck(C, Eigen::VectorXd::Constant(51, 5.75e-14), 1e70);
  // The fuzzer's poses: half turns about z and (nearly) y, so that the planes are parallel and
  // the speck's shadow is mirrored and skewed by 4e-9.
  const Pose pose_huge({1e70, 1e70, 0}, Eigen::Vector4d(1.398e-76, 1.398e-76, 0, -2.875));
  // (The fuzzer's quaternion had norm 7.5e-68, below today's minimum; 2^100 times it normalizes to
  // the same unit quaternion, bit for bit.)
  const Pose pose_speck(
      {3, 0, 1.398e-76},
      std::ldexp(1.0, 100) * Eigen::Vector4d(9e-308, 1.398e-76, 7.522e-68, 3.66e-86));
  const Proximity ab = proximity(huge, pose_huge, speck, pose_speck);
  const Proximity ba = proximity(speck, pose_speck, huge, pose_huge);
  EXPECT_FALSE(ab.cores_intersect);
  EXPECT_FALSE(ba.cores_intersect);
  EXPECT_LE((ab.core_points[1] - pose_speck.r()).norm(), 1e-12);
  EXPECT_EQ(ab.core_points[0], ba.core_points[1]);
  EXPECT_NEAR(ab.phi, ba.phi, 1e-12 * 4e140);
  // The huge polygon's closest point is its vertex or edge toward (3, 0): at its circumradius
  // from its centre at most, and the gap is the centre distance less that.
  const double centre_distance = std::hypot(1e70 - 3, 1e70);
  EXPECT_LE((ab.core_points[0] - pose_huge.r()).norm(), 1e70 / std::cos(M_PI / 51) * (1 + 1e-12));
  EXPECT_GE((ab.core_points[0] - ab.core_points[1]).norm(),
            centre_distance - 1e70 / std::cos(M_PI / 51) * (1 + 1e-12));
}

// A radius 1e-158 of the scene: in the pair's frame (R1 + R2)^2 is subnormal and loses digits, so
// the radius term is taken in the inputs' units and phi >= -(R1 + R2)^2 holds (found by
// fuzz_proximity: phi = -4.07e-133 for (R1 + R2)^2 = 4.067e-133).
TEST(Scaling, RadiusFarBelowTheScene) {
  Eigen::MatrixX2d triangle(3, 2), C(35, 2);
  triangle << 1, 0, -0.5, std::sqrt(0.75), -0.5, -std::sqrt(0.75);
  for (int k = 0; k < 35; ++k) C.row(k) << std::cos(2 * M_PI * k / 35), std::sin(2 * M_PI * k / 35);
  const PaddedPolygon speck(triangle, Eigen::Vector3d::Constant(1.3241822640263115e-300), 0.0);
  const double radius = 6.376925397871113e-67;
  const PaddedPolygon huge(C, Eigen::VectorXd::Constant(35, 9.3182071319932369e+90), radius);
  const Pose pose_speck({1.2099298215479115e+62, 0.375, 0.375}, {1e100, 0.375, 0.375, 0.375});
  const Pose pose_huge({0.375, 0.375, 0.375}, {0.375, 0.375, 0.375, 0.375});
  for (const bool swap : {false, true}) {
    const Proximity p = swap ? proximity(huge, pose_huge, speck, pose_speck)
                             : proximity(speck, pose_speck, huge, pose_huge);
    EXPECT_GE(p.phi, -radius * radius);
    const SignedDistance sd = swap ? signed_distance(huge, pose_huge, speck, pose_speck)
                                   : signed_distance(speck, pose_speck, huge, pose_huge);
    EXPECT_TRUE(std::isfinite(sd.distance) && sd.gradient.allFinite());
  }
}

// The smallest accepted quaternion norm in the largest accepted scene: derivatives with respect to
// q carry 1 / |q|, and stay finite (fuzz_proximity found an infinite gradient with |q| = 2e-146
// and lengths near 1e100, then accepted).
TEST(Scaling, SmallestQuaternionInTheLargestScene) {
  Eigen::MatrixX2d C(50, 2);
  for (int k = 0; k < 50; ++k) C.row(k) << std::cos(2 * M_PI * k / 50), std::sin(2 * M_PI * k / 50);
  const std::vector<Shape> shapes = {
      PaddedPolygon(C, Eigen::VectorXd::Constant(50, 0.99e100), 1e100), Capsule(1e100, 1e100)};
  const double smallest = 1.0000001e-40;  // just above the smallest accepted norm
  const Eigen::Vector4d tiny_q = smallest * Eigen::Vector4d(0.5, -0.5, 0.5, 0.5);
  const Pose far({-1e100, 1e100, -1e100}, tiny_q);
  const Pose near({1e100, -1e100, 1e100},
                  Eigen::Vector4d(0.3, 0.1, -0.2, 0.9).normalized() * smallest);
  for (const Shape& a : shapes) {
    for (const Shape& b : shapes) {
      const ProximityJacobian result = proximity_jacobian(a, far, b, near);
      EXPECT_TRUE(std::isfinite(result.phi));
      EXPECT_TRUE(result.gradient.allFinite());
      EXPECT_TRUE(result.points_jacobian.allFinite());
      EXPECT_GT(result.gradient.segment<4>(3).norm(), 1e200);  // large, as it must be
    }
  }
}

}  // namespace
}  // namespace diffpills::testing
