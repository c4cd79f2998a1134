// Every degenerate configuration of the core issue, each against an analytic answer: parallel,
// anti-parallel and collinear capsules, zero lengths, crossing cores, identical shapes at one
// pose, stacked and coplanar polygons, a capsule parallel to a polygon, extreme scales and the
// parallel / non-parallel boundary. Every output must be finite.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "diffpills/diffpills.hpp"
#include "proximity/polygon_features.hpp"
#include "support/random_shapes.hpp"
#include "support/reference.hpp"
#include "support/scene_helpers.hpp"

namespace diffpills::testing {
namespace {

template <class A, class B>
ProximityJacobian query(const A& a, const Pose& pa, const B& b, const Pose& pb) {
  ProximityJacobian result = proximity_jacobian(a, pa, b, pb);
  EXPECT_TRUE(std::isfinite(result.phi));
  EXPECT_TRUE(result.gradient.allFinite());
  EXPECT_TRUE(result.core_points_jacobian.allFinite());
  EXPECT_TRUE(result.points_jacobian.allFinite());
  EXPECT_TRUE(result.normal.allFinite());
  EXPECT_NEAR(result.normal.norm(), 1.0, 1e-12);
  return result;
}

// Central differences of phi along the 14 pose coordinates.
template <class A, class B>
Eigen::Matrix<double, 14, 1> phi_differences(const A& a, const Pose& pa, const B& b, const Pose& pb,
                                             double step) {
  Eigen::Matrix<double, 14, 1> x, out;
  x << pa.r(), pa.q(), pb.r(), pb.q();
  for (int j = 0; j < 14; ++j) {
    auto at = [&](double e) {
      Eigen::Matrix<double, 14, 1> y = x;
      y(j) += e;
      return proximity(a, Pose(y.segment<3>(0), y.segment<4>(3)), b,
                       Pose(y.segment<3>(7), y.segment<4>(10)))
          .phi;
    };
    out(j) = (at(step) - at(-step)) / (2 * step);
  }
  return out;
}

// Two parallel segments of length 2, the second shifted by 0.5 along x and 1 up: the optimal set
// is x in [-0.5, 1] on both; its midpoint 0.25 is returned. phi = 1 - (0.1 + 0.1)^2.
TEST(Degenerate, ParallelCapsulesTakeTheMiddleOfTheOverlap) {
  const Capsule a(2.0, 0.1), b(2.0, 0.1);
  const Pose pa({0, 0, 0}, kIdentity), pb({0.5, 0, 1}, kIdentity);
  const ProximityJacobian r = query(a, pa, b, pb);
  EXPECT_NEAR(r.phi, 1.0 - 0.04, 1e-14);
  EXPECT_LE((r.core_points[0] - Eigen::Vector3d(0.25, 0, 0)).norm(), 1e-14);
  EXPECT_LE((r.core_points[1] - Eigen::Vector3d(0.25, 0, 1)).norm(), 1e-14);
  EXPECT_LE((r.normal - Eigen::Vector3d::UnitZ()).norm(), 1e-14);
  // The midpoint choice makes the gradient equal the central difference even across the kink in
  // rotation (the average of the two one-sided derivatives). Across a kink the central difference
  // errs by O(step) (measured 3.5e-6 at step 1e-6), hence the small step.
  EXPECT_LE((r.gradient - phi_differences(a, pa, b, pb, 1e-8)).cwiseAbs().maxCoeff(), 1e-6);
  // Sliding the second segment keeps it parallel; the midpoint moves at half the rate.
  const ProximityJacobian slid = query(a, pa, b, Pose({0.6, 0, 1}, kIdentity));
  EXPECT_NEAR(slid.core_points[0].x(), 0.3, 1e-14);
}

TEST(Degenerate, AntiParallelCapsulesMatchParallel) {
  const Capsule a(2.0, 0.1), b(2.0, 0.1);
  const ProximityJacobian r =
      query(a, Pose({0, 0, 0}, kIdentity), b, Pose({0.5, 0, 1}, about(M_PI, 0, 0, 1)));
  EXPECT_NEAR(r.phi, 0.96, 1e-14);
  EXPECT_LE((r.core_points[0] - Eigen::Vector3d(0.25, 0, 0)).norm(), 1e-12);
  EXPECT_LE((r.core_points[1] - Eigen::Vector3d(0.25, 0, 1)).norm(), 1e-12);
}

TEST(Degenerate, CollinearCapsules) {
  const Capsule a(2.0, 0.1), b(2.0, 0.2);
  // End to end with a gap of 1: the facing end points.
  const ProximityJacobian apart =
      query(a, Pose({0, 0, 0}, kIdentity), b, Pose({3, 0, 0}, kIdentity));
  EXPECT_NEAR(apart.phi, 1.0 - 0.09, 1e-14);
  EXPECT_LE((apart.core_points[0] - Eigen::Vector3d(1, 0, 0)).norm(), 1e-14);
  EXPECT_LE((apart.core_points[1] - Eigen::Vector3d(2, 0, 0)).norm(), 1e-14);
  EXPECT_LE((apart.points[0] - Eigen::Vector3d(1.1, 0, 0)).norm(), 1e-14);
  EXPECT_LE((apart.points[1] - Eigen::Vector3d(1.8, 0, 0)).norm(), 1e-14);
  // Overlapping on one line: the cores intersect and the normal falls back to r2 - r1.
  const ProximityJacobian overlap =
      query(a, Pose({0, 0, 0}, kIdentity), b, Pose({1, 0, 0}, kIdentity));
  EXPECT_TRUE(overlap.cores_intersect);
  EXPECT_NEAR(overlap.phi, -0.09, 1e-14);
  EXPECT_LE((overlap.normal - Eigen::Vector3d::UnitX()).norm(), 1e-14);
  EXPECT_TRUE(overlap.gradient.isZero(1e-14));
}

TEST(Degenerate, ZeroLengthCapsulesAreSpheres) {
  const Capsule sphere_a(0.0, 0.3), sphere_b(0.0, 0.2), segment(2.0, 0.1);
  const ProximityJacobian spheres =
      query(sphere_a, Pose({0, 0, 0}, kIdentity), sphere_b, Pose({1, 2, 2}, kIdentity));
  EXPECT_NEAR(spheres.phi, 9.0 - 0.25, 1e-14);
  EXPECT_LE((spheres.normal - Eigen::Vector3d(1, 2, 2) / 3.0).norm(), 1e-15);
  Eigen::Matrix<double, 14, 1> expected;  // d|r1 - r2|^2 = 2 (r1 - r2) . (dr1 - dr2), no q terms
  expected << -2, -4, -4, 0, 0, 0, 0, 2, 4, 4, 0, 0, 0, 0;
  EXPECT_LE((spheres.gradient - expected).cwiseAbs().maxCoeff(), 1e-14);
  // A sphere beside a segment's end and above its middle.
  const ProximityJacobian end = query(sphere_a, Pose({3, 0, 0}, kIdentity), segment, Pose());
  EXPECT_NEAR(end.phi, 4.0 - 0.16, 1e-14);
  const ProximityJacobian middle = query(segment, Pose(), sphere_a, Pose({0.3, 2, 0}, kIdentity));
  EXPECT_NEAR(middle.phi, 4.0 - 0.16, 1e-14);
  EXPECT_LE((middle.core_points[0] - Eigen::Vector3d(0.3, 0, 0)).norm(), 1e-14);
  // A sphere above a polygon's face and beside its edge.
  const PaddedPolygon plate = square(1.0, 0.05);
  EXPECT_NEAR(query(sphere_a, Pose({0.2, 0.3, 2}, kIdentity), plate, Pose()).phi, 4.0 - 0.1225,
              1e-13);
  EXPECT_NEAR(query(plate, Pose(), sphere_a, Pose({3, 0.5, 0}, kIdentity)).phi, 4.0 - 0.1225,
              1e-13);
  // Two points at the same place: cores intersect, normal falls back to shape 1's body z.
  const ProximityJacobian same = query(sphere_a, Pose({1, 1, 1}, about(M_PI / 2, 1, 0, 0)),
                                       sphere_b, Pose({1, 1, 1}, kIdentity));
  EXPECT_TRUE(same.cores_intersect);
  EXPECT_LE((same.normal - Eigen::Vector3d(0, -1, 0)).norm(), 1e-14);  // R_x(90) z = -y
}

TEST(Degenerate, CrossingCores) {
  const Capsule a(2.0, 0.1), b(2.0, 0.2);
  const ProximityJacobian r =
      query(a, Pose({0, 0, 0}, kIdentity), b, Pose({0, 0, 0.5}, about(M_PI / 2, 0, 0, 1)));
  EXPECT_FALSE(r.cores_intersect);  // 0.5 apart: not crossing yet
  const ProximityJacobian crossing =
      query(a, Pose({0.3, 0, 0}, kIdentity), b, Pose({0, 0.2, 0}, about(M_PI / 2, 0, 0, 1)));
  EXPECT_TRUE(crossing.cores_intersect);
  EXPECT_NEAR(crossing.phi, -0.09, 1e-14);
  EXPECT_LE((crossing.core_points[0] - Eigen::Vector3d(0, 0, 0)).norm(), 1e-14);
  EXPECT_TRUE(crossing.gradient.isZero(1e-14));
  EXPECT_LE((crossing.normal - Eigen::Vector3d(-0.3, 0.2, 0).normalized()).norm(), 1e-14);
  // A segment piercing a polygon, and two polygons crossing each other.
  const PaddedPolygon plate = square(1.0, 0.05);
  const ProximityJacobian pierce =
      query(plate, Pose(), a, Pose({0.2, 0.1, 0.3}, about(M_PI / 2, 0, 1, 0)));
  EXPECT_TRUE(pierce.cores_intersect);
  EXPECT_NEAR(pierce.phi, -0.0225, 1e-14);
  EXPECT_LE((pierce.core_points[0] - Eigen::Vector3d(0.2, 0.1, 0)).norm(), 1e-9);
  const ProximityJacobian cross =
      query(plate, Pose(), plate, Pose({0.3, 0, 0.2}, about(M_PI / 2, 1, 0, 0)));
  EXPECT_TRUE(cross.cores_intersect);
  EXPECT_NEAR(cross.phi, -0.01, 1e-14);
}

// Cores within the tolerance (1e-12 of the scene) of each other intersect, and say so
// consistently: phi = -(R1 + R2)^2, not the tiny positive |p1 - p2|^2 (found by a hostile review:
// phi = 1e-18 with cores_intersect for a 1e6 capsule crossing another 1e-9 below it).
TEST(Degenerate, IntersectingWithinTheToleranceIsFlat) {
  const Capsule long_capsule(1e6, 0.0), short_capsule(1.0, 0.0);
  const Proximity p = proximity(long_capsule, Pose(), short_capsule,
                                Pose({0, 0, 1e-9}, {0.7071067811865476, 0, 0, 0.7071067811865476}));
  EXPECT_TRUE(p.cores_intersect);
  EXPECT_EQ(p.phi, 0.0);
  EXPECT_TRUE(p.gradient.isZero(0.0));
  const Proximity padded =
      proximity(Capsule(1e6, 0.5), Pose(), Capsule(1.0, 0.25),
                Pose({0, 0, 1e-9}, {0.7071067811865476, 0, 0, 0.7071067811865476}));
  EXPECT_EQ(padded.phi, -0.75 * 0.75);
}

TEST(Degenerate, IdenticalShapesAtTheSamePose) {
  const Pose pose({1, 2, 3}, about(0.7, 0.6, 0.8, 0));
  const Eigen::Vector3d body_z = rotation_matrix(pose.q()).col(2);
  const Capsule capsule(1.5, 0.2);
  const PaddedPolygon plate = square(0.5, 0.1);
  for (const ProximityJacobian& r :
       {query(capsule, pose, capsule, pose), query(plate, pose, plate, pose),
        query(capsule, pose, plate, pose), query(plate, pose, capsule, pose)}) {
    EXPECT_TRUE(r.cores_intersect);
    EXPECT_LE((r.normal - body_z).norm(), 1e-14);
    EXPECT_TRUE(r.gradient.isZero(1e-12));
  }
}

// Parallel planes one apart, the squares' projections overlapping: every pair above each other
// is closest. phi = 1 - (R1 + R2)^2, the points lie in both squares, p2 - p1 is vertical.
TEST(Degenerate, StackedParallelPolygons) {
  const PaddedPolygon a = square(1.0, 0.1), b = square(0.5, 0.2);
  const Pose pa({0, 0, 0}, kIdentity), pb({0.7, -0.2, 1}, about(0.4, 0, 0, 1));
  const ProximityJacobian r = query(a, pa, b, pb);
  EXPECT_NEAR(r.phi, 1.0 - 0.09, 1e-12);
  EXPECT_LE((r.core_points[1] - r.core_points[0] - Eigen::Vector3d::UnitZ()).norm(), 1e-9);
  EXPECT_LE(r.core_points[0].head<2>().cwiseAbs().maxCoeff(), 1.0 + 1e-9);
  // Translations keep the configuration degenerate: there phi is smooth and the gradient exact.
  const Eigen::Matrix<double, 14, 1> fd = phi_differences(a, pa, b, pb, 1e-6);
  for (int j : {0, 1, 2, 7, 8, 9}) EXPECT_NEAR(r.gradient(j), fd(j), 1e-7);
}

TEST(Degenerate, CoplanarPolygons) {
  const PaddedPolygon a = square(1.0, 0.1), b = square(1.0, 0.1);
  const ProximityJacobian apart = query(a, Pose(), b, Pose({3, 0.5, 0}, kIdentity));
  EXPECT_NEAR(apart.phi, 1.0 - 0.04, 1e-12);
  EXPECT_NEAR(apart.core_points[0].x(), 1.0, 1e-9);
  EXPECT_NEAR(apart.core_points[1].x(), 2.0, 1e-9);
  EXPECT_LE((apart.normal - Eigen::Vector3d::UnitX()).norm(), 1e-9);
  const ProximityJacobian overlap = query(a, Pose(), b, Pose({1, 0.5, 0}, about(0.3, 0, 0, 1)));
  EXPECT_TRUE(overlap.cores_intersect);
  EXPECT_NEAR(overlap.phi, -0.04, 1e-14);
}

TEST(Degenerate, CapsuleParallelToPolygonPlane) {
  const Capsule capsule(4.0, 0.1);
  const PaddedPolygon plate = square(1.0, 0.2);
  const Pose capsule_pose({0.2, 0.4, 1.5}, about(0.3, 0, 0, 1));
  const ProximityJacobian r = query(capsule, capsule_pose, plate, Pose());
  EXPECT_NEAR(r.phi, 2.25 - 0.09, 1e-12);
  EXPECT_LE((r.core_points[0] - r.core_points[1] - Eigen::Vector3d(0, 0, 1.5)).norm(), 1e-9);
  EXPECT_LE(r.core_points[1].head<2>().cwiseAbs().maxCoeff(), 1.0 + 1e-9);
  const ProximityJacobian swapped = query(plate, Pose(), capsule, capsule_pose);
  EXPECT_NEAR(swapped.phi, r.phi, 1e-12);
  const Eigen::Matrix<double, 14, 1> fd =
      phi_differences(capsule, capsule_pose, plate, Pose(), 1e-6);
  for (int j : {0, 1, 2, 7, 8, 9}) EXPECT_NEAR(r.gradient(j), fd(j), 1e-7);
}

// Two capsules turned by `angle` about the common perpendicular, at every scale: phi against the
// brute force and continuous through angle 0. A fixed absolute parallel threshold such as
// DiffPills.jl's 1e-4 would take angle 1e-3 at scale 1e-3 (det ~ 1e-12) for parallel; the
// relative test does not, and the answer stays exact.
TEST(Degenerate, ParallelBoundaryIsContinuousAtEveryScale) {
  for (double scale : {1e-3, 1.0, 1e3}) {
    const Capsule a(2.0 * scale, 0.1 * scale), b(1.5 * scale, 0.1 * scale);
    const Pose pa({0, 0, 0}, kIdentity);
    const Proximity parallel = proximity(a, pa, b, Pose({0.4 * scale, 0, scale}, kIdentity));
    for (double angle : {1e-12, 1e-9, 1e-7, 1e-5, 1e-3, 1e-1}) {
      for (double sign : {-1.0, 1.0}) {
        const Pose pb({0.4 * scale, 0, scale}, about(sign * angle, 0, 0, 1));
        const Proximity r = proximity(a, pa, b, pb);
        TestShape ta{a, {Eigen::Vector3d(-scale, 0, 0), Eigen::Vector3d(scale, 0, 0)}, scale};
        TestShape tb{
            b, {Eigen::Vector3d(-0.75 * scale, 0, 0), Eigen::Vector3d(0.75 * scale, 0, 0)}, scale};
        const long double d = brute_force_closest(to_world(ta, pa), to_world(tb, pb)).distance;
        const double expected = static_cast<double>(d * d) - 0.04 * scale * scale;
        EXPECT_NEAR(r.phi, expected, 1e-12 * scale * scale)
            << "scale " << scale << " angle " << angle;
        // The planes z = 0 and z = scale stay parallel: phi stays at its parallel value.
        EXPECT_NEAR(r.phi, parallel.phi, 1e-12 * scale * scale);
      }
    }
    // Tilted out of parallel within the plane of both segments: phi drops smoothly to zero
    // separation at the crossing angle, never jumps.
    double previous = parallel.phi;
    for (int k = 0; k < 18; ++k) {  // tilts 1e-6 2^k, up to 0.13
      const double tilt = std::ldexp(1e-6, k);
      const Proximity r = proximity(a, pa, b, Pose({0.4 * scale, 0, scale}, about(tilt, 0, 1, 0)));
      EXPECT_LE(r.phi, previous + 1e-12 * scale * scale);
      EXPECT_GE(r.phi, previous - 4.0 * tilt * scale * scale);  // Lipschitz in the angle
      previous = r.phi;
    }
  }
}

// A long capsule (length L from 2^40 up to 2^66 ~ 7e19) with a small shape near its middle, at a
// gap g = 2^-30 L (the cores intersect below 1e-12 L ~ 2^-40 L): the closest points are computed
// from the segments' middles, so the long capsule's point keeps the digits of its own offset (0.3
// here), and phi is g^2 to rounding. Anchored at the ends, the offset was lost to the rounding of L
// / 2 (a hostile review: a stick 1e9 beside a 1e20-long capsule got phi 1e18 + 1.2e8 and the point
// x = 11102 instead of 0.665). Analytic answers, both orders.
TEST(Degenerate, ShapesNearTheMiddleOfALongCapsule) {
  Eigen::MatrixX2d C(3, 2);
  C << 0, -1, 1, 1, -1, 1;
  const PaddedPolygon triangle(C.rowwise().normalized(), Eigen::Vector3d(0.5, 0.5, 0.5), 0.0);
  for (const int k : {40, 50, 66}) {
    SCOPED_TRACE(k);
    const double length = std::ldexp(1.0, k), gap = std::ldexp(1.0, k - 30);
    const Capsule rod(length, 0.0), dot(0.0, 0.0), stick(2.0, 0.0);
    const Pose along_x;
    // A point at (0.3, g, 0): the rod's point (0.3, 0, 0), phi = g^2.
    const Pose beside(Eigen::Vector3d(0.3, gap, 0.0), kIdentity);
    // A stick of length 2 through (0.3, g, 0.25), turned 0.6 rad about y: its point nearest the x
    // axis is at z = 0, s = 0.25 / sin 0.6 along it, and phi = g^2.
    const Pose tilted(Eigen::Vector3d(0.3, gap, 0.25), about(0.6, 0, 1, 0));
    const double stick_x = 0.3 + std::cos(0.6) * 0.25 / std::sin(0.6);
    // The triangle's edge y = -1/2 parallel to the rod: phi = (g - 1/2)^2, the rod's point the
    // middle of the edge's shadow, x = 0.3.
    for (const bool swap : {false, true}) {
      const auto query = [&](const auto& other, const Pose& pose) {
        const Proximity r =
            swap ? proximity(other, pose, rod, along_x) : proximity(rod, along_x, other, pose);
        return std::make_pair(r.phi, r.core_points[swap ? 1 : 0]);
      };
      const auto [phi_dot, on_rod_dot] = query(dot, beside);
      EXPECT_NEAR(phi_dot, gap * gap, 1e-14 * gap * gap);
      EXPECT_NEAR(on_rod_dot.x(), 0.3, 1e-14 * gap);
      const auto [phi_stick, on_rod_stick] = query(stick, tilted);
      EXPECT_NEAR(phi_stick, gap * gap, 1e-14 * gap * gap);
      EXPECT_NEAR(on_rod_stick.x(), stick_x, 1e-14 * gap);
      const auto [phi_triangle, on_rod_triangle] = query(triangle, beside);
      EXPECT_NEAR(phi_triangle, (gap - 0.5) * (gap - 0.5), 1e-14 * gap * gap);
      EXPECT_NEAR(on_rod_triangle.x(), 0.3, 1e-14 * gap);
    }
  }
}

TEST(Degenerate, ExtremeScalesWithMixedSizes) {
  // A tiny capsule against a huge polygon, far from the origin, both orders.
  const Capsule tiny(1e-3, 1e-4);
  const PaddedPolygon huge = square(1e3, 1.0);
  const Pose tiny_pose({500, -200, 3}, about(0.3, 1, 0, 0));
  const ProximityJacobian r = query(tiny, tiny_pose, huge, Pose({0, 0, 0}, kIdentity));
  const double lowest_z = 3.0 - 0.5e-3 * std::sin(0.0);  // the segment lies along x: z constant
  EXPECT_NEAR(std::sqrt(r.phi + std::pow(1.0 + 1e-4, 2)), lowest_z, 1e-9);
  const ProximityJacobian s = query(huge, Pose(), tiny, tiny_pose);
  EXPECT_NEAR(s.phi, r.phi, 1e-9);
}

// A scene of subnormal numbers: the frame stops at 2^-1000 (pair_frame.hpp), so the scene is
// 2^-52 in it rather than 1. The normal rules used to take its size as 1: any feature normal then
// "agreed" with the closest points' direction, and two capsules of length 5e-324, 1e-317 apart
// along x, got the normal z (fuzz_proximity). The normal follows the points again, for proximity
// and the signed distance, and the witness points differ by distance * normal.
TEST(Degenerate, SubnormalSceneNormalFollowsThePoints) {
  const double m = std::numeric_limits<double>::denorm_min();
  const Capsule a(m, m), b(m, m);
  const Pose pose_a({m, m, m}, Eigen::Vector4d(std::sqrt(0.5), 0, 0, std::sqrt(0.5)));
  const Pose pose_b({-1.0361307573072619e-317, m, m}, Eigen::Vector4d(-0.5, 0.5, -0.5, 0.5));
  const Eigen::Vector3d along(-1, 0, 0);
  for (const bool swapped : {false, true}) {
    const double sign = swapped ? -1.0 : 1.0;
    const Proximity p = swapped ? proximity(b, pose_b, a, pose_a) : proximity(a, pose_a, b, pose_b);
    EXPECT_LT((p.normal - sign * along).norm(), 1e-12) << swapped;
    const SignedDistance s =
        swapped ? signed_distance(b, pose_b, a, pose_a) : signed_distance(a, pose_a, b, pose_b);
    EXPECT_FALSE(s.penetrating);
    EXPECT_LT((s.normal - sign * along).norm(), 1e-12) << swapped;
    EXPECT_LE((s.points[1] - s.points[0] - s.distance * s.normal).lpNorm<Eigen::Infinity>(), 8 * m);
  }
}

// Slivers: spikes whose rows, grown by the tolerance, would meet far beyond the apex (at
// tolerance / sin(half the apex angle): a whole scene away for an apex of 1e-11), so the tolerance
// of "within the polygon" is bevelled at spikes (polygon_features.hpp). Against capsules and
// polygons at random poses, both orders, phi and the signed distance of apart cores equal the
// brute force's on the triangle written by hand from the rows:
//   - x <= e, y <= e, -x <= e, -y <= 1 with rows at 0, 90, 180 and 270 degrees as cos and sin round
//     them (6e-17 off), e from 1e-300 to 1e-20: the reduction keeps an apex of two nearly opposite
//     rows (shapes.hpp); apex at the origin, base corners (-1.2246e-16, -1) and (0, -1), within
//     1e-16 of the true corners;
//   - x <= e, -x + s y <= e, -y <= 1 (s = 1e-11, e = 1e-13, accepted and answered wrongly before
//     the bevels, 0.5% of random poses): apex (e, 2e / s), base corners (-e - s, -1) and (e, -1).
// And the parallel case: a square in a plane 0.01 above the spike's, 0.03 beyond its apex.
TEST(Degenerate, SliversAgainstTheBruteForce) {
  Eigen::MatrixX2d rounded(4, 2);
  for (int i = 0; i < 4; ++i) rounded.row(i) << std::cos(i * M_PI / 2), std::sin(i * M_PI / 2);
  std::vector<TestShape> slivers;
  for (const double e : {1e-300, 1e-100, 1e-20}) {
    slivers.push_back({PaddedPolygon(rounded, Eigen::Vector4d(e, e, e, 1.0), 0.05),
                       {Eigen::Vector3d::Zero(), Eigen::Vector3d(-1.2246467991473532e-16, -1, 0),
                        Eigen::Vector3d(0, -1, 0)},
                       1.0});
  }
  const double s = 1e-11, e = 1e-13;
  Eigen::MatrixX2d spike_rows(3, 2);
  spike_rows << 1, 0, -1, s, 0, -1;
  slivers.push_back({PaddedPolygon(spike_rows, Eigen::Vector3d(e, e, 1.0), 0.05),
                     {Eigen::Vector3d(e, 2 * e / s, 0), Eigen::Vector3d(-e - s, -1, 0),
                      Eigen::Vector3d(e, -1, 0)},
                     1.0});
  Rng rng(41);
  for (std::size_t k = 0; k < slivers.size(); ++k) {
    const TestShape& sliver = slivers[k];
    for (int trial = 0; trial < 400; ++trial) {
      const TestShape other = trial % 2 ? random_capsule(rng, 1.0) : random_polygon(rng, 1.0);
      const Pose pa = random_pose(rng, 1.0), pb = random_pose(rng, 1.0);
      const double radii = 0.05 + std::visit([](const auto& x) { return x.radius(); }, other.shape);
      const long double gap =
          brute_force_closest(to_world(sliver, pa), to_world(other, pb)).distance;
      if (gap < 1e-9) continue;  // intersecting cores: phi is flat, checked elsewhere
      const double expected = static_cast<double>(gap * gap) - radii * radii;
      EXPECT_NEAR(proximity(sliver.shape, pa, other.shape, pb).phi, expected, 1e-12)
          << "sliver " << k << " trial " << trial;
      EXPECT_NEAR(proximity(other.shape, pb, sliver.shape, pa).phi, expected, 1e-12)
          << "sliver " << k << " trial " << trial;
      EXPECT_NEAR(signed_distance(sliver.shape, pa, other.shape, pb).distance,
                  static_cast<double>(gap) - radii, 1e-12)
          << "sliver " << k << " trial " << trial;
    }
  }
  const PaddedPolygon& spike = std::get<PaddedPolygon>(slivers.back().shape);
  const PaddedPolygon plate = square(0.05, 0.0);
  const Pose above({0, 2 * e / s + 0.08, 0.01}, kIdentity);  // the plate's near edge 0.03 beyond
  const double expected = 0.03 * 0.03 + 0.01 * 0.01 - 0.05 * 0.05;
  EXPECT_NEAR(proximity(spike, Pose(), plate, above).phi, expected, 1e-12);
  EXPECT_NEAR(proximity(plate, above, spike, Pose()).phi, expected, 1e-12);
}

// A needle polygon against another shape, both orders: the default path's phi to 1e-12 of the
// expected one; the interior-point reference's to 1e-6, or SolverError, the documented answer
// where the reference cannot resolve the spike.
template <class Other>
void expect_needle_answers(const PaddedPolygon& needle, const Pose& needle_pose, const Other& other,
                           const Pose& other_pose, double expected) {
  EXPECT_NEAR(proximity(needle, needle_pose, other, other_pose).phi, expected, 1e-12);
  EXPECT_NEAR(proximity(other, other_pose, needle, needle_pose).phi, expected, 1e-12);
  for (const bool swapped : {false, true}) {
    try {
      const double phi =
          swapped ? proximity(other, other_pose, needle, needle_pose, {Method::kInteriorPoint}).phi
                  : proximity(needle, needle_pose, other, other_pose, {Method::kInteriorPoint}).phi;
      EXPECT_NEAR(phi, expected, 1e-6) << "swapped " << swapped;
    } catch (const SolverError&) {
    }
  }
}

// fuzz_proximity's needle: a strip 1.2e-91 wide whose two sides differ in direction by 3e-16, so
// that they cross 4e-76 from the origin; the row through the origin (d = 1e-300) is dropped as
// cutting off nothing resolvable, and the polygon is a triangle 1.4 long and 5e-15 wide at its
// far end. Beyond its apex, points satisfy both sides to rounding: the interior-point reference
// returned one 0.4 beyond the tip (phi 0.16 too small). The default path is exact against the
// vertices written out here; the reference either agrees or reports SolverError.
TEST(Degenerate, NeedleWhoseApexIsBelowTheRounding) {
  const Eigen::Vector2d strip(0.20260703884442144, 0.97926012264908202);
  Eigen::MatrixX2d C(4, 2);
  C << -strip.transpose(), 0.20260703884442111, 0.97926012264908202, -0.47679923006332192,
      0.87901222642863353, -0.11479492660650993, -0.99338921114808065;
  const PaddedPolygon needle(
      C, Eigen::Vector4d(6.1363668316221582e-92, 6.1363668316221582e-92, 1e-300, 0.125), 0.0);
  const Pose pose({2, 1.25, 1.25}, {-0.5, 0.5, -0.5, 0.5});
  const Capsule capsule(2.875, 2.875);
  const Pose capsule_pose({1.25, 1.25, -0.75}, kIdentity);
  // The needle as a segment from the origin along t = (strip.y, -strip.x) to row 3's cut at
  // 0.125 / ((-0.1148, -0.9934) . t): its width (< 1e-14) is below what the check resolves.
  const Eigen::Vector2d t(strip.y(), -strip.x());
  const double length = 0.125 / C.row(3).dot(t);
  const TestShape as_segment{
      needle, {Eigen::Vector3d::Zero(), Eigen::Vector3d(t.x(), t.y(), 0) * length}, 1.0};
  const TestShape core{
      capsule, {Eigen::Vector3d(-1.4375, 0, 0), Eigen::Vector3d(1.4375, 0, 0)}, 1.0};
  const long double gap =
      brute_force_closest(to_world(as_segment, pose), to_world(core, capsule_pose)).distance;
  const double expected = static_cast<double>(gap * gap) - 2.875 * 2.875;
  expect_needle_answers(needle, pose, capsule, capsule_pose, expected);
}

// fuzz_proximity's second needle: two sides whose normals differ from opposite by ~2e-172, so
// that the bevel at the apex (the sum of the two normals, normalized) has a squared norm that
// underflows. Eigen's normalized() returned it unscaled, 2e-172 long, and the bevel cut nothing:
// the interior-point reference's point 1.2 beyond the tip passed check_inside and phi came out
// 1.41 too small. The rows as the fuzzer wrote them (most redundant); the polygon is the triangle
// with apex (~0, 1/16) and base y = -1/24 at x ~ 1e-173.
TEST(Degenerate, NeedleWhoseBevelNormalUnderflows) {
  Eigen::MatrixX2d C(17, 2);
  C << -5.8025197824417076e-50, 1.25, 1e-300, 1e-300, 1.25, 1.25, 1.25, 0.125, 0.125,
      1.506200933628582e-314, 0.125, 2.8413210118836735e-173, 0.125, 0.125, -1.75, 0.125, 0.125,
      0.125, 0.125, 0.125, -0.375, -3, 1e-300, 0.125, 1.25, 3, 7.8303653615982294e-54, 2.625,
      -1e+100, 1.25, 1.25, 0.125, -1.875, 2.841321139066013e-173;
  Eigen::VectorXd d(17);
  d << 1.25, 1.25, 1.25, 0.125, 0.125, 1e-300, 0.125, 0.125, 0.125, 0.125, 0.125, 0.125, 3, 2.625,
      1.25, 0.125, 2.841321139066013e-173;
  const PaddedPolygon needle(C, d, 2.811931526054308e-242);
  const detail::PolygonView view(needle, 1.0);
  EXPECT_TRUE(detail::contains(view, Eigen::Vector2d(0, 0.06), 1e-9));
  EXPECT_FALSE(detail::contains(view, Eigen::Vector2d(0, 0.07), 1e-9));  // beyond the apex
  EXPECT_FALSE(detail::contains(view, Eigen::Vector2d(0, 1.25), 1e-9));

  Eigen::MatrixX2d triangle_rows(3, 2);
  triangle_rows << 1, 0, -0.49999999999999978, 0.86602540378443871, -0.50000000000000044,
      -0.86602540378443837;
  const double tiny = 2.841321139066013e-173;
  const PaddedPolygon speck(triangle_rows, Eigen::Vector3d::Constant(tiny), tiny);
  const Pose needle_pose({0.125, 0.125, 1.25}, {0.70710678118654757, -0.70710678118654757, 0, 0});
  const Pose speck_pose(
      {-7.1600071019521985e-153, -7.1600071019521985e-153, -5.7528439046457733e-93},
      {0.5, 0.5, 0.5, 0.5});
  // The needle's body y runs along world -z from z = 1.25: its tip is the closest point to the
  // speck at the origin (within 1e-92). The tip is where rows 5 and 16 meet: 0.125 x + a y =
  // 1e-300 and -1.875 x + b y = b give y = (b + 1.5e-299) / (15 a + b), x ~ 1e-173.
  const double a = C(5, 1), b = C(16, 1);
  const double tip = (b + 1.5e-299) / (15 * a + b);
  const double expected = 0.125 * 0.125 * 2 + (1.25 - tip) * (1.25 - tip);
  expect_needle_answers(needle, needle_pose, speck, speck_pose, expected);
}

}  // namespace
}  // namespace diffpills::testing
