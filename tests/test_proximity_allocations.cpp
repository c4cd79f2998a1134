// proximity(), proximity_jacobian() and signed_distance() of shapes with up to 32 vertices
// allocate nothing (proximity.hpp, batch.hpp): this binary counts every heap allocation (it
// defines malloc and its relatives over glibc's own, which Eigen's matrices and operator new both
// reach) around calls in the configurations whose code paths keep buffers: stacked and coplanar
// parallel polygons (the common region of two polygons), penetrating ones (the deepest facet),
// capsules crossing a polygon and lying in its plane, at sizes on both sides of every buffer's
// bound. Its own binary, since the definitions apply to everything linked in; not under
// AddressSanitizer, which defines malloc itself (the test is skipped there, and labelled
// no_sanitize).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstddef>
#include <string>

#include "diffpills/diffpills.hpp"

namespace {
std::atomic<long> allocations{0};
}  // namespace

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kCounting = false;
#else
constexpr bool kCounting = true;
extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* p, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);
void __libc_free(void* p);

void* malloc(std::size_t size) noexcept {
  ++allocations;
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) noexcept {
  ++allocations;
  return __libc_calloc(count, size);
}
void* realloc(void* p, std::size_t size) noexcept {
  ++allocations;
  return __libc_realloc(p, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) noexcept {
  ++allocations;
  return __libc_memalign(alignment, size);
}
void free(void* p) noexcept { __libc_free(p); }
}
#endif

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
  const long before = allocations.load();
  all();
  return allocations.load() - before;
}

TEST(ProximityAllocations, NoneUpToThirtyTwoVertices) {
  if (!kCounting) GTEST_SKIP() << "AddressSanitizer defines malloc";
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

}  // namespace
}  // namespace diffpills
