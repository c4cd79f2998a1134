// proximity(), proximity_jacobian() and signed_distance() of shapes with up to 32 vertices
// allocate nothing (proximity.hpp, batch.hpp): this binary counts every heap allocation
// (support/allocation_counter.hpp) around calls in the configurations whose code paths keep
// buffers: stacked and coplanar parallel polygons (the common region of two polygons), penetrating
// ones (the deepest facet), capsules crossing a polygon and lying in its plane, at sizes on both
// sides of every buffer's bound. Skipped under AddressSanitizer (labelled no_sanitize).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>

#include "diffpills/diffpills.hpp"
#include "support/allocation_counter.hpp"

namespace diffpills {
namespace {

// A regular k-gon of circumradius about 1 (rows at the edges' normals, offset cos(pi / k)).
PaddedPolygon regular(int k) {
  Eigen::MatrixX2d C(k, 2);
  for (int i = 0; i < k; ++i) {
    const double angle = 2.0 * M_PI * i / k;
    C.row(i) << std::cos(angle), std::sin(angle);
  }
  return PaddedPolygon(C, Eigen::VectorXd::Constant(k, std::cos(M_PI / k)), 0.05);
}

// Allocations made by the three queries of a pair (after one call of each, warm).
template <class A, class B>
long allocations_of(const A& a, const Pose& pose_a, const B& b, const Pose& pose_b) {
  const auto all = [&] {
    proximity(a, pose_a, b, pose_b);
    proximity_jacobian(a, pose_a, b, pose_b);
    signed_distance(a, pose_a, b, pose_b);
  };
  all();
  const long before = testing::heap_allocations();
  all();
  return testing::heap_allocations() - before;
}

TEST(ProximityAllocations, NoneUpToThirtyTwoVertices) {
  if (!testing::kCountingAllocations) GTEST_SKIP() << "AddressSanitizer defines malloc";
  const Capsule capsule(1.0, 0.1);
  const Eigen::Vector4d level(1, 0, 0, 0), tilted(1, 0, 1, 0);
  for (const int k : {3, 8, 16, 17, 31, 32}) {
    SCOPED_TRACE("k = " + std::to_string(k));
    const PaddedPolygon polygon = regular(k);
    const Pose origin;
    EXPECT_EQ(allocations_of(polygon, origin, polygon, Pose({0.3, 0.2, 1.0}, level)), 0)
        << "stacked parallel";
    EXPECT_EQ(allocations_of(polygon, origin, polygon, Pose({0.3, 0.2, 0.01}, level)), 0)
        << "penetrating parallel";
    EXPECT_EQ(allocations_of(polygon, origin, polygon, Pose({0.5, 0.2, 0.0}, level)), 0)
        << "coplanar crossing";
    EXPECT_EQ(allocations_of(polygon, origin, polygon, Pose({0.3, 0.2, 2.5}, {1, 0.3, 0.1, 0})), 0)
        << "tilted apart";
    EXPECT_EQ(allocations_of(capsule, Pose({0.1, 0, 0}, tilted), polygon, origin), 0)
        << "capsule crossing";
    EXPECT_EQ(allocations_of(capsule, Pose({0.1, 0, 0}, level), polygon, origin), 0)
        << "capsule in the plane";
  }
  // The counter sees allocations: a polygon of 33 vertices stacked on another takes the heap.
  const PaddedPolygon large = regular(33);
  EXPECT_GT(allocations_of(large, Pose(), large, Pose({0.3, 0.2, 1.0}, level)), 0);
}

// The batch into caller-owned outputs allocates nothing (batch.hpp), on one thread or several:
// the threads' shares of the rows live on the calling thread's stack, the workers are started by
// the first call. Capsule pairs (the vector kernel, and its degenerate rows left to the single
// call) and hexagon pairs.
TEST(ProximityAllocations, NoneInABatchIntoCallerOutputs) {
  if (!testing::kCountingAllocations) GTEST_SKIP() << "AddressSanitizer defines malloc";
  constexpr Eigen::Index kRows = 3000;
  PositionArray r_a(kRows, 3), r_b(kRows, 3);
  QuaternionArray q_a(kRows, 4), q_b(kRows, 4);
  for (Eigen::Index i = 0; i < kRows; ++i) {
    const double t = static_cast<double>(i);
    r_a.row(i) << std::sin(0.3 * t), std::cos(0.7 * t), 0.5 * std::sin(0.11 * t);
    r_b.row(i) << std::cos(0.2 * t), std::sin(0.5 * t), 0.5 * std::cos(0.13 * t);
    q_a.row(i) << 1.0, 0.3 * std::sin(t), 0.2 * std::cos(t), 0.1;
    // Every tenth row's capsules parallel: rows the vector kernel leaves to the single call.
    q_b.row(i) = i % 10 == 0 ? q_a.row(i) : Eigen::RowVector4d(0.5, std::cos(t), 0.3, -0.2);
  }
  Eigen::VectorXd phi(kRows);
  GradientArray gradient(kRows, 14);
  const Capsule capsule(1.0, 0.1);
  const PaddedPolygon hexagon = regular(6);
  for (const int threads : {1, 2, 0}) {
    SCOPED_TRACE("threads = " + std::to_string(threads));
    for (const auto& [a, b] :
         {std::pair<Shape, Shape>{capsule, capsule}, std::pair<Shape, Shape>{hexagon, hexagon}}) {
      proximity_batch(a, r_a, q_a, b, r_b, q_b, phi, gradient, {threads});
      const long before = testing::heap_allocations();
      proximity_batch(a, r_a, q_a, b, r_b, q_b, phi, gradient, {threads});
      EXPECT_EQ(testing::heap_allocations() - before, 0);
    }
  }
}

}  // namespace
}  // namespace diffpills
