// segment_distance_bounds (src/proximity/segment_bounds.hpp), the vector kernel that decides
// which edge pairs of two small polygons reach the exact segment solver, on every instruction set
// Highway compiled it for that this CPU runs: its lower bounds never exceed the exact distance
// (closest_segment_parameters, separately written), are tight for pairs far from parallel, and
// its least value is an achievable distance; and polygon pairs get the same answer, bit for bit,
// on every instruction set (the scalar bounds below 4 lanes, the kernel's above), near the
// long-double brute force.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "diffpills/diffpills.hpp"
#include "proximity/segment_bounds.hpp"
#include "proximity/segment_segment.hpp"
#include "support/random_shapes.hpp"
#include "support/reference.hpp"

namespace diffpills::testing {
namespace {

template <class Check>
void on_every_target(const Check& check) {
  for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    SCOPED_TRACE(std::string("target ") + hwy::TargetName(target));
    ASSERT_STREQ(detail::segment_bounds_target(), hwy::TargetName(target));
    check(target);
  }
  hwy::SetSupportedTargetsForTest(0);
}

// A random segment of length up to 2 (sometimes 0) near the origin; with `parallel_to`, within
// `twist` rad of that direction.
detail::Segment random_segment(Rng& rng, const Eigen::Vector3d* parallel_to = nullptr,
                               double twist = 0.0) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::Vector3d direction(unit(rng), unit(rng), unit(rng));
  if (parallel_to != nullptr) {
    const Eigen::Vector3d normal = parallel_to->unitOrthogonal();
    direction = Eigen::AngleAxisd(twist, normal) * *parallel_to;
  }
  const double length =
      std::uniform_int_distribution<int>(0, 9)(rng) == 0 ? 0.0 : 2 * std::abs(unit(rng));
  return {Eigen::Vector3d(unit(rng), unit(rng), unit(rng)), direction.normalized(), length};
}

double exact_distance(const detail::Segment& p, const detail::Segment& q) {
  const detail::SegmentParameters closest = detail::closest_segment_parameters(p, q);
  return (p.at(closest.s_offset) - q.at(closest.t_offset)).norm();
}

TEST(SegmentBounds, BoundTheExactDistanceOnEveryInstructionSet) {
  on_every_target([](std::int64_t) {
    Rng rng(1401);
    int tight = 0, loose = 0;
    for (int trial = 0; trial < 400; ++trial) {
      const Eigen::Index count_a = 1 + trial % 9, count_b = 1 + (trial / 9) % 17;
      std::vector<detail::Segment> a, b;
      detail::SegmentColumns columns_a(count_a), columns_b(count_b);
      for (Eigen::Index i = 0; i < count_a; ++i) {
        a.push_back(random_segment(rng));
        columns_a.set(i, a.back());
      }
      for (Eigen::Index j = 0; j < count_b; ++j) {
        // A third near parallel to one of A's (twists 0 to 1e-1), the rest at random.
        const bool near = j % 3 == 0;
        const double twist = near ? std::pow(10.0, -static_cast<double>(trial % 8)) * (j % 2) : 0.0;
        b.push_back(
            near ? random_segment(rng, &a[static_cast<std::size_t>(j) % a.size()].direction, twist)
                 : random_segment(rng));
        columns_b.set(j, b.back());
      }
      const Eigen::Index width = columns_b.padded_size();
      std::vector<double> lower(static_cast<std::size_t>(count_a * width));
      const double least = detail::segment_distance_bounds(columns_a, columns_b, lower.data());
      double closest = std::numeric_limits<double>::infinity();
      for (Eigen::Index i = 0; i < count_a; ++i) {
        for (Eigen::Index j = 0; j < count_b; ++j) {
          const detail::Segment& p = a[static_cast<std::size_t>(i)];
          const detail::Segment& q = b[static_cast<std::size_t>(j)];
          const double exact = exact_distance(p, q);
          closest = std::min(closest, exact);
          const double bound = std::sqrt(lower[static_cast<std::size_t>(i * width + j)]);
          // The margin the enumeration uses is 100 times its tolerance, 1e-10 of the scene; the
          // bound is meant to hold with 1e-13.
          ASSERT_LE(bound - 1e-13, exact) << "pair " << i << ", " << j << " trial " << trial;
          const double sin = p.direction.cross(q.direction).norm();
          if (sin > 1e-2 && p.length > 0 && q.length > 0) {
            ASSERT_NEAR(bound, exact, 1e-13) << "a pair far from parallel gets its distance";
            ++tight;
          } else {
            ++loose;
          }
        }
      }
      // The least value is the squared distance of two points of some pair: at least the
      // closest pair's, and at most it plus the rounding where a pair is far from parallel.
      ASSERT_GE(std::sqrt(least), closest - 1e-13);
      ASSERT_TRUE(std::isfinite(least));
    }
    EXPECT_GT(tight, 2000);
    EXPECT_GT(loose, 200);
  });
}

// The enumeration answers the same on every instruction set (its bounds differ, the pairs it
// solves within the tie band do not), and near the brute force.
TEST(SegmentBounds, PolygonPairsAnswerTheSameOnEveryInstructionSet) {
  Rng rng(1402);
  std::vector<TestShape> as, bs;
  std::vector<Pose> pas, pbs;
  for (int trial = 0; trial < 600; ++trial) {
    as.push_back(random_polygon(rng, 1.0));
    bs.push_back(random_polygon(rng, 1.0));
    pas.push_back(random_pose(rng, 1.5));
    Pose pb = random_pose(rng, 1.5);
    if (trial % 4 == 0) pb = Pose(pb.r(), pas.back().q());  // parallel planes: ties
    pbs.push_back(pb);
  }
  std::vector<ProximityJacobian> reference;
  for (std::size_t t = 0; t < as.size(); ++t) {
    reference.push_back(proximity_jacobian(as[t].shape, pas[t], bs[t].shape, pbs[t]));
    const Proximity& p = reference.back();
    if (p.cores_intersect) continue;
    const ClosestPair brute = brute_force_closest(to_world(as[t], pas[t]), to_world(bs[t], pbs[t]));
    const long double radii =
        std::get<PaddedPolygon>(as[t].shape).radius() +
        static_cast<long double>(std::get<PaddedPolygon>(bs[t].shape).radius());
    ASSERT_NEAR(p.phi, static_cast<double>(brute.distance * brute.distance - radii * radii), 1e-11)
        << t;
  }
  int vectorized = 0, scalar = 0;
  on_every_target([&](std::int64_t) {
    (detail::segment_bounds_vectorized() ? vectorized : scalar) += 1;
    for (std::size_t t = 0; t < as.size(); ++t) {
      const ProximityJacobian p = proximity_jacobian(as[t].shape, pas[t], bs[t].shape, pbs[t]);
      ASSERT_EQ(p.phi, reference[t].phi) << t;
      ASSERT_EQ(p.core_points[0], reference[t].core_points[0]) << t;
      ASSERT_EQ(p.core_points[1], reference[t].core_points[1]) << t;
      ASSERT_EQ(p.gradient, reference[t].gradient) << t;
      ASSERT_EQ(p.core_points_jacobian, reference[t].core_points_jacobian) << t;
    }
  });
  // Both ways of bounding the pairs ran (this CPU has at least SSE4 and AVX2).
  EXPECT_GT(vectorized, 0);
  EXPECT_GT(scalar, 0);
}

}  // namespace
}  // namespace diffpills::testing
