// proximity(), proximity_jacobian() and proximity_hessian() of two capsules in the generic case
// take a fused pass (src/proximity/capsule_proximity.hpp) instead of the general pipeline. Checked
// here against references that share none of its code: a long-double brute force (phi, the
// closest points, the normal), the general pipeline (every field, the Jacobians and the Hessian
// too), central differences (the gradient, the points' Jacobians, the Hessian); and by
// properties: a scene scaled by 2^k scales every result exactly, swapping the capsules swaps the
// results, a rigid motion leaves phi. Rows on both sides of each boundary of the generic case
// (nearly parallel axes, close cores, short capsules, tiny scenes) agree with the brute force too,
// so nothing jumps where the path changes.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "diffpills/diffpills.hpp"
#include "proximity/capsule_proximity.hpp"
#include "proximity/symmetric_gram.hpp"
#include "support/random_shapes.hpp"
#include "support/reference.hpp"

namespace diffpills::testing {
namespace {

struct Pair {
  Capsule a, b;
  Pose pose_a, pose_b;
};

TestShape as_test_shape(const Capsule& capsule) {
  const double h = 0.5 * capsule.length();
  return {capsule, {{-h, 0, 0}, {h, 0, 0}}, capsule.length()};
}

// The scene's size: the largest of the lengths, the radii's sum and the middles' distance.
double scene_size(const Pair& p) {
  return std::max({p.a.length(), p.b.length(), p.a.radius() + p.b.radius(),
                   (p.pose_a.r() - p.pose_b.r()).norm()});
}

bool generic(const Pair& p) {
  detail::GenericCapsuleSolution unused;
  return detail::solve_generic_capsules(p.a, p.pose_a, p.b, p.pose_b, unused);
}

Proximity fused(const Pair& p) { return proximity(p.a, p.pose_a, p.b, p.pose_b); }

// The pair with coordinate j of x = [r_a q_a r_b q_b] (q as given) moved by delta.
Pair nudged(const Pair& p, int j, double delta) {
  Eigen::Matrix<double, 14, 1> x;
  x << p.pose_a.r(), p.pose_a.q(), p.pose_b.r(), p.pose_b.q();
  x(j) += delta;
  return {p.a, p.b, Pose(x.segment<3>(0), x.segment<4>(3)),
          Pose(x.segment<3>(7), x.segment<4>(10))};
}

// phi, the closest points and the normal of the fused answer against the long-double brute force,
// relative to the scene's size S. (Along a core much shorter than S the distance changes by less
// than a long double resolves, and the brute force's point may sit anywhere on it.)
void expect_matches_brute_force(const Pair& p, double tolerance) {
  const Proximity fast = fused(p);
  const ClosestPair brute = brute_force_closest(to_world(as_test_shape(p.a), p.pose_a),
                                                to_world(as_test_shape(p.b), p.pose_b));
  const double S = scene_size(p);
  const long double radii = static_cast<long double>(p.a.radius()) + p.b.radius();
  const double phi = static_cast<double>(brute.distance * brute.distance - radii * radii);
  ASSERT_NEAR(fast.phi, phi, tolerance * S * S);
  const Vec3L direction = (brute.p2 - brute.p1) / brute.distance;
  for (int k = 0; k < 3; ++k) {
    ASSERT_NEAR(fast.core_points[0](k), static_cast<double>(brute.p1(k)), tolerance * S);
    ASSERT_NEAR(fast.core_points[1](k), static_cast<double>(brute.p2(k)), tolerance * S);
    ASSERT_NEAR(fast.normal(k), static_cast<double>(direction(k)), tolerance);
  }
}

// Every field of the fused answer against the general pipeline, relative to the scene's size S.
void expect_matches_general(const Pair& p, double tolerance) {
  const Proximity fast = fused(p);
  const ProximityHessian general =
      detail::general_capsule_proximity_hessian(p.a, p.pose_a, p.b, p.pose_b);
  const double S = scene_size(p);
  ASSERT_NEAR(fast.phi, general.phi, tolerance * S * S);
  ASSERT_FALSE(fast.cores_intersect);
  for (int k = 0; k < 3; ++k) {
    for (int i = 0; i < 2; ++i) {
      ASSERT_NEAR(fast.core_points[i](k), general.core_points[i](k), tolerance * S);
      ASSERT_NEAR(fast.points[i](k), general.points[i](k), tolerance * S);
    }
    ASSERT_NEAR(fast.normal(k), general.normal(k), tolerance);
  }
  for (int block : {0, 7}) {
    const double q_norm = (block == 0 ? p.pose_a : p.pose_b).q().norm();
    for (int j = 0; j < 3; ++j) {
      ASSERT_NEAR(fast.gradient(block + j), general.gradient(block + j), tolerance * S);
    }
    for (int j = 3; j < 7; ++j) {
      ASSERT_NEAR(fast.gradient(block + j), general.gradient(block + j),
                  tolerance * S * S / q_norm);
    }
  }
  // The Jacobians: the Proximity part is the same pass's, bit for bit; the points' Jacobians
  // against the general pipeline's, position columns unitless, quaternion columns in length per
  // unit of q; the surface points' carry the normal's motion, 1 / |p1 - p2| (>= 1e-2 S / 2 here).
  // Ten times the tolerance: with 1 / sin^2 <= 100 in the free coordinates' motion, hostile
  // reviews found the general pipeline up to 7.2e-13 units from 60 digits (13 random pairs in
  // 198,858 beyond 1e-13 apart, the worst 7.8e-13), where the fused pass was within 1.6e-13.
  const double jacobian_tolerance = 10 * tolerance;
  const ProximityJacobian jacobian = proximity_jacobian(p.a, p.pose_a, p.b, p.pose_b);
  ASSERT_EQ(jacobian.phi, fast.phi);
  ASSERT_EQ(jacobian.gradient, fast.gradient);
  ASSERT_EQ(jacobian.normal, fast.normal);
  ASSERT_EQ(jacobian.points[0], fast.points[0]);
  ASSERT_EQ(jacobian.core_points[1], fast.core_points[1]);
  const double gap = (fast.core_points[1] - fast.core_points[0]).norm();
  const double radius = std::max(p.a.radius(), p.b.radius());
  for (int row = 0; row < 6; ++row) {
    for (int column = 0; column < 14; ++column) {
      const bool rotation = (column >= 3 && column < 7) || column >= 10;
      const double q_norm = (column < 7 ? p.pose_a : p.pose_b).q().norm();
      const double unit = rotation ? S / q_norm : 1.0;
      ASSERT_NEAR(jacobian.core_points_jacobian(row, column),
                  general.core_points_jacobian(row, column), jacobian_tolerance * unit)
          << row << ", " << column;
      ASSERT_NEAR(jacobian.points_jacobian(row, column), general.points_jacobian(row, column),
                  jacobian_tolerance * unit * (1 + radius / gap))
          << row << ", " << column;
    }
  }
  // The Hessian (through the Shape overload, as every caller reaches it): its Jacobian part is
  // the same pass's, bit for bit; phi's Hessian against the general pipeline's, each index in
  // its unit (1 for a position, S / |q| for a quaternion component), relative to the entry's size
  // in those units: entries reach ~300 units (1 / sin^2 <= 100 in the free coordinates' motion),
  // and a hostile review found both paths ~1e-12 units from 50 digits on such an entry (6 pairs
  // in 100,000 apart by 1.5e-13 units, 4e-15 of the entry).
  const ProximityHessian second = proximity_hessian(Shape(p.a), p.pose_a, Shape(p.b), p.pose_b);
  ASSERT_EQ(second.phi, fast.phi);
  ASSERT_EQ(second.gradient, fast.gradient);
  ASSERT_EQ(second.core_points_jacobian, jacobian.core_points_jacobian);
  ASSERT_EQ(second.points_jacobian, jacobian.points_jacobian);
  const auto index_unit = [&](int index) {
    return index % 7 < 3 ? 1.0 : S / (index < 7 ? p.pose_a : p.pose_b).q().norm();
  };
  for (int row = 0; row < 14; ++row) {
    for (int column = 0; column < 14; ++column) {
      const double unit = index_unit(row) * index_unit(column);
      ASSERT_NEAR(second.hessian(row, column), general.hessian(row, column),
                  tolerance * (unit + std::abs(general.hessian(row, column))))
          << row << ", " << column;
      ASSERT_EQ(second.hessian(row, column), second.hessian(column, row)) << row << ", " << column;
    }
  }
  // proximity_with_hessian: the same pass without the Jacobians, every field bit for bit.
  const ProximityWithHessian lean =
      proximity_with_hessian(Shape(p.a), p.pose_a, Shape(p.b), p.pose_b);
  ASSERT_EQ(lean.phi, fast.phi);
  ASSERT_EQ(lean.gradient, fast.gradient);
  ASSERT_EQ(lean.normal, fast.normal);
  ASSERT_EQ(lean.points[1], fast.points[1]);
  ASSERT_EQ(lean.core_points[0], fast.core_points[0]);
  ASSERT_EQ(lean.hessian, second.hessian);
}

void expect_matches_references(const Pair& p, double tolerance) {
  expect_matches_brute_force(p, tolerance);
  expect_matches_general(p, tolerance);
}

Pair random_pair(Rng& rng, double scale) {
  const TestShape a = random_capsule(rng, scale), b = random_capsule(rng, scale);
  return {std::get<Capsule>(a.shape), std::get<Capsule>(b.shape), random_pose(rng, 1.5 * scale),
          random_pose(rng, 1.5 * scale)};
}

TEST(CapsuleProximity, RandomPairsMatchBruteForceAndTheGeneralPipeline) {
  Rng rng(1301);
  for (const double scale : {0x1p-30, 1.0, 0x1p30}) {
    int answered = 0;
    const int n = 3'000;
    for (int i = 0; i < n; ++i) {
      const Pair p = random_pair(rng, scale);
      if (!generic(p)) continue;
      ++answered;
      SCOPED_TRACE(i);
      expect_matches_references(p, 1e-13);
    }
    // The path is what random poses take: the test exercises it, not the fallback.
    EXPECT_GT(answered, 0.85 * n) << "scale " << scale;
  }
}

// The Hessian's dense part runs in the widest vectors the CPU has (symmetric_gram.hpp): the same
// checks on every instruction set it was compiled for, each near the general pipeline and exactly
// symmetric (test_symmetric_gram.cpp checks the kernel alone).
TEST(CapsuleProximity, HessianOnEveryInstructionSet) {
  for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    SCOPED_TRACE(std::string("target ") + hwy::TargetName(target));
    ASSERT_STREQ(detail::symmetric_gram_target(), hwy::TargetName(target));
    Rng rng(1309);
    for (int i = 0; i < 300; ++i) {
      const Pair p = random_pair(rng, 1.0);
      if (!generic(p)) continue;
      SCOPED_TRACE(i);
      expect_matches_references(p, 1e-13);
    }
  }
  hwy::SetSupportedTargetsForTest(0);
}

// The axis Hessian's factor, 1 / |q|^2 times a short capsule's s times scale^2, leaves the
// normal range in its parts where the entry does not (a hostile review: |q| = 1e100 and a capsule
// 1e-25 long in a 1e99 scene lost its q-q block). Scaling q by 1e100 scales that block by
// 1e-200 exactly in real numbers; the fused pass must keep it to rounding.
TEST(CapsuleProximity, AxisHessianOfAHugeQuaternionKeepsItsDigits) {
  const double c = std::sqrt(0.5);
  for (const double length : {1e-15, 1e-25, 1e-40}) {
    const Capsule a(length, 0.0), b(1e99, 0.0);
    const Pose pose_b(Eigen::Vector3d(1e98, 0, 5e98), Eigen::Vector4d(c, 0, 0, c));
    const Pose unit(Eigen::Vector3d::Zero(), Eigen::Vector4d(1, 0, 0, 0));
    const Pose huge(Eigen::Vector3d::Zero(), Eigen::Vector4d(1e100, 0, 0, 0));
    ASSERT_TRUE(generic({a, b, unit, pose_b}));
    ASSERT_TRUE(generic({a, b, huge, pose_b}));
    const Eigen::Matrix<double, 14, 14> H1 =
        proximity_with_hessian(Shape(a), unit, Shape(b), pose_b).hessian;
    const Eigen::Matrix<double, 14, 14> H2 =
        proximity_with_hessian(Shape(a), huge, Shape(b), pose_b).hessian;
    ASSERT_NE(H1(5, 5), 0.0);
    for (int i = 3; i < 7; ++i) {
      for (int j = 3; j < 7; ++j) {
        EXPECT_NEAR(H2(i, j), H1(i, j) * 1e-200, 1e-12 * std::abs(H1(5, 5)) * 1e-200)
            << "length " << length << ", entry " << i << ", " << j;
      }
    }
  }
}

// Central differences of phi in every position coordinate and every raw quaternion component
// (the gradient refers to q as given, normalization included).
TEST(CapsuleProximity, GradientMatchesCentralDifferences) {
  Rng rng(1302);
  int checked = 0;
  for (int i = 0; i < 300; ++i) {
    const Pair p = random_pair(rng, 1.0);
    if (!generic(p)) continue;
    ++checked;
    const Eigen::Matrix<double, 14, 1> gradient = fused(p).gradient;
    for (int j = 0; j < 14; ++j) {
      const double step = 1e-6;
      const double difference =
          (fused(nudged(p, j, step)).phi - fused(nudged(p, j, -step)).phi) / (2 * step);
      ASSERT_NEAR(gradient(j), difference, 1e-6 * (1 + std::abs(difference)))
          << "pair " << i << ", entry " << j;
    }
  }
  EXPECT_GT(checked, 250);
}

// How many of the two closest points lie at an end of their segment (0, 1 or 2), from the
// brute force's points.
int ends_held(const Pair& p) {
  const WorldCore ends_a = to_world(as_test_shape(p.a), p.pose_a);
  const WorldCore ends_b = to_world(as_test_shape(p.b), p.pose_b);
  const ClosestPair brute = brute_force_closest(ends_a, ends_b);
  const auto at_an_end = [](const Vec3L& point, const WorldCore& core) {
    return (point - core.vertices[0]).norm() < 1e-9 || (point - core.vertices[1]).norm() < 1e-9;
  };
  return static_cast<int>(at_an_end(brute.p1, ends_a)) +
         static_cast<int>(at_an_end(brute.p2, ends_b));
}

// Central differences of the surface and core points (proximity(), the fused pass's own points)
// against proximity_jacobian's Jacobians, on pairs of each kind of closest points: both inside
// their segments, one at an end, both at ends.
TEST(CapsuleProximity, JacobiansMatchCentralDifferences) {
  Rng rng(1306);
  int kinds[3] = {0, 0, 0};  // closest points at 0, 1 or 2 segment ends
  for (int i = 0; i < 400; ++i) {
    const Pair p = random_pair(rng, 1.0);
    if (!generic(p)) continue;
    const ProximityJacobian jacobian = proximity_jacobian(p.a, p.pose_a, p.b, p.pose_b);
    ++kinds[ends_held(p)];
    for (int j = 0; j < 14; ++j) {
      const double step = 1e-6;
      const Proximity plus = fused(nudged(p, j, step)), minus = fused(nudged(p, j, -step));
      for (const Eigen::Index c : {0, 1}) {
        const Eigen::Vector3d core = (plus.core_points[c] - minus.core_points[c]) / (2 * step);
        const Eigen::Vector3d surface = (plus.points[c] - minus.points[c]) / (2 * step);
        const Eigen::Index row = 3 * c;
        ASSERT_LT((jacobian.core_points_jacobian.block<3, 1>(row, j) - core).norm(),
                  1e-6 * (1 + core.norm()))
            << "pair " << i << ", point " << c << ", entry " << j;
        ASSERT_LT((jacobian.points_jacobian.block<3, 1>(row, j) - surface).norm(),
                  1e-6 * (1 + surface.norm()))
            << "pair " << i << ", point " << c << ", entry " << j;
      }
    }
  }
  for (const int count : kinds) EXPECT_GT(count, 20);
}

// Central differences of the fused gradient against the fused Hessian, on each kind of closest
// points. Where the differences at two steps disagree, the clamping changes within the step (a
// kink, where phi is not twice differentiable): skipped and counted.
TEST(CapsuleProximity, HessianMatchesCentralDifferencesOfTheGradient) {
  using Vector14 = Eigen::Matrix<double, 14, 1>;
  Rng rng(1307);
  int kinds[3] = {0, 0, 0}, kinks = 0;
  for (int i = 0; i < 400; ++i) {
    const Pair p = random_pair(rng, 1.0);
    if (!generic(p)) continue;
    const ProximityHessian exact = proximity_hessian(Shape(p.a), p.pose_a, Shape(p.b), p.pose_b);
    Eigen::Matrix<double, 14, 14> numeric;
    bool smooth = true;
    for (int j = 0; j < 14 && smooth; ++j) {
      const auto column = [&](double step) {
        return Vector14((fused(nudged(p, j, step)).gradient - fused(nudged(p, j, -step)).gradient) /
                        (2 * step));
      };
      const Vector14 coarse = column(1e-5), fine = column(2.5e-6);
      smooth = (coarse - fine).cwiseAbs().maxCoeff() <= 1e-5 * (1 + fine.cwiseAbs().maxCoeff());
      numeric.col(j) = fine;
    }
    if (!smooth) {
      ++kinks;
      continue;
    }
    ++kinds[ends_held(p)];
    ASSERT_LE((exact.hessian - numeric).cwiseAbs().maxCoeff(),
              1e-6 * (1 + numeric.cwiseAbs().maxCoeff()))
        << "pair " << i << "\nexact\n"
        << exact.hessian << "\nnumeric\n"
        << numeric;
  }
  for (const int count : kinds) EXPECT_GT(count, 20);
  EXPECT_LT(kinks, 20);
}

Pose scaled(const Pose& pose, int k) { return Pose(std::ldexp(1.0, k) * pose.r(), pose.q()); }

// Lengths divided by a power of two of the scene (capsule_proximity.hpp): a scene scaled by 2^k
// gives the same bits scaled, phi by 2^2k, points and the position gradient by 2^k, the
// quaternion gradient by 2^2k, the normal not at all; and the same rows take the path.
TEST(CapsuleProximity, ScalingByAPowerOfTwoIsExact) {
  Rng rng(1303);
  for (int i = 0; i < 200; ++i) {
    const Pair p = random_pair(rng, 1.0);
    const Proximity base = fused(p);
    for (const int k : {-960, -300, -13, 13, 300, 325}) {
      const double f = std::ldexp(1.0, k);
      const Pair big{Capsule(f * p.a.length(), f * p.a.radius()),
                     Capsule(f * p.b.length(), f * p.b.radius()), scaled(p.pose_a, k),
                     scaled(p.pose_b, k)};
      ASSERT_EQ(generic(big), generic(p)) << "pair " << i << ", k = " << k;
      const Proximity result = fused(big);
      ASSERT_EQ(result.phi, std::ldexp(base.phi, 2 * k)) << "pair " << i << ", k = " << k;
      ASSERT_EQ(result.normal, base.normal);
      for (int c = 0; c < 2; ++c) {
        ASSERT_EQ(result.core_points[c], f * base.core_points[c]);
        ASSERT_EQ(result.points[c], f * base.points[c]);
      }
      for (const int block : {0, 7}) {
        ASSERT_EQ(result.gradient.segment<3>(block), f * base.gradient.segment<3>(block));
        ASSERT_EQ(result.gradient.segment<4>(block + 3),
                  std::ldexp(1.0, 2 * k) * base.gradient.segment<4>(block + 3));
      }
    }
  }
}

// The same for the Jacobians (position columns unitless, quaternion columns a length) and phi's
// Hessian (one length per quaternion index), for every k that keeps the Hessian's quaternion
// block, of order 2^2k, a normal number.
TEST(CapsuleProximity, SecondOrderScalingByAPowerOfTwoIsExact) {
  Rng rng(1308);
  for (int i = 0; i < 200; ++i) {
    const Pair p = random_pair(rng, 1.0);
    const ProximityHessian base = proximity_hessian(Shape(p.a), p.pose_a, Shape(p.b), p.pose_b);
    for (const int k : {-300, -13, 13, 300, 325}) {
      const double f = std::ldexp(1.0, k);
      const ProximityHessian result =
          proximity_hessian(Capsule(f * p.a.length(), f * p.a.radius()), scaled(p.pose_a, k),
                            Capsule(f * p.b.length(), f * p.b.radius()), scaled(p.pose_b, k));
      for (int column = 0; column < 14; ++column) {
        const bool rotation_column = column % 7 >= 3;
        for (int row = 0; row < 6; ++row) {
          ASSERT_EQ(result.points_jacobian(row, column),
                    std::ldexp(base.points_jacobian(row, column), rotation_column ? k : 0))
              << "pair " << i << ", k = " << k << " (" << row << ", " << column << ")";
          ASSERT_EQ(result.core_points_jacobian(row, column),
                    std::ldexp(base.core_points_jacobian(row, column), rotation_column ? k : 0));
        }
        for (int row = 0; row < 14; ++row) {
          const int power = static_cast<int>(rotation_column) + static_cast<int>(row % 7 >= 3);
          ASSERT_EQ(result.hessian(row, column), std::ldexp(base.hessian(row, column), power * k))
              << "pair " << i << ", k = " << k << " (" << row << ", " << column << ")";
        }
      }
    }
  }
}

// Q(2^m q) = Q(q): a quaternion scaled by a power of two, from near the smallest norm a Pose takes
// (1e-40) to near the largest components (1e100), leaves phi, the points and the normal bit for
// bit and divides that quaternion's gradient by 2^m exactly (the fused pass forms each axis from
// the raw quaternion and 1 / |q|^2, and the gradient from q / |q|, capsule_proximity.cpp), so
// long as every product of two components inside A(q) stays a normal number (a component of
// 1.23e-241 scaled by 2^-128 squares below it, and the axis then rounds differently); and the
// answer still matches the brute force and the general pipeline, which normalizes q first.
// random_pose keeps |q| in [0.5, 2] with normally distributed components, so 2^-128 |q| >= 1.4e-39,
// each component of 2^330 q is at most 4.4e99, and no product comes near 2^-1022.
TEST(CapsuleProximity, QuaternionScaledByAPowerOfTwo) {
  Rng rng(1310);
  const std::pair<int, int> exponents[] = {{-128, 330}, {330, -128}, {-60, -60}, {60, 60}};
  int checked = 0;
  for (int i = 0; i < 300; ++i) {
    const Pair p = random_pair(rng, 1.0);
    if (!generic(p)) continue;
    ++checked;
    const Proximity base = fused(p);
    for (const auto& [m_a, m_b] : exponents) {
      SCOPED_TRACE(::testing::Message() << "pair " << i << ", m = " << m_a << ", " << m_b);
      const Pair turned{p.a, p.b, Pose(p.pose_a.r(), std::ldexp(1.0, m_a) * p.pose_a.q()),
                        Pose(p.pose_b.r(), std::ldexp(1.0, m_b) * p.pose_b.q())};
      ASSERT_TRUE(generic(turned));
      const Proximity result = fused(turned);
      ASSERT_EQ(result.phi, base.phi);
      ASSERT_EQ(result.normal, base.normal);
      for (int c = 0; c < 2; ++c) {
        ASSERT_EQ(result.core_points[c], base.core_points[c]);
        ASSERT_EQ(result.points[c], base.points[c]);
      }
      ASSERT_EQ(result.gradient.segment<3>(0), base.gradient.segment<3>(0));
      ASSERT_EQ(result.gradient.segment<3>(7), base.gradient.segment<3>(7));
      ASSERT_EQ(result.gradient.segment<4>(3), std::ldexp(1.0, -m_a) * base.gradient.segment<4>(3));
      ASSERT_EQ(result.gradient.segment<4>(10),
                std::ldexp(1.0, -m_b) * base.gradient.segment<4>(10));
      expect_matches_references(turned, 1e-13);
    }
  }
  EXPECT_GT(checked, 250);
}

// A closest point near a capsule's middle (s from 1e-80 to 1e-300 of a unit scene) with |q| up
// to 1e100: dphi/dq = (4 s / |q|) T scale^2 with T of the size of D (capsule_proximity.cpp). A
// factor formed as 4 s / |q|^2, for |q| T, underflowed at |q| = 1e100 and s = 1e-150 where the
// entry is 2e-250 (a hostile review), and the 2^k scaling promise failed at k = -150 with
// s = 1e-80. Against the general pipeline, which normalizes q first, and against the same scene
// scaled by 2^-150 and 2^150 where the scaled entry is a normal number.
TEST(CapsuleProximity, QuaternionGradientNearTheMiddleOfAHugeQuaternion) {
  const Capsule a(2.0, 0.0), b(2.0, 0.0);
  const Pose pose_b(Eigen::Vector3d(0, 0, 3),
                    Eigen::Vector4d(std::sqrt(0.5), 0, 0, std::sqrt(0.5)));
  const std::pair<double, double> cases[] = {
      {1e-80, 1e100}, {1e-150, 1e100}, {1e-190, 1e100}, {1e-250, 1e50}, {1e-300, 1.0}};
  for (const auto& [s, norm] : cases) {
    SCOPED_TRACE(::testing::Message() << "s = " << s << ", |q| = " << norm);
    // a along x with its middle at x = -s: its closest point to b's axis (the line z = 3 along
    // y) is at x = 0, s from a's middle.
    const Pair p{a, b, Pose(Eigen::Vector3d(-s, 0, 0), Eigen::Vector4d(norm, 0, 0, 0)), pose_b};
    ASSERT_TRUE(generic(p));
    const Proximity fast = fused(p);
    const ProximityHessian general =
        detail::general_capsule_proximity_hessian(p.a, p.pose_a, p.b, p.pose_b);
    ASSERT_GT(std::abs(general.gradient(5)), 1e-300);  // 12 s / |q| >= 1.2e-299
    for (int j = 3; j < 7; ++j) {
      EXPECT_NEAR(fast.gradient(j), general.gradient(j), 1e-14 * std::abs(general.gradient(5)))
          << "entry " << j;
    }
    for (const int k : {-150, 150}) {
      const double f = std::ldexp(1.0, k);
      const Proximity scaled_scene =
          fused({Capsule(f * a.length(), 0.0), Capsule(f * b.length(), 0.0), scaled(p.pose_a, k),
                 scaled(p.pose_b, k)});
      if (std::abs(std::ldexp(fast.gradient(5), 2 * k)) < 1e-300) continue;
      EXPECT_EQ(scaled_scene.gradient.segment<4>(3),
                std::ldexp(1.0, 2 * k) * fast.gradient.segment<4>(3))
          << "k = " << k;
    }
  }
  // The same in a scene of 2^330 with the point 2.2e-151 from a's middle (s = 1e-250 of the
  // frame's unit) and |q_a| = 1e100: 12 x0 2^329 / |q| = 2.9e-151, where 4 s / |q| formed in the
  // frame underflowed (a second review; the general pipeline's own order still gives 0 there).
  const double huge = std::ldexp(1.0, 330), x0 = 2.2e-151;
  const Pair far{Capsule(huge, 0), Capsule(huge, 0),
                 Pose(Eigen::Vector3d(-x0, 0, 0), Eigen::Vector4d(1e100, 0, 0, 0)),
                 Pose(Eigen::Vector3d(0, 0, 1.5 * huge),
                      Eigen::Vector4d(std::sqrt(0.5), 0, 0, std::sqrt(0.5)))};
  ASSERT_TRUE(generic(far));
  const double expected = 12 * x0 * (0.5 * huge) / 1e100;
  EXPECT_NEAR(fused(far).gradient(5), expected, 1e-14 * expected);
}

TEST(CapsuleProximity, SwappingTheCapsulesSwapsTheResults) {
  Rng rng(1304);
  for (int i = 0; i < 1'000; ++i) {
    const Pair p = random_pair(rng, 1.0);
    const Proximity ab = fused(p);
    const Proximity ba = proximity(p.b, p.pose_b, p.a, p.pose_a);
    const double S = scene_size(p);
    ASSERT_NEAR(ab.phi, ba.phi, 1e-14 * S * S) << "pair " << i;
    for (int k = 0; k < 3; ++k) {
      ASSERT_NEAR(ab.normal(k), -ba.normal(k), 1e-13);
      ASSERT_NEAR(ab.core_points[0](k), ba.core_points[1](k), 1e-13 * S);
      ASSERT_NEAR(ab.points[1](k), ba.points[0](k), 1e-13 * S);
    }
    for (int j = 0; j < 7; ++j) {
      ASSERT_NEAR(ab.gradient(j), ba.gradient(7 + j), 1e-13 * S * S * (1 + S));
      ASSERT_NEAR(ab.gradient(7 + j), ba.gradient(j), 1e-13 * S * S * (1 + S));
    }
    // phi's Hessian: the blocks of [r1 q1] and [r2 q2] trade places.
    const ProximityHessian second_ab =
        proximity_hessian(Shape(p.a), p.pose_a, Shape(p.b), p.pose_b);
    const ProximityHessian second_ba =
        proximity_hessian(Shape(p.b), p.pose_b, Shape(p.a), p.pose_a);
    const double size = second_ab.hessian.cwiseAbs().maxCoeff();
    for (int row = 0; row < 14; ++row) {
      for (int column = 0; column < 14; ++column) {
        ASSERT_NEAR(second_ab.hessian(row, column),
                    second_ba.hessian((row + 7) % 14, (column + 7) % 14), 1e-12 * size)
            << "pair " << i << " (" << row << ", " << column << ")";
      }
    }
  }
}

TEST(CapsuleProximity, RigidMotionLeavesPhi) {
  Rng rng(1305);
  for (int i = 0; i < 500; ++i) {
    const Pair p = random_pair(rng, 1.0);
    const Eigen::Quaterniond turn = Eigen::Quaterniond::UnitRandom();
    const Eigen::Vector3d shift = Eigen::Vector3d::Random() * 4.0;
    const Proximity before = fused(p);
    const Proximity after = proximity(p.a, rigidly_moved(p.pose_a, turn, shift), p.b,
                                      rigidly_moved(p.pose_b, turn, shift));
    const double S = scene_size(p) + shift.norm();
    ASSERT_NEAR(after.phi, before.phi, 1e-13 * S * S) << "pair " << i;
    ASSERT_LT((after.normal - turn * before.normal).norm(), 1e-12) << "pair " << i;
  }
}

// Both sides of each boundary of the generic case: the fused path on one side, the general
// pipeline on the other, both against the brute force.
TEST(CapsuleProximity, BoundariesOfTheGenericCase) {
  const Capsule a(1.0, 0.1), b(0.8, 0.2);
  const Eigen::Vector4d identity(1, 0, 0, 0);
  const auto about_z = [](double angle) {
    return Eigen::Vector4d(std::cos(angle / 2), 0, 0, std::sin(angle / 2));
  };
  // Axes apart by an angle whose sine squared is 1e-2 (the threshold), times 1 -+ 1e-6 and
  // further each way; the cores 0.3 apart across z.
  const double threshold = std::asin(0.1);
  for (const double factor : {0.5, 0.99, 1 - 1e-6, 1 + 1e-6, 1.01, 2.0}) {
    const Pair p{a, b, Pose({0.1, 0.05, 0}, identity),
                 Pose({-0.05, 0.02, 0.3}, about_z(threshold * factor))};
    EXPECT_EQ(generic(p), factor > 1) << factor;
    SCOPED_TRACE(factor);
    expect_matches_references(p, 1e-13);
  }
  // Crossing cores a gap g apart: the path needs g > 1e-2 of the frame's power of two (1 here:
  // the scene's size is 1).
  for (const double gap : {0.5e-2, 0.999e-2, 1.001e-2, 2e-2, 0.3}) {
    const Pair p{a, b, Pose({0, 0, 0}, identity), Pose({0, 0, gap}, about_z(M_PI / 2))};
    EXPECT_EQ(generic(p), gap > 1e-2) << gap;
    SCOPED_TRACE(gap);
    expect_matches_references(p, 1e-13);
  }
  // A zero-length capsule (a sphere) is the general pipeline's; so is a core whose closest point
  // is inside it and whose half length is below 2^-36 of the frame's power of two (2^-1 here: b
  // is the longest, 0.8), a length below 2^-36 here: its whole length is a tie of s's clamp. One
  // of 2^-36 or longer takes the path, and so does a shorter one whose closest point is an end
  // decided by far (moved 0.1 along x).
  const Pose crossed({0, 0, 0.4}, about_z(M_PI / 3));
  EXPECT_FALSE(generic({Capsule(0.0, 0.1), b, Pose(), crossed}));
  // The lines cross above the origin, 0.4 apart: phi = 0.4^2 - 0.3^2 wherever a's core holds
  // x = 0, its closest point. (The brute force cannot place a point on cores this short: it
  // picks either end.)
  const double phi = 0.4 * 0.4 - 0.3 * 0.3;
  for (const double length : {0x1p-40, 0x1p-38, 0x1.8p-37, 0x1.fffffp-37, 0x1p-36, 0x1p-30}) {
    SCOPED_TRACE(length);
    const Pair inside{Capsule(length, 0.1), b, Pose(), crossed};
    EXPECT_EQ(generic(inside), length >= 0x1p-36);
    EXPECT_NEAR(fused(inside).phi, phi, 1e-15);
    EXPECT_LT(fused(inside).core_points[0].norm(), 1e-16);
    expect_matches_general(inside, 1e-13);
    const Pair held{Capsule(length, 0.1), b, Pose({0.1, 0, 0}, identity), crossed};
    EXPECT_TRUE(generic(held));
    expect_matches_references(held, 1e-13);
  }
  // An end of a at b's axis (a's core from x = 0 to 1), then moved along a's axis by 2^-40
  // (inside the tie band, 2^-36 of 2^-1 here) and by 1e-9 (outside it), each way: ties are the
  // general pipeline's, and the answers agree across the band.
  for (const double shift : {0.0, 0x1p-40, -0x1p-40, 1e-9, -1e-9}) {
    SCOPED_TRACE(shift);
    const Pair end_at_axis{a, b, Pose({0.5 + shift, 0, 0}, identity), crossed};
    EXPECT_EQ(generic(end_at_axis), std::abs(shift) > 1e-10);
    const Proximity result = fused(end_at_axis);
    EXPECT_NEAR(result.core_points[0].x(), std::max(shift, 0.0), 1e-16);
    EXPECT_NEAR(result.phi, phi + std::max(shift, 0.0) * std::max(shift, 0.0), 1e-15);
    expect_matches_general(end_at_axis, 1e-13);
  }
  // Scenes below 2^-1000 are the general pipeline's (1 / scale would not be a normal number);
  // their points and normal scale as the path's (phi, of order 2^-2000, underflows).
  const Pair unit{a, b, Pose({0.1, 0.05, 0}, identity), Pose({-0.05, 0.02, 0.3}, about_z(1.0))};
  ASSERT_TRUE(generic(unit));
  const int k = -1001;
  const double f = std::ldexp(1.0, k);
  const Pair tiny{Capsule(f * a.length(), f * a.radius()), Capsule(f * b.length(), f * b.radius()),
                  scaled(unit.pose_a, k), scaled(unit.pose_b, k)};
  EXPECT_FALSE(generic(tiny));
  const Proximity result = fused(tiny), base = fused(unit);
  EXPECT_LT((result.normal - base.normal).norm(), 1e-13);
  for (int c = 0; c < 2; ++c) {
    EXPECT_LT((std::ldexp(1.0, -k) * result.core_points[c] - base.core_points[c]).norm(), 1e-13);
  }
}

// fuzz_proximity's finding (CI, stop 44): a core 2e-81 long, 3 from a speck, its axis at a right
// angle to the line between them. The closest point's parameter, 1.5e-202 from the middle, is
// inside the core in exact arithmetic, but the axis is known to ~1e-16, which moves it by ~1e-16
// of the distance, far past either end: a tie along the whole core. The fused pass computed the
// axis exactly and took the point as free, the general pipeline's rounding held it at an end,
// and phi's Hessian differed by 2 in the positions' block (free: 0 along the core, held: 2) and
// by 36 in q_b's. Ties are now the general pipeline's, whatever path is asked.
TEST(CapsuleProximity, ACoreShorterThanTheAxesRoundingIsATie) {
  const Pair p{Capsule(2.6657913884525794e-82, 0),
               Capsule(2.0546545316943124e-81, 3.9111294961626162e-315),
               Pose({4.374567730286343e-69, 6.2217686780788177e-320, 8.622360669331673e-308},
                    Eigen::Vector4d(0, 0, 1, 0)),
               Pose({-3, -1.5309611444885864e-202, -1.0206407629923909e-202},
                    Eigen::Vector4d(std::sqrt(0.5), 0, 0, std::sqrt(0.5)))};
  EXPECT_FALSE(generic(p));
  const ProximityHessian general =
      detail::general_capsule_proximity_hessian(p.a, p.pose_a, p.b, p.pose_b);
  const ProximityHessian hessian = proximity_hessian(Shape(p.a), p.pose_a, Shape(p.b), p.pose_b);
  EXPECT_EQ(hessian.hessian, general.hessian);
  EXPECT_EQ(hessian.points_jacobian, general.points_jacobian);
  EXPECT_NEAR(hessian.phi, 9.0, 1e-15);
}

// Two points inside their segments: the normal is -+(u x v) / |u x v|, as the general pipeline
// takes it. D / |D| carries s's rounding, ~eps |w| / (sin^2 |D|): a hostile review's pair (both
// axes in the xy plane, the normal exactly z) got (1.7e-13, -1.7e-14, 1) from it.
TEST(CapsuleProximity, NormalOfTwoInnerPointsIsExact) {
  const Pair p{Capsule(1.999, 0), Capsule(1.999, 0), Pose(),
               Pose({-1.9136399208967076, 0.10399592593041433, 0.010362708799863365},
                    Eigen::Vector4d(0.052887107911724768, 0, 0, 0.99860049760488978))};
  ASSERT_TRUE(generic(p));
  const Proximity ab = fused(p), ba = proximity(p.b, p.pose_b, p.a, p.pose_a);
  EXPECT_LT((ab.normal - Eigen::Vector3d::UnitZ()).norm(), 1e-15);
  EXPECT_LT((ab.normal + ba.normal).norm(), 1e-15);
  EXPECT_EQ(proximity_jacobian(p.a, p.pose_a, p.b, p.pose_b).normal, ab.normal);
}

// Two inner points near the edge of the case (sin^2 = 1.01e-2, gap 0.0103, radius 1.99): the
// surface points' Jacobian against the general pipeline's (both within 1e-14 of 50 digits),
// with no (1 + R / gap) allowance. The review of the first fused Jacobian measured 7e-11 here:
// its normal motion (I - n n') (dp2 - dp1) / |Delta| carried 1 / sin^2 times the axes' rounding
// times R / |Delta|; the edges' normal does not move with the positions at all.
TEST(CapsuleProximity, InnerPointsJacobianIsExact) {
  const Pair p{Capsule(1.99, 1.99), Capsule(1.99, 0.79878076383288976),
               Pose({0, 0, 0}, Eigen::Vector4d(0.059930149699555957, 0.032907540093997573,
                                               0.32745174853133679, -0.94239101404126324)),
               Pose({-0.17741590796507692, -0.058558665451077234, 0.0074676432623888801},
                    Eigen::Vector4d(0.0067357397526827132, 0.014268703643235049,
                                    0.060744655212883879, -0.17288577189825372))};
  ASSERT_TRUE(generic(p));
  const ProximityJacobian fast = proximity_jacobian(p.a, p.pose_a, p.b, p.pose_b);
  const ProximityHessian general =
      detail::general_capsule_proximity_hessian(p.a, p.pose_a, p.b, p.pose_b);
  const double q_norm_b = p.pose_b.q().norm();  // 0.19: q_b's columns are 5x larger
  for (int column = 0; column < 14; ++column) {
    const double unit = column >= 10 ? 1.0 / q_norm_b : 1.0;
    for (int row = 0; row < 6; ++row) {
      EXPECT_NEAR(fast.points_jacobian(row, column), general.points_jacobian(row, column),
                  1e-13 * unit)
          << row << ", " << column;
    }
  }
  // The surface points move with the positions exactly as the core points do.
  for (const int column : {0, 1, 2, 7, 8, 9}) {
    EXPECT_EQ(fast.points_jacobian.col(column), fast.core_points_jacobian.col(column)) << column;
  }
}

// A scene of 2^-538 with |q| = 2e-40: the quaternion gradient, ~1e-284, is a normal number, but
// scale^2 = 2^-1076 is not; both paths multiply by scale twice (a hostile review found it
// flushed to zero).
TEST(CapsuleProximity, QuaternionGradientOfATinySceneDoesNotUnderflow) {
  const double u = std::ldexp(1.0, -538);
  const Pair p{Capsule(u, 0), Capsule(u, 0), Pose({0, 0, 0}, Eigen::Vector4d(2e-40, 0, 0, 0)),
               Pose({1.2 * u, 1.2 * u, 1.2 * u},
                    2e-40 * Eigen::Vector4d(std::sqrt(0.5), 0, 0, std::sqrt(0.5)))};
  ASSERT_TRUE(generic(p));
  const Proximity fast = fused(p);
  const ProximityHessian general =
      detail::general_capsule_proximity_hessian(p.a, p.pose_a, p.b, p.pose_b);
  for (int j = 3; j < 7; ++j) {
    EXPECT_NEAR(fast.gradient(j), general.gradient(j), 1e-12 * std::abs(general.gradient(j)));
  }
  EXPECT_GT(std::abs(fast.gradient(5)), 1e-285);  // dphi/dq_a's y part, 1.48e-284
  EXPECT_GT(std::abs(general.gradient(5)), 1e-285);
}

}  // namespace
}  // namespace diffpills::testing
