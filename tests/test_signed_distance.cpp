// The signed distance (signed_distance.hpp), against computations written apart from it:
//   - a brute-force reference over the facets of the convex hull of the cores' vertex differences
//     (support/reference.hpp), on 10^4 random pairs apart and in penetration;
//   - FCL's signed distance for capsule pairs;
//   - central finite differences of the distance and of the points, on 1,000 random pairs per
//     ordering, in penetration and apart, at several scales;
//   - analytic cases, the properties (swap, rigid motion, exact power-of-two scaling, agreement
//     with proximity() apart, a step along the normal) and the degenerate cases.
#include <fcl/geometry/shape/capsule.h>
#include <fcl/narrowphase/distance.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "diffpills/diffpills.hpp"
#include "support/fcl_pose.hpp"
#include "support/random_shapes.hpp"
#include "support/reference.hpp"
#include "support/scene_helpers.hpp"

namespace diffpills::testing {
namespace {

using Gradient = Eigen::Matrix<double, 14, 1>;

// The four orderings of the two shape types.
enum class Pair { kCapsuleCapsule, kCapsulePolygon, kPolygonCapsule, kPolygonPolygon };
const Pair kPairs[] = {Pair::kCapsuleCapsule, Pair::kCapsulePolygon, Pair::kPolygonCapsule,
                       Pair::kPolygonPolygon};

std::string name(Pair pair) {
  switch (pair) {
    case Pair::kCapsuleCapsule:
      return "capsule-capsule";
    case Pair::kCapsulePolygon:
      return "capsule-polygon";
    case Pair::kPolygonCapsule:
      return "polygon-capsule";
    default:
      return "polygon-polygon";
  }
}

struct Case {
  TestShape a, b;
  Pose pose_a, pose_b;
  double scale = 1.0;
};

// Shapes of size ~scale, posed within `spread` * scale of each other: a spread below 1 makes most
// pairs intersect, one above 2 most of them apart.
Case random_case(Rng& rng, Pair pair, double scale, double spread) {
  const bool a_capsule = pair == Pair::kCapsuleCapsule || pair == Pair::kCapsulePolygon;
  const bool b_capsule = pair == Pair::kCapsuleCapsule || pair == Pair::kPolygonCapsule;
  const TestShape a = a_capsule ? random_capsule(rng, scale, 0.05) : random_polygon(rng, scale);
  const TestShape b = b_capsule ? random_capsule(rng, scale, 0.05) : random_polygon(rng, scale);
  const Pose pose_a = random_pose(rng, spread * scale);
  const Pose pose_b = random_pose(rng, spread * scale);
  return {a, b, pose_a, pose_b, scale};
}

double radius(const Shape& shape) {
  return std::visit([](const auto& s) { return s.radius(); }, shape);
}

SignedDistanceJacobian evaluate(const Case& c) {
  return signed_distance_jacobian(c.a.shape, c.pose_a, c.b.shape, c.pose_b);
}

// The pose after moving coordinate k (0-2: r, 3-6: q) by h.
Pose moved(const Pose& pose, int k, double h) {
  Eigen::Vector3d r = pose.r();
  Eigen::Vector4d q = pose.q();
  if (k < 3) {
    r(k) += h;
  } else {
    q(k - 3) += h;
  }
  return Pose(r, q);
}

// Central differences of f over the 14 pose coordinates; r steps are h * scale, q steps h.
template <class F>
auto central_differences(const Case& c, double h, const F& f) {
  using Value = decltype(f(c.pose_a, c.pose_b));
  std::vector<Value> columns;
  for (int k = 0; k < 14; ++k) {
    const int local = k % 7;
    const double step = local < 3 ? h * c.scale : h;
    const bool first = k < 7;
    const Pose plus_a = first ? moved(c.pose_a, local, step) : c.pose_a;
    const Pose minus_a = first ? moved(c.pose_a, local, -step) : c.pose_a;
    const Pose plus_b = first ? c.pose_b : moved(c.pose_b, local, step);
    const Pose minus_b = first ? c.pose_b : moved(c.pose_b, local, -step);
    columns.push_back((f(plus_a, plus_b) - f(minus_a, minus_b)) / (2.0 * step));
  }
  return columns;
}

TEST(SignedDistance, AgreesWithBruteForceHullOnTenThousandPairs) {
  Rng rng(20261123);
  for (const Pair pair : kPairs) {
    double worst = 0.0;
    int penetrating = 0;
    for (int i = 0; i < 2500; ++i) {
      const double scale = i % 3 == 0 ? 1e-3 : (i % 3 == 1 ? 1.0 : 1e4);
      const Case c = random_case(rng, pair, scale, i % 2 == 0 ? 0.15 : 1.5);
      const SignedDistance ours = signed_distance(c.a.shape, c.pose_a, c.b.shape, c.pose_b);
      const SignedCoreDistance reference = brute_force_signed_distance(
          to_world(c.a, c.pose_a), to_world(c.b, c.pose_b), static_cast<long double>(scale));
      const double expected =
          static_cast<double>(reference.s) - radius(c.a.shape) - radius(c.b.shape);
      const double error = std::abs(ours.distance - expected) / scale;
      worst = std::max(worst, error);
      ASSERT_LE(error, 1e-9) << name(pair) << " case " << i << ": ours " << ours.distance
                             << ", hull " << expected;
      // The witnesses: points[1] - points[0] = distance * normal, on the two cores.
      EXPECT_LE((ours.points[1] - ours.points[0] - ours.distance * ours.normal).norm(),
                1e-9 * scale);
      EXPECT_LE(distance_to_core(ours.core_points[0], to_world(c.a, c.pose_a)), 1e-12L * scale);
      EXPECT_LE(distance_to_core(ours.core_points[1], to_world(c.b, c.pose_b)), 1e-12L * scale);
      EXPECT_NEAR(ours.normal.norm(), 1.0, 1e-14);
      if (reference.s < -1e-6L * scale) {
        ++penetrating;
        EXPECT_TRUE(ours.penetrating);
      }
    }
    std::cout << "[hull] " << name(pair) << ": 2500 pairs, " << penetrating
              << " in penetration, max |distance - hull| / scale " << worst << "\n";
    if (pair != Pair::kCapsuleCapsule) {
      EXPECT_GT(penetrating, 400);  // (the D of two segments is flat: s >= 0)
    }
  }
}

// Cores crossing nearly coplanar (10^-2 .. 10^-12 rad): D is thin and many of its facets are
// nearly as deep as the nearest one. The chosen facet's witnesses must lie on the two cores
// (choosing among all facets, a tie-break once took one whose nearest point was off it, and the
// witnesses lay off the cores by up to the scene's size), points[1] - points[0] = distance *
// normal, and the depth is the separating-axis brute force's.
TEST(SignedDistance, NearlyCoplanarCrossingsHaveWitnessesOnTheCores) {
  Rng rng(20261124);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (const Pair pair : {Pair::kPolygonPolygon, Pair::kCapsulePolygon}) {
    int penetrating = 0;
    double worst_off = 0.0, worst_depth = 0.0;
    for (int i = 0; i < 3000; ++i) {
      Case c = random_case(rng, pair, 1.0, 0.0);
      // a's plane (or a capsule's axis) turned off b's plane by the tilt, a's origin near b's
      // plane.
      const Eigen::Quaterniond base =
          Eigen::Quaterniond(c.pose_b.q()(0), c.pose_b.q()(1), c.pose_b.q()(2), c.pose_b.q()(3))
              .normalized();
      const double tilt = std::pow(10.0, -2.0 - 10.0 * uniform(rng));
      const Eigen::Quaterniond turned =
          base *
          Eigen::Quaterniond(Eigen::AngleAxisd(
              tilt, Eigen::Vector3d(uniform(rng) - 0.5, uniform(rng) - 0.5, 0).normalized()));
      const Eigen::Quaterniond flat_capsule =
          base *
          Eigen::Quaterniond(Eigen::AngleAxisd(6.3 * uniform(rng), Eigen::Vector3d::UnitZ())) *
          Eigen::Quaterniond(Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitY()));
      const Eigen::Quaterniond qa = pair == Pair::kPolygonPolygon ? turned : flat_capsule;
      c.pose_a = Pose(c.pose_b.r() + base * Eigen::Vector3d(uniform(rng) - 0.5, uniform(rng) - 0.5,
                                                            (uniform(rng) - 0.5) * tilt),
                      Eigen::Vector4d(qa.w(), qa.x(), qa.y(), qa.z()));
      const SignedDistance sd = signed_distance(c.a.shape, c.pose_a, c.b.shape, c.pose_b);
      if (!sd.penetrating) continue;
      ++penetrating;
      const WorldCore wa = to_world(c.a, c.pose_a), wb = to_world(c.b, c.pose_b);
      const double off = static_cast<double>(std::max(distance_to_core(sd.core_points[0], wa),
                                                      distance_to_core(sd.core_points[1], wb)));
      worst_off = std::max(worst_off, off);
      ASSERT_LE(off, 1e-12) << name(pair) << " case " << i;
      // (Cores within the tolerance, 1e-12 of the scene, keep their closest points: 4e-12.)
      ASSERT_LE((sd.points[1] - sd.points[0] - sd.distance * sd.normal).norm(), 4e-12)
          << name(pair) << " case " << i;
      const double depth = static_cast<double>(brute_force_penetration_depth(wa, wb));
      const double error = std::abs(sd.distance + radius(c.a.shape) + radius(c.b.shape) + depth);
      worst_depth = std::max(worst_depth, error);
      ASSERT_LE(error, 4e-12) << name(pair) << " case " << i;  // ties: 1e-12 of a scene < 4
    }
    std::cout << "[nearly coplanar] " << name(pair) << ": " << penetrating
              << " in penetration, witnesses off the cores by at most " << worst_off
              << ", |depth - separating axes| at most " << worst_depth << "\n";
    EXPECT_GT(penetrating, 1000);
  }
}

// FCL's signed capsule distance is |p1 - p2| - R1 - R2 also when the capsules overlap (two
// segments have a flat D, so s = |p1 - p2| >= 0): the same as ours. Apart, FCL's own capsule
// distance is exact; for overlapping capsules FCL 0.7 offers only its libccd GJK/EPA, which
// stops at a tolerance of 1e-6 (asked for 1e-12, its EPA asserts), so agreement is to that.
constexpr double kFclSignedTolerance = 1e-5;  // 1e-6 seen

TEST(SignedDistance, CapsulePairsAgreeWithFcl) {
  Rng rng(5);
  int overlapping = 0;
  double worst_apart = 0.0, worst_overlapping = 0.0;
  for (int i = 0; i < 3000; ++i) {
    const Case c = random_case(rng, Pair::kCapsuleCapsule, 1.0, i % 2 == 0 ? 0.3 : 1.0);
    const auto& ca = std::get<Capsule>(c.a.shape);
    const auto& cb = std::get<Capsule>(c.b.shape);
    const SignedDistance ours = signed_distance(ca, c.pose_a, cb, c.pose_b);
    fcl::Capsuled fa(ca.radius(), ca.length());
    fcl::Capsuled fb(cb.radius(), cb.length());
    fcl::DistanceRequestd request;
    request.enable_signed_distance = ours.distance < 0.0;
    fcl::DistanceResultd result;
    fcl::distance(&fa, fcl_capsule_transform(c.pose_a), &fb, fcl_capsule_transform(c.pose_b),
                  request, result);
    const double error = std::abs(ours.distance - result.min_distance);
    if (ours.distance < 0.0) {
      ++overlapping;
      worst_overlapping = std::max(worst_overlapping, error);
      ASSERT_LE(error, kFclSignedTolerance)
          << "case " << i << ": ours " << ours.distance << ", FCL " << result.min_distance;
    } else {
      worst_apart = std::max(worst_apart, error);
      ASSERT_LE(error, 1e-9) << "case " << i << ": ours " << ours.distance << ", FCL "
                             << result.min_distance;
    }
  }
  std::cout << "[fcl] 3000 capsule pairs: " << overlapping << " overlapping, max |distance - FCL| "
            << worst_overlapping << "; apart " << worst_apart << "\n";
  EXPECT_GT(overlapping, 500);
}

// Finite differences of the distance (the gradient) and of the points (the Jacobians), on 1,000
// random pairs per ordering. Where the answer has a kink within the step (a change of facet or of
// closest features, a tie) the difference quotients at steps h and h / 4 disagree; such cases are
// counted and skipped, and must stay rare.
TEST(SignedDistance, DerivativesMatchFiniteDifferences) {
  Rng rng(77);
  for (const Pair pair : kPairs) {
    int checked = 0, skipped = 0, penetrating = 0;
    for (int i = 0; i < 1000; ++i) {
      const double scale = i % 4 == 0 ? 1e-4 : (i % 4 == 1 ? 1.0 : (i % 4 == 2 ? 1e3 : 1e8));
      const Case c = random_case(rng, pair, scale, i % 2 == 0 ? 0.15 : 1.5);
      const SignedDistanceJacobian result = evaluate(c);
      const auto distance = [&](const Pose& a, const Pose& b) {
        return signed_distance(c.a.shape, a, c.b.shape, b).distance;
      };
      const auto points = [&](const Pose& a, const Pose& b) -> Eigen::Matrix<double, 6, 1> {
        const SignedDistance r = signed_distance(c.a.shape, a, c.b.shape, b);
        Eigen::Matrix<double, 6, 1> stacked;
        stacked << r.points[0], r.points[1];
        return stacked;
      };
      const auto fd = central_differences(c, 1e-6, distance);
      const auto fd_fine = central_differences(c, 0.25e-6, distance);
      const auto fd_points = central_differences(c, 1e-6, points);
      const auto fd_points_fine = central_differences(c, 0.25e-6, points);
      bool smooth = true;
      for (int k = 0; k < 14; ++k) {
        const double unit = k % 7 < 3 ? 1.0 : scale;  // d/dr is a number, d/dq a length
        smooth = smooth && std::abs(fd[k] - fd_fine[k]) <= 1e-5 * unit &&
                 (fd_points[k] - fd_points_fine[k]).norm() <= 1e-5 * unit;
      }
      if (!smooth) {
        ++skipped;
        continue;
      }
      ++checked;
      if (result.penetrating) ++penetrating;
      for (int k = 0; k < 14; ++k) {
        const double unit = k % 7 < 3 ? 1.0 : scale;
        ASSERT_NEAR(result.gradient(k), fd[k], 1e-6 * unit)
            << name(pair) << " case " << i << " coordinate " << k
            << (result.penetrating ? " (penetrating)" : " (apart)");
        ASSERT_LE((result.points_jacobian.col(k) - fd_points[k]).norm(), 1e-5 * unit)
            << name(pair) << " case " << i << " coordinate " << k
            << (result.penetrating ? " (penetrating)" : " (apart)");
      }
    }
    std::cout << "[fd] " << name(pair) << ": " << checked << " checked (" << penetrating
              << " penetrating), " << skipped << " skipped at a kink\n";
    EXPECT_LE(skipped, 30);
    if (pair != Pair::kCapsuleCapsule) {
      EXPECT_GT(penetrating, 200);
    }
  }
}

// Swapping the shapes: the same distance, the points swapped, the normal reversed and the
// gradient's halves exchanged. Moving the whole scene rigidly: the same distance, the points and
// normal moved with it.
TEST(SignedDistance, SwapAndRigidMotion) {
  Rng rng(8);
  for (const Pair pair : kPairs) {
    for (int i = 0; i < 500; ++i) {
      const Case c = random_case(rng, pair, 1.0, i % 2 == 0 ? 0.3 : 1.5);
      const SignedDistance ab = signed_distance(c.a.shape, c.pose_a, c.b.shape, c.pose_b);
      const SignedDistance ba = signed_distance(c.b.shape, c.pose_b, c.a.shape, c.pose_a);
      ASSERT_NEAR(ab.distance, ba.distance, 1e-12) << name(pair) << " case " << i;
      EXPECT_LE((ab.points[0] - ba.points[1]).norm(), 1e-9);
      EXPECT_LE((ab.points[1] - ba.points[0]).norm(), 1e-9);
      EXPECT_LE((ab.normal + ba.normal).norm(), 1e-9);
      EXPECT_LE((ab.gradient.head<7>() - ba.gradient.tail<7>()).norm(), 1e-8);

      const Eigen::Quaterniond turn = Eigen::Quaterniond::UnitRandom();
      const Eigen::Vector3d shift = Eigen::Vector3d::Random() * 3.0;
      const SignedDistance moved_pair =
          signed_distance(c.a.shape, rigidly_moved(c.pose_a, turn, shift), c.b.shape,
                          rigidly_moved(c.pose_b, turn, shift));
      ASSERT_NEAR(moved_pair.distance, ab.distance, 1e-11) << name(pair) << " case " << i;
      EXPECT_LE((moved_pair.normal - turn * ab.normal).norm(), 1e-8);
      EXPECT_LE((moved_pair.points[0] - (turn * ab.points[0] + shift)).norm(), 1e-8);
    }
  }
}

// Scaling every length by 2^k: distance and points by 2^k, the gradient's position part
// unchanged and its quaternion part by 2^k, the Jacobians' quaternion columns by 2^k: exactly.
TEST(SignedDistance, PowerOfTwoScalingIsExact) {
  Rng rng(9);
  for (const Pair pair : kPairs) {
    for (int i = 0; i < 200; ++i) {
      const Case c = random_case(rng, pair, 1.0, i % 2 == 0 ? 0.3 : 1.5);
      const SignedDistanceJacobian base = evaluate(c);
      for (const int k : {-300, -40, 7, 300}) {
        const auto scaled_shape = [&](const Shape& shape) -> Shape {
          if (const auto* capsule = std::get_if<Capsule>(&shape)) {
            return Capsule(std::ldexp(capsule->length(), k), std::ldexp(capsule->radius(), k));
          }
          const auto& polygon = std::get<PaddedPolygon>(shape);
          Eigen::VectorXd d = polygon.constraint_offsets();
          for (Eigen::Index j = 0; j < d.size(); ++j) d(j) = std::ldexp(d(j), k);
          return PaddedPolygon(polygon.constraint_matrix(), d, std::ldexp(polygon.radius(), k));
        };
        const auto scaled_pose = [&](const Pose& pose) {
          Eigen::Vector3d r = pose.r();
          for (int j = 0; j < 3; ++j) r(j) = std::ldexp(r(j), k);
          return Pose(r, pose.q());
        };
        const SignedDistanceJacobian big =
            signed_distance_jacobian(scaled_shape(c.a.shape), scaled_pose(c.pose_a),
                                     scaled_shape(c.b.shape), scaled_pose(c.pose_b));
        const double f = std::ldexp(1.0, k);
        ASSERT_EQ(big.distance, base.distance * f) << name(pair) << " case " << i << " k " << k;
        EXPECT_EQ(big.points[0], base.points[0] * f);
        EXPECT_EQ(big.points[1], base.points[1] * f);
        EXPECT_EQ(big.normal, base.normal);
        EXPECT_EQ(big.gradient.segment<3>(0), base.gradient.segment<3>(0));
        EXPECT_EQ(big.gradient.segment<4>(3), base.gradient.segment<4>(3) * f);
        EXPECT_EQ(big.points_jacobian.middleCols<4>(10),
                  base.points_jacobian.middleCols<4>(10) * f);
      }
    }
  }
}

// Apart, the signed distance is |p1 - p2| - R1 - R2 of proximity()'s closest points, and its
// gradient is proximity's d phi / (2 |p1 - p2|). The closest points are the same bits, except for
// two capsules: proximity() takes their fused pass (capsule_proximity.hpp, which forms each axis
// from the raw quaternion), and it agrees with the general pipeline the signed distance runs to
// rounding (proximity.hpp's kDefault), here within 1e-14 of the coordinates' size (at most ~6).
TEST(SignedDistance, ApartItIsTheProximitysDistance) {
  Rng rng(10);
  for (const Pair pair : kPairs) {
    for (int i = 0; i < 500; ++i) {
      const Case c = random_case(rng, pair, 1.0, 3.0);
      const Proximity p = proximity(c.a.shape, c.pose_a, c.b.shape, c.pose_b);
      if (p.cores_intersect) continue;
      const SignedDistance sd = signed_distance(c.a.shape, c.pose_a, c.b.shape, c.pose_b);
      const double gap = (p.core_points[1] - p.core_points[0]).norm();
      EXPECT_FALSE(sd.penetrating);
      EXPECT_NEAR(sd.distance, gap - radius(c.a.shape) - radius(c.b.shape), 1e-14);
      for (int k = 0; k < 2; ++k) {
        if (pair == Pair::kCapsuleCapsule) {
          EXPECT_LE((sd.core_points[k] - p.core_points[k]).cwiseAbs().maxCoeff(), 6e-14);
        } else {
          EXPECT_EQ(sd.core_points[k], p.core_points[k]);
        }
      }
      EXPECT_LE((sd.gradient - p.gradient / (2.0 * gap)).norm(), 1e-9 * (1 + sd.gradient.norm()));
    }
  }
}

// Shape 2 moved by -distance * normal touches shape 1: the distance there is zero.
TEST(SignedDistance, MovingAlongTheNormalByTheDistanceMakesTheShapesTouch) {
  Rng rng(11);
  for (const Pair pair : kPairs) {
    for (int i = 0; i < 300; ++i) {
      const Case c = random_case(rng, pair, 1.0, 0.3);
      const SignedDistance sd = signed_distance(c.a.shape, c.pose_a, c.b.shape, c.pose_b);
      const Pose touching(c.pose_b.r() - sd.distance * sd.normal, c.pose_b.q());
      const SignedDistance after = signed_distance(c.a.shape, c.pose_a, c.b.shape, touching);
      ASSERT_NEAR(after.distance, 0.0, 1e-9) << name(pair) << " case " << i;
    }
  }
}

// Two squares [-1, 1]^2 crossing at right angles through their centres, one in the x-y plane and
// one in the x-z plane: B clears A by moving 1 along +-z or +-y (2 along x), so the depth is 1.
TEST(SignedDistance, CrossingSquares) {
  const PaddedPolygon a = square(1.0, 0.1), b = square(1.0, 0.2);
  const Pose pose_a(Eigen::Vector3d::Zero(), kIdentity);
  const Pose pose_b(Eigen::Vector3d(0, 0, 0.25), about(M_PI / 2, 1, 0, 0));  // B in x-z, raised
  const SignedDistanceJacobian sd = signed_distance_jacobian(a, pose_a, b, pose_b);
  // Raised by 0.25, B clears A upward after 0.75: B's lowest point z = -0.75 must reach 0.
  EXPECT_TRUE(sd.penetrating);
  EXPECT_NEAR(sd.distance, -0.75 - 0.3, 1e-14);
  EXPECT_NEAR(sd.normal.z(), 1.0, 1e-14);
  EXPECT_NEAR(sd.gradient(9), 1.0, 1e-14);   // d/dz of shape 2
  EXPECT_NEAR(sd.gradient(2), -1.0, 1e-14);  // d/dz of shape 1
}

// A capsule along z through the square's point (0.5, 0): it clears the face upward after 0.3 (its
// lower end is at z = -0.3), sideways after 0.5 along +x (the edge at x = 1): depth 0.3, normal
// +z, points above one another.
TEST(SignedDistance, CapsuleThroughASquare) {
  const PaddedPolygon plate = square(1.0, 0.05);
  const Capsule capsule(1.0, 0.1);
  const Pose pose_plate(Eigen::Vector3d::Zero(), kIdentity);
  const Pose pose_capsule(Eigen::Vector3d(0.5, 0, 0.2), about(-M_PI / 2, 0, 1, 0));  // x -> z
  const SignedDistance sd = signed_distance(plate, pose_plate, capsule, pose_capsule);
  EXPECT_NEAR(sd.distance, -0.3 - 0.15, 1e-14);
  EXPECT_NEAR((sd.normal - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-14);
  EXPECT_NEAR((sd.core_points[0] - Eigen::Vector3d(0.5, 0, 0)).norm(), 0.0, 1e-14);
  EXPECT_NEAR((sd.core_points[1] - Eigen::Vector3d(0.5, 0, -0.3)).norm(), 0.0, 1e-14);
  // Swapped: the same depth, the normal reversed.
  const SignedDistance ds = signed_distance(capsule, pose_capsule, plate, pose_plate);
  EXPECT_NEAR(ds.distance, sd.distance, 1e-14);
  EXPECT_NEAR((ds.normal + Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-14);
}

// An edge-edge facet: a capsule along y lying across a square's edge region, tilted so that the
// cheapest way out is over the edge x = 1 along the direction normal to both.
TEST(SignedDistance, EdgeEdgeFacetAgreesWithTheHull) {
  const PaddedPolygon plate = square(1.0, 0.0);
  const Capsule capsule(2.0, 0.0);
  const Pose pose_plate(Eigen::Vector3d::Zero(), kIdentity);
  // The capsule's axis along (1, 0, 1) / sqrt(2), crossing the plate at (0.9, 0, 0).
  const Pose pose_capsule(Eigen::Vector3d(0.9, 0, 0), about(-M_PI / 4, 0, 1, 0));
  const SignedDistance sd = signed_distance(plate, pose_plate, capsule, pose_capsule);
  const SignedCoreDistance hull = brute_force_signed_distance(
      {{Vec3L(1, 1, 0), Vec3L(-1, 1, 0), Vec3L(-1, -1, 0), Vec3L(1, -1, 0)}},
      {{Vec3L(0.9 - std::sqrt(0.5L), 0, -std::sqrt(0.5L)),
        Vec3L(0.9 + std::sqrt(0.5L), 0, std::sqrt(0.5L))}},
      1.0L);
  EXPECT_NEAR(sd.distance, static_cast<double>(hull.s), 1e-13);
  EXPECT_LE((sd.normal - hull.normal.cast<double>()).norm(), 1e-12);
}

// Two capsules crossing exactly: s = 0 (their D is flat), distance = -(R1 + R2), and the normal is
// the tie's documented choice: along +-(a x b), the sign toward shape 2's body origin.
TEST(SignedDistance, CrossingCapsulesTakeTheDocumentedNormal) {
  const Capsule a(2.0, 0.1), b(2.0, 0.2);
  const Pose pose_a(Eigen::Vector3d::Zero(), kIdentity);                    // along x
  const Pose pose_b(Eigen::Vector3d(0, 0.5, 0), about(M_PI / 2, 0, 0, 1));  // along y, through 0
  const SignedDistanceJacobian sd = signed_distance_jacobian(a, pose_a, b, pose_b);
  EXPECT_NEAR(sd.distance, -0.3, 1e-15);
  EXPECT_TRUE(sd.penetrating);
  EXPECT_NEAR(std::abs(sd.normal.z()), 1.0, 1e-15);  // normal to both axes
  EXPECT_TRUE(sd.gradient.allFinite() && sd.points_jacobian.allFinite());
  // Raised a little along +z, shape 2 is apart and the normal is +z; the gradient's z part is 1.
  const SignedDistance above =
      signed_distance(a, pose_a, b, Pose(Eigen::Vector3d(0, 0.5, 1e-3), pose_b.q()));
  EXPECT_NEAR(above.distance, 1e-3 - 0.3, 1e-15);
  EXPECT_NEAR(above.normal.z(), 1.0, 1e-15);
}

// Collinear overlapping capsules: D is a segment, s = 0, and the normal is normal to the axis
// (moving a capsule sideways by R1 + R2 separates them; along the axis it would take longer).
TEST(SignedDistance, CollinearCapsulesGetANormalAcrossTheAxis) {
  const Capsule a(2.0, 0.1), b(1.0, 0.1);
  const SignedDistance sd = signed_distance(a, Pose(Eigen::Vector3d::Zero(), kIdentity), b,
                                            Pose(Eigen::Vector3d(0.5, 0, 0), kIdentity));
  EXPECT_NEAR(sd.distance, -0.2, 1e-15);
  EXPECT_NEAR(sd.normal.x(), 0.0, 1e-15);
  EXPECT_NEAR(sd.normal.norm(), 1.0, 1e-15);
  // Two concentric spheres: the normal is shape 1's body z axis.
  const SignedDistance spheres = signed_distance(Capsule(0, 1), Pose(), Capsule(0, 2), Pose());
  EXPECT_NEAR(spheres.distance, -3.0, 1e-15);
  EXPECT_NEAR(spheres.normal.z(), 1.0, 1e-15);
}

// A capsule lying in a polygon's plane across it (flat D): s = 0, and the normal is the plane's,
// signed toward shape 2's body origin.
TEST(SignedDistance, CapsuleInThePlaneOfAPolygon) {
  const PaddedPolygon plate = square(1.0, 0.1);
  const Capsule capsule(3.0, 0.1);
  const SignedDistanceJacobian sd =
      signed_distance_jacobian(plate, Pose(Eigen::Vector3d(0, 0, -0.5), kIdentity), capsule,
                               Pose(Eigen::Vector3d(0, 0, -0.5), about(0.3, 0, 0, 1)));
  EXPECT_NEAR(sd.distance, -0.2, 1e-15);
  EXPECT_NEAR(std::abs(sd.normal.z()), 1.0, 1e-15);
  EXPECT_TRUE(sd.gradient.allFinite() && sd.points_jacobian.allFinite());
}

// Stacked, coplanar squares (flat D): s = 0, the witnesses in the middle of the overlap. The
// normal is +-z alike; both orders must pick the same one, reversed (a hostile review: the first
// argument's face normal in both orders, the padded points 2R apart and the gradients of opposite
// sign), for the same square twice and for a rectangle turned against it.
TEST(SignedDistance, CoplanarOverlappingSquares) {
  const PaddedPolygon a = square(1.0, 0.1), b = square(1.0, 0.1);
  const SignedDistance sd = signed_distance(a, Pose(Eigen::Vector3d::Zero(), kIdentity), b,
                                            Pose(Eigen::Vector3d(1.0, 0, 0), kIdentity));
  EXPECT_NEAR(sd.distance, -0.2, 1e-15);
  EXPECT_NEAR(std::abs(sd.normal.z()), 1.0, 1e-15);
  EXPECT_NEAR((sd.core_points[0] - Eigen::Vector3d(0.5, 0, 0)).norm(), 0.0, 1e-14);

  // The same square turned, a rectangle turned, and the same square moved by an offset t whose
  // weighted sum (1, 2^(1/2), 3^(1/2)) . t is exactly 0, the first key of the order of identical
  // polygons (pair_setup.hpp; a hostile review: both orders took the same normal there).
  const PaddedPolygon rectangle_b = rectangle(0.5, 0.8, 0.1);
  const Pose turned({0.3, 0.2, 0}, about(0.4, 0, 0, 1));
  const Pose level({0.7071067811865476, -0.5, 0}, kIdentity);
  for (const auto& [other, pose] :
       {std::pair{&b, turned}, std::pair{&rectangle_b, turned}, std::pair{&b, level}}) {
    const SignedDistanceJacobian ab = signed_distance_jacobian(a, Pose(), *other, pose);
    const SignedDistanceJacobian ba = signed_distance_jacobian(*other, pose, a, Pose());
    EXPECT_EQ(ab.distance, ba.distance);
    EXPECT_LE((ab.normal + ba.normal).norm(), 1e-15);
    EXPECT_LE((ab.points[0] - ba.points[1]).norm(), 1e-15);
    EXPECT_LE((ab.points[1] - ba.points[0]).norm(), 1e-15);
    EXPECT_LE((ab.gradient.head<7>() - ba.gradient.tail<7>()).norm(), 1e-14);
    EXPECT_LE((ab.gradient.tail<7>() - ba.gradient.head<7>()).norm(), 1e-14);
    // Rows [p1; p2] and columns [r1 q1 r2 q2], both swapped.
    const Eigen::Matrix<double, 3, 7> da_in_ab = ab.points_jacobian.block<3, 7>(0, 0);
    const Eigen::Matrix<double, 3, 7> da_in_ba = ba.points_jacobian.block<3, 7>(3, 7);
    EXPECT_LE((da_in_ab - da_in_ba).norm(), 1e-13);
  }
}

// Two equal hexagons crossing at 2e-11 rad about a line through their centres: D is a thin
// polytope, the depth ~2e-11 of their size. The edges are pairwise nearly parallel, and e x f must
// be formed stably (fuzz_proximity found a depth of the polygons' whole size here).
TEST(SignedDistance, NearlyCoplanarCrossingPolygons) {
  Eigen::MatrixX2d C(6, 2);
  for (int k = 0; k < 6; ++k) C.row(k) << std::cos(M_PI * k / 3), std::sin(M_PI * k / 3);
  const PaddedPolygon hexagon(C, Eigen::VectorXd::Constant(6, 1.0), 0.0);
  for (const double angle : {2e-11, 1e-9, 3e-7}) {
    const Pose flat(Eigen::Vector3d(0.1, 0.2, 0.3), about(0.4, 0, 0, 1));
    const Pose tilted(Eigen::Vector3d(0.1, 0.2, 0.3),
                      Eigen::Vector4d(std::cos(angle / 2), std::sin(angle / 2), 0, 0));
    const SignedDistance ab = signed_distance(hexagon, flat, hexagon, tilted);
    const SignedDistance ba = signed_distance(hexagon, tilted, hexagon, flat);
    std::vector<Eigen::Vector3d> body;
    for (const auto& v : hexagon.vertices().rowwise()) body.emplace_back(v.x(), v.y(), 0.0);
    const TestShape shape{hexagon, body, 1.2};
    const SignedCoreDistance hull =
        brute_force_signed_distance(to_world(shape, flat), to_world(shape, tilted), 1.0L);
    // Facets within the tie tolerance (1e-12 of the size) of each other count as equally deep.
    EXPECT_NEAR(ab.distance, static_cast<double>(hull.s), 2e-12) << angle;
    EXPECT_NEAR(ba.distance, ab.distance, 2e-12) << angle;
    EXPECT_LT(-ab.distance, 2.0 * angle);  // about the hexagon's reach (2 / sqrt(3)) times angle
  }
}

// Near touching the closest points are a few ulps of the scene apart from exact, so the direction
// of x2 - x1 is known only to ~1e-16 / |x2 - x1| (a hostile review: 7e-5 off for two capsules
// 1e-12 apart, 2e-7 for a capsule through a square's face tilted 1e-10). Where the features fix
// the normal (two edges crossing, a point over a face) it comes from them, exact to a few ulps:
// for proximity() and signed_distance(), apart and in penetration, and the signed distance's
// position gradient is that normal.
TEST(SignedDistance, NormalsNearTouchingComeFromTheFeatures) {
  Rng rng(77);
  std::normal_distribution<double> normal;
  const Capsule stick(1.0, 0.1);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Quaterniond turn =
        Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized();
    const Eigen::Vector3d e = turn * Eigen::Vector3d::UnitX();
    const Eigen::Vector3d f = turn * Eigen::Vector3d(0.6, 0.8, 0.0);  // in a's x-y plane
    const Eigen::Vector3d n = e.cross(f).normalized();
    // Crossing off the segments' middles (0.3 along a, -0.2 along b), s apart along n.
    const double s = std::pow(10.0, -8.0 - 3.0 * (i % 4) / 3.0);  // above the tolerance, 1e-12
    const Eigen::Vector3d at(0.1 * normal(rng), 0.1 * normal(rng), 0.1 * normal(rng));
    const Eigen::Quaterniond qb =
        Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitX(), turn.inverse() * f);
    const Pose pa(at - 0.3 * e, Eigen::Vector4d(turn.w(), turn.x(), turn.y(), turn.z()));
    const Eigen::Quaterniond q2 = turn * qb;
    const Pose pb(at + 0.2 * f + s * n, Eigen::Vector4d(q2.w(), q2.x(), q2.y(), q2.z()));
    const Proximity p = proximity(stick, pa, stick, pb);
    const SignedDistance sd = signed_distance(stick, pa, stick, pb);
    EXPECT_LE((p.normal - n).norm(), 1e-14) << "s = " << s;
    EXPECT_LE((sd.normal - n).norm(), 1e-14) << "s = " << s;
    EXPECT_LE((sd.gradient.segment<3>(7) - n).norm(), 1e-14) << "s = " << s;

    // A capsule through a unit square's face, tilted by t off the normal: the facet of the
    // capsule's axis and a square edge, or the face; its normal is exact.
    const double t = std::pow(10.0, -9.0 - (i % 3));
    const PaddedPolygon plate = square(1.0, 0.1);
    const Pose upright(Eigen::Vector3d(0.3, 0.2, 0.0),
                       about(-M_PI / 2 + t, 0, 1, 0));  // axis along z, tilted in x-z
    const SignedDistance through = signed_distance(plate, Pose(), stick, upright);
    const SignedDistance reference_face =
        signed_distance(plate, Pose(), stick, Pose(upright.r(), about(-M_PI / 2, 0, 1, 0)));
    EXPECT_TRUE(through.penetrating);
    EXPECT_LE(std::abs(through.normal.norm() - 1.0), 1e-15);
    // The nearest facet is the square's edge x = 1 against the axis (0.7 to go) or the face; either
    // way its normal lies in the x-z plane, with no y part beyond rounding.
    EXPECT_LE(std::abs(through.normal.y()), 1e-15) << "t = " << t;
    EXPECT_NEAR(through.distance, reference_face.distance, 1e-6);
  }
}

// A polygon 1e-300 wide against one 1e70 wide (found by fuzz_proximity): in the pair's frame the
// small one is a point whose edges have zero length, and its closest point, labelled inside a
// face or an edge, fixes no normal. The normal must still be the direction between the points.
TEST(SignedDistance, FeatureNormalsAgreeWithThePoints) {
  const auto regular = [](double offset, double radius) {
    Eigen::MatrixX2d C(51, 2);
    for (int k = 0; k < 51; ++k)
      C.row(k) << std::cos(2 * M_PI * k / 51), std::sin(2 * M_PI * k / 51);
    return PaddedPolygon(C, Eigen::VectorXd::Constant(51, offset), radius);
  };
  const double big = 1.0352619520185846e+70;
  const PaddedPolygon a = regular(big, 8.8162076311671563e-39);
  const PaddedPolygon b = regular(3.5093507569358994e-300, 9.1949732451953332e+54);
  const Pose pa(Eigen::Vector3d(2.875, big, big),
                Eigen::Vector4d(big, big, big, 4.043992000072596e+67));
  const Pose pb(Eigen::Vector3d(1.3980656882659035e-76, 1.3980432860952889e-76, 16.188235294117646),
                Eigen::Vector4d(big, 0, 0, 0));
  for (const bool swap : {false, true}) {
    const SignedDistance sd = swap ? signed_distance(b, pb, a, pa) : signed_distance(a, pa, b, pb);
    const Proximity p = swap ? proximity(b, pb, a, pa) : proximity(a, pa, b, pb);
    const Eigen::Vector3d along = (sd.core_points[1] - sd.core_points[0]).normalized();
    EXPECT_LE((sd.normal - along).norm(), 1e-12) << swap;
    EXPECT_LE((p.normal - along).norm(), 1e-12) << swap;
    EXPECT_LE((sd.points[1] - sd.points[0] - sd.distance * sd.normal).norm(), 1e-10 * big);
  }
}

// Continuity across touching: a capsule moved down through a plate, the signed distance falls
// linearly, with slope -1, before and after its end touches the face.
TEST(SignedDistance, ContinuousAcrossTouching) {
  const PaddedPolygon plate = square(1.0, 0.0);
  const Capsule capsule(1.0, 0.0);
  const Eigen::Vector4d upright = about(-M_PI / 2, 0, 1, 0);
  for (const double height : {0.6, 0.5 + 1e-9, 0.5, 0.5 - 1e-9, 0.45, 0.3}) {
    const SignedDistanceJacobian sd = signed_distance_jacobian(
        plate, Pose(), capsule, Pose(Eigen::Vector3d(0.2, 0.1, height), upright));
    EXPECT_NEAR(sd.distance, height - 0.5, 1e-15) << height;
    EXPECT_NEAR(sd.gradient(9), 1.0, 1e-15) << height;
  }
}

// Cores far smaller than the radii that make the scene (a hostile review): a capsule 4e-11 long
// lying 2e-12 .. 1e-14 above a needle 4e-11 by 4e-14, and above the same capsule, radii 1. At the
// scene's tolerance (1e-12) the penetration search's allowances exceeded the gap, and the signed
// gap came out -4.001e-13 in one order of the shapes and +3.999e-13 in the other; the cores are
// searched at their own tolerances, so the gap is the exact one to the rounding of the radii (the
// distance is gap - 2) in both orders, and the cores do not penetrate.
TEST(SignedDistance, CoresFarSmallerThanTheirRadiiKeepTheirGap) {
  const double length = 4e-11;
  Eigen::MatrixX2d C(4, 2);
  C << 1, 0, -1, 0, 0, 1, 0, -1;
  const PaddedPolygon needle(
      C, Eigen::Vector4d(length / 2, length / 2, length / 2000, length / 2000), 1.0);
  const Capsule capsule(length, 1.0);
  const double s2 = std::sqrt(0.5);
  for (const double gap : {2e-12, 9e-13, 4e-13, 1e-13, 1e-14}) {
    SCOPED_TRACE(::testing::Message() << "gap " << gap);
    const Pose above(Eigen::Vector3d(0, 0, gap), Eigen::Vector4d(s2, 0, 0, s2));
    const Pose below(Eigen::Vector3d::Zero(), kIdentity);
    const std::array<SignedDistance, 4> answers = {
        signed_distance(capsule, above, needle, below),
        signed_distance(needle, below, capsule, above),
        signed_distance(capsule, above, capsule, Pose(Eigen::Vector3d::Zero(), kIdentity)),
        signed_distance(capsule, Pose(Eigen::Vector3d::Zero(), kIdentity), capsule, above)};
    for (const SignedDistance& sd : answers) {
      EXPECT_NEAR(sd.distance + 2.0, gap, 4e-16);
      EXPECT_FALSE(sd.penetrating);
      EXPECT_NEAR(std::abs(sd.normal.z()), 1.0, 1e-12);
    }
  }
  // A capsule through the needle's middle, crossing it at 60 degrees, 1e-14 below its top: the
  // depth is the needle's half width less that (the way out along the needle's width, 1.9e-14),
  // found as for radius 0.
  const Pose crossing(Eigen::Vector3d(0, 0, 0), about(M_PI / 3, 1, 0, 0));
  const PaddedPolygon bare(C, Eigen::Vector4d(length / 2, length / 2, length / 2000, length / 2000),
                           0.0);
  const SignedDistance bare_answer = signed_distance(Capsule(length, 0.0), crossing, bare, Pose());
  for (const bool swapped : {false, true}) {
    const SignedDistance sd = swapped ? signed_distance(needle, Pose(), capsule, crossing)
                                      : signed_distance(capsule, crossing, needle, Pose());
    EXPECT_TRUE(sd.penetrating);
    EXPECT_NEAR(sd.distance + 2.0, bare_answer.distance, 4e-16) << swapped;
  }
}

// Cores 1e-105 to 1e-135 of their radii, apart (two capsules' segments 20 degrees apart in
// direction and 0.9 of their length apart, the closest points inside both): their signed distance
// is solved in the cores' own frame (signed_distance.cpp), where |sin| = 0.34 is below |d| over
// the frame's unit, and was returned with the normal's source chosen there, d / |d|, whose
// derivative in the radii's frame divides the points' rounding (ulps of the radii) by the gap: the
// normal's Jacobian came out 1e90 to 1e117 times too large (a hostile review). The same scene with
// the cores 2^m larger (~1e-60 of the radii, the radii kept) is the reference: the normal equal,
// its Jacobian's position columns scaled by 2^m, its rotation columns equal, and the Hessian's
// position block scaled by 2^m and its rotation block by 2^-m, to 1e-9 of their size.
TEST(SignedDistance, TinyCoresApartKeepTheirDerivatives) {
  const auto scene = [](double length) {
    return std::array<Pose, 2>{
        Pose(Eigen::Vector3d::Zero(), kIdentity),
        Pose(length * Eigen::Vector3d(0.3, 0.1, 0.9), about(M_PI / 9, 0, 0, 1))};
  };
  const std::array<int, 6> positions = {0, 1, 2, 7, 8, 9};
  const std::array<int, 8> rotations = {3, 4, 5, 6, 10, 11, 12, 13};
  for (const double length : {1e-105, 1e-120, 1e-135}) {
    SCOPED_TRACE(::testing::Message() << "length " << length);
    const double factor = std::exp2(std::round(std::log2(1e-60 / length)));
    const Capsule a(length, 1.0), b(length, 0.5);
    const Capsule a_ref(length * factor, 1.0), b_ref(length * factor, 0.5);
    const std::array<Pose, 2> poses = scene(length), poses_ref = scene(length * factor);
    const SignedDistanceHessian h = signed_distance_hessian(a, poses[0], b, poses[1]);
    const SignedDistanceHessian ref =
        signed_distance_hessian(a_ref, poses_ref[0], b_ref, poses_ref[1]);
    ASSERT_FALSE(h.penetrating);
    EXPECT_LE((h.normal - ref.normal).norm(), 1e-12);
    Eigen::Matrix<double, 3, 14> expected = ref.normal_jacobian;
    Eigen::Matrix<double, 14, 14> expected_hessian = ref.hessian;
    for (const int i : positions) {
      expected.col(i) *= factor;
      for (const int j : positions) expected_hessian(i, j) *= factor;
    }
    for (const int i : rotations) {
      for (const int j : rotations) expected_hessian(i, j) /= factor;
    }
    EXPECT_LE((h.normal_jacobian - expected).norm(), 1e-9 * expected.norm());
    EXPECT_LE((h.hessian - expected_hessian).norm(), 1e-9 * expected_hessian.norm());
  }
}

}  // namespace
}  // namespace diffpills::testing
