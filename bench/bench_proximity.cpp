// diffpills beside FCL 0.7 on the same random poses, per pair type (issue 3's scenes):
//   capsule-capsule  lengths 1.2 and 0.8, radii 0.2 and 0.15
//   capsule-hexagon  the first capsule against a padded regular hexagon, d = 0.6
//   hexagon-hexagon  padded regular hexagons, d = 0.6 and 0.43
// FCL gets the same cores (its capsule axis is body z, ours x; a hexagon is an FCL Convex with one
// face) and computes a bare distance; diffpills computes phi, both closest points, the normal and
// the 14-entry gradient, and for *_Jacobian both 6x14 Jacobians too, for *_Hessian also the 14x14
// Hessian of phi.
#include <benchmark/benchmark.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/narrowphase/distance.h>
#include <hwy/targets.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "arm_shelf/arm_shelf.hpp"
#include "car_bus/car_bus.hpp"
#include "car_bus/car_bus_ipopt.hpp"
#include "diffpills/diffpills.hpp"
#include "ipopt/problem_nlp.hpp"
#include "quadrotor_window/quadrotor_window.hpp"

namespace {

using namespace diffpills;

constexpr int kPoses = 1024;

struct Scene {
  std::vector<Pose> a, b;
};

// Positions in [-1.5, 1.5]^3, uniformly random attitudes: a mix of near and far pairs.
const Scene& scene() {
  static const Scene poses = [] {
    std::mt19937_64 rng(2026);
    std::normal_distribution<double> normal;
    std::uniform_real_distribution<double> box(-1.5, 1.5);
    Scene s;
    for (int i = 0; i < kPoses; ++i) {
      for (auto* list : {&s.a, &s.b}) {
        const Eigen::Vector4d q =
            Eigen::Vector4d(normal(rng), normal(rng), normal(rng), normal(rng)).normalized();
        list->emplace_back(Eigen::Vector3d(box(rng), box(rng), box(rng)), q);
      }
    }
    return s;
  }();
  return poses;
}

PaddedPolygon hexagon(double apothem, double radius) {
  Eigen::MatrixX2d C(6, 2);
  for (int i = 0; i < 6; ++i) C.row(i) << std::cos(M_PI / 3 * i), std::sin(M_PI / 3 * i);
  return PaddedPolygon(C, Eigen::VectorXd::Constant(6, apothem), radius);
}

const Capsule kCapsuleA(1.2, 0.2), kCapsuleB(0.8, 0.15);
const PaddedPolygon kHexagonA = hexagon(0.6, 0.1), kHexagonB = hexagon(0.43, 0.05);

template <class A, class B>
void run_proximity(benchmark::State& state, const A& a, const B& b, Method method) {
  const Scene& s = scene();
  const ProximityOptions options{method};
  int i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(proximity(a, s.a[i], b, s.b[i], options));
    i = (i + 1) % kPoses;
  }
}

template <class A, class B>
void run_jacobian(benchmark::State& state, const A& a, const B& b) {
  const Scene& s = scene();
  int i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(proximity_jacobian(a, s.a[i], b, s.b[i]));
    i = (i + 1) % kPoses;
  }
}

// proximity_hessian: the Jacobians and the 14x14 Hessian of phi (its shapes as Shape).
template <class A, class B>
void run_hessian(benchmark::State& state, const A& a, const B& b) {
  const Scene& s = scene();
  const Shape shape_a = a, shape_b = b;
  int i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(proximity_hessian(shape_a, s.a[i], shape_b, s.b[i]));
    i = (i + 1) % kPoses;
  }
}

// proximity_with_hessian: phi, the gradient and the 14x14 Hessian, without the Jacobians.
template <class A, class B>
void run_with_hessian(benchmark::State& state, const A& a, const B& b) {
  const Scene& s = scene();
  const Shape shape_a = a, shape_b = b;
  int i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(proximity_with_hessian(shape_a, s.a[i], shape_b, s.b[i]));
    i = (i + 1) % kPoses;
  }
}

// `run` with the library's vector kernels held to the instruction set indexed by the benchmark's
// argument among those this CPU runs (Highway's targets, widest first), labelled with its name.
template <class Run>
void on_instruction_set(benchmark::State& state, const Run& run) {
  const std::vector<std::int64_t> targets = hwy::SupportedAndGeneratedTargets();
  const auto index = static_cast<std::size_t>(state.range(0));
  if (index >= targets.size()) {
    state.SkipWithError("no such instruction set here");
    return;
  }
  hwy::SetSupportedTargetsForTest(targets[index]);
  state.SetLabel(hwy::TargetName(targets[index]));
  run();
  hwy::SetSupportedTargetsForTest(0);
}

// proximity_with_hessian of two capsules (the Hessian's Gram matrix, symmetric_gram.hpp) and
// proximity of two hexagons (the edge pairs' bounds, segment_bounds.hpp) on each instruction set.
void CapsuleCapsule_WithHessian_InstructionSet(benchmark::State& state) {
  on_instruction_set(state, [&] { run_with_hessian(state, kCapsuleA, kCapsuleB); });
}
void HexagonHexagon_Proximity_InstructionSet(benchmark::State& state) {
  on_instruction_set(state, [&] { run_proximity(state, kHexagonA, kHexagonB, Method::kDefault); });
}

// FCL's transform of one of our poses; `capsule` adds the z-to-x axis change.
fcl::Transform3d fcl_pose(const Pose& pose, bool capsule) {
  const Eigen::Quaterniond q(pose.q()(0), pose.q()(1), pose.q()(2), pose.q()(3));
  fcl::Transform3d t = fcl::Transform3d::Identity();
  t.linear() = q.toRotationMatrix();
  if (capsule)
    t.linear() =
        t.linear() * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  t.translation() = pose.r();
  return t;
}

std::shared_ptr<fcl::Convexd> fcl_hexagon(const PaddedPolygon& polygon) {
  auto vertices = std::make_shared<std::vector<fcl::Vector3d>>();
  auto faces = std::make_shared<std::vector<int>>();
  faces->push_back(static_cast<int>(polygon.vertices().rows()));
  for (Eigen::Index i = 0; i < polygon.vertices().rows(); ++i) {
    vertices->emplace_back(polygon.vertices()(i, 0), polygon.vertices()(i, 1), 0.0);
    faces->push_back(static_cast<int>(i));
  }
  return std::make_shared<fcl::Convexd>(vertices, 1, faces);
}

// FCL's distance, or with `signed_distance` its signed distance (GJK/EPA through libccd, the only
// solver FCL 0.7 offers for it).
void run_fcl(benchmark::State& state, const fcl::CollisionGeometryd& a, bool a_capsule,
             const fcl::CollisionGeometryd& b, bool b_capsule, bool signed_distance = false) {
  const Scene& s = scene();
  std::vector<fcl::Transform3d> ta, tb;
  for (int i = 0; i < kPoses; ++i) {
    ta.push_back(fcl_pose(s.a[i], a_capsule));
    tb.push_back(fcl_pose(s.b[i], b_capsule));
  }
  fcl::DistanceRequestd request;
  request.enable_signed_distance = signed_distance;
  int i = 0;
  for (auto _ : state) {
    fcl::DistanceResultd result;
    benchmark::DoNotOptimize(fcl::distance(&a, ta[i], &b, tb[i], request, result));
    i = (i + 1) % kPoses;
  }
}

template <class A, class B>
void run_signed_distance(benchmark::State& state, const A& a, const B& b) {
  const Scene& s = scene();
  int i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(signed_distance(a, s.a[i], b, s.b[i]));
    i = (i + 1) % kPoses;
  }
}

// The signed distance with its gradient (issue 10) beside FCL's signed distance; FCL's hexagons
// are the bare cores, as in the rows above.
void CapsuleCapsule_SignedDistance(benchmark::State& s) {
  run_signed_distance(s, kCapsuleA, kCapsuleB);
}
void CapsuleCapsule_FclSignedDistance(benchmark::State& s) {
  const fcl::Capsuled a(0.2, 1.2), b(0.15, 0.8);
  run_fcl(s, a, true, b, true, true);
}
void CapsuleHexagon_SignedDistance(benchmark::State& s) {
  run_signed_distance(s, kCapsuleA, kHexagonA);
}
void CapsuleHexagon_FclSignedDistance(benchmark::State& s) {
  const fcl::Capsuled a(0.2, 1.2);
  run_fcl(s, a, true, *fcl_hexagon(kHexagonA), false, true);
}
void HexagonHexagon_SignedDistance(benchmark::State& s) {
  run_signed_distance(s, kHexagonA, kHexagonB);
}
void HexagonHexagon_FclSignedDistance(benchmark::State& s) {
  run_fcl(s, *fcl_hexagon(kHexagonA), false, *fcl_hexagon(kHexagonB), false, true);
}

void CapsuleCapsule_Proximity(benchmark::State& s) {
  run_proximity(s, kCapsuleA, kCapsuleB, Method::kDefault);
}
void CapsuleCapsule_InteriorPoint(benchmark::State& s) {
  run_proximity(s, kCapsuleA, kCapsuleB, Method::kInteriorPoint);
}
void CapsuleHexagon_InteriorPoint(benchmark::State& s) {
  run_proximity(s, kCapsuleA, kHexagonA, Method::kInteriorPoint);
}
void HexagonHexagon_InteriorPoint(benchmark::State& s) {
  run_proximity(s, kHexagonA, kHexagonB, Method::kInteriorPoint);
}
void CapsuleCapsule_Jacobian(benchmark::State& s) { run_jacobian(s, kCapsuleA, kCapsuleB); }
void CapsuleCapsule_Hessian(benchmark::State& s) { run_hessian(s, kCapsuleA, kCapsuleB); }
void CapsuleCapsule_WithHessian(benchmark::State& s) { run_with_hessian(s, kCapsuleA, kCapsuleB); }
void CapsuleCapsule_FclDistance(benchmark::State& s) {
  const fcl::Capsuled a(0.2, 1.2), b(0.15, 0.8);
  run_fcl(s, a, true, b, true);
}
void CapsuleHexagon_Proximity(benchmark::State& s) {
  run_proximity(s, kCapsuleA, kHexagonA, Method::kDefault);
}
void CapsuleHexagon_Jacobian(benchmark::State& s) { run_jacobian(s, kCapsuleA, kHexagonA); }
void CapsuleHexagon_Hessian(benchmark::State& s) { run_hessian(s, kCapsuleA, kHexagonA); }
void CapsuleHexagon_WithHessian(benchmark::State& s) { run_with_hessian(s, kCapsuleA, kHexagonA); }
void CapsuleHexagon_FclDistance(benchmark::State& s) {
  const fcl::Capsuled a(0.2, 1.2);
  run_fcl(s, a, true, *fcl_hexagon(kHexagonA), false);
}
void HexagonHexagon_Proximity(benchmark::State& s) {
  run_proximity(s, kHexagonA, kHexagonB, Method::kDefault);
}
void HexagonHexagon_Jacobian(benchmark::State& s) { run_jacobian(s, kHexagonA, kHexagonB); }
void HexagonHexagon_Hessian(benchmark::State& s) { run_hessian(s, kHexagonA, kHexagonB); }
void HexagonHexagon_WithHessian(benchmark::State& s) { run_with_hessian(s, kHexagonA, kHexagonB); }
void HexagonHexagon_FclDistance(benchmark::State& s) {
  run_fcl(s, *fcl_hexagon(kHexagonA), false, *fcl_hexagon(kHexagonB), false);
}

// Growth with the vertex count (issue 9): regular k-gons of circumradius 0.6 and 0.43 (radii 0.1,
// 0.05) at the scene's poses, for k from 8 to 10^5. Up to 32 x 32 vertex pairs every edge pair is
// enumerated; beyond, the windows of polygon_windows.hpp make a pair about linear in k.
PaddedPolygon regular_polygon(int count, double circumradius, double radius) {
  Eigen::MatrixX2d C(count, 2);
  for (int i = 0; i < count; ++i) {
    C.row(i) << std::cos(2 * M_PI * i / count), std::sin(2 * M_PI * i / count);
  }
  return PaddedPolygon(C, Eigen::VectorXd::Constant(count, circumradius * std::cos(M_PI / count)),
                       radius);
}

void PolygonPolygon_Vertices(benchmark::State& state) {
  const auto count = static_cast<int>(state.range(0));
  run_proximity(state, regular_polygon(count, 0.6, 0.1), regular_polygon(count, 0.43, 0.05),
                Method::kDefault);
  state.SetComplexityN(count);
}
void CapsulePolygon_Vertices(benchmark::State& state) {
  const auto count = static_cast<int>(state.range(0));
  run_proximity(state, kCapsuleA, regular_polygon(count, 0.6, 0.1), Method::kDefault);
  state.SetComplexityN(count);
}
BENCHMARK(PolygonPolygon_Vertices)
    ->RangeMultiplier(4)
    ->Range(8, 32768)
    ->Arg(100000)
    ->Complexity()
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(CapsulePolygon_Vertices)
    ->RangeMultiplier(4)
    ->Range(8, 32768)
    ->Arg(100000)
    ->Complexity()
    ->Unit(benchmark::kMicrosecond);

// The large-polygon cases' vertex counts, 1,024 to 65,536 by fours and 10^5, in milliseconds
// with the growth fitted.
void large_polygon_sizes(benchmark::internal::Benchmark* benchmark) {
  benchmark->RangeMultiplier(4)
      ->Range(1024, 65536)
      ->Arg(100000)
      ->Complexity()
      ->Unit(benchmark::kMillisecond);
}

// Two unit-circumradius k-gons, radius 0, the first at the origin and the second at `second`.
void run_unit_polygons(benchmark::State& state, const Pose& second) {
  const auto count = static_cast<int>(state.range(0));
  const PaddedPolygon polygon = regular_polygon(count, 1.0, 0.0);
  const Pose origin;
  for (auto _ : state) benchmark::DoNotOptimize(proximity(polygon, origin, polygon, second));
  state.SetComplexityN(count);
}

// Nearly parallel faces (a hostile review's stall): two unit-circumradius k-gons, one 0.5 above
// the other and tilted 1e-11 rad about x, so that thousands of vertices of each tie within the
// windows' margin and the windows' pairs are swept (separated_polygons.cpp).
void PolygonPolygon_NearlyParallel(benchmark::State& state) {
  run_unit_polygons(state, Pose({0, 0, 0.5}, {std::cos(0.5e-11), std::sin(0.5e-11), 0, 0}));
}
BENCHMARK(PolygonPolygon_NearlyParallel)->Apply(large_polygon_sizes);

// Two unit-circumradius k-gons 1e13 and 1e30 times their size apart (in the plane, along a
// diagonal), alternately: far beyond the point where the intersection tolerance (1e-12 of the
// scene) exceeds their size and every feature pair ties, and where rounding makes every depth along
// the line between them the same number (separated_polygons.cpp, search_point_candidates).
void PolygonPolygon_FarApart(benchmark::State& state) {
  const auto count = static_cast<int>(state.range(0));
  const PaddedPolygon polygon = regular_polygon(count, 1.0, 0.0);
  const Pose origin;
  const std::array<Pose, 2> far = {Pose({1e13, 0, 0}, {1, 0, 0, 0}),
                                   Pose({7.0710678e29, 7.0710678e29, 0}, {1, 0, 0, 0})};
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(proximity(polygon, origin, polygon, far[i]));
    i ^= 1;
  }
  state.SetComplexityN(count);
}
BENCHMARK(PolygonPolygon_FarApart)->Apply(large_polygon_sizes);

// Two unit-circumradius k-gons 1e8 apart, facing, the second tilted 1e-5 rad (a hostile review:
// 0.18 s at 2,000 vertices, 8.3 s at 16,000): their features tie only within 64 ulps of the
// distance, and the windows judge ties by that tie tolerance, not by the intersection tolerance
// (1e-12 of the distance, 1e-4 here, which took the polygons whole; polygon_windows.cpp).
void PolygonPolygon_FarApartTilted(benchmark::State& state) {
  run_unit_polygons(state, Pose({0, 0, 1e8}, {std::cos(0.5e-5), std::sin(0.5e-5), 0, 0}));
}
BENCHMARK(PolygonPolygon_FarApartTilted)->Apply(large_polygon_sizes);

// The same k-gons tilted only 1e-8 rad: their heights over each other vary by less than the
// rounding of coordinates 1e8 from the origin, every feature pair ties, and they are solved as
// parallel faces across their mean normal (polygon_polygon.cpp, level_and_apart). Swept as
// apart polygons they took 1.3 s at 8,000 vertices, growing as k^2.
void PolygonPolygon_FarApartLevel(benchmark::State& state) {
  run_unit_polygons(state, Pose({0, 0, 1e8}, {std::cos(0.5e-8), std::sin(0.5e-8), 0, 0}));
}
BENCHMARK(PolygonPolygon_FarApartLevel)->Apply(large_polygon_sizes);

// The same k-gons 1e8 apart, tilted 1e-5 rad and moved 2.5 to the side: the tilt carries the
// second 1,000 to the side in the first's frame, where bounds along the plane rule nothing out
// (65 ms at 4,000 vertices, growing as k^2); far windows are searched in depth_box_tree.hpp's
// hierarchies (separated_polygons.cpp, search_point_candidates).
void PolygonPolygon_FarApartTiltedAside(benchmark::State& state) {
  run_unit_polygons(state, Pose({2.5, 0, 1e8}, {std::cos(0.5e-5), std::sin(0.5e-5), 0, 0}));
}
BENCHMARK(PolygonPolygon_FarApartTiltedAside)->Apply(large_polygon_sizes);

// The same k-gons 3e6 apart, tilted 1e-6 rad about the line toward which they are moved 2.5 to
// the side: every pair's distance differs from the least by a slope and by its offset across the
// line between them squared over twice the distance, both near the distance's rounding. The
// sweeps by depth along that line and along the plane each bounded one of the two and stayed
// quadratic (0.66 s at 32,000 vertices); the hierarchies bound both.
void PolygonPolygon_FarApartNearlyFacing(benchmark::State& state) {
  const double half = 0.5e-6;
  run_unit_polygons(state, Pose({1.5, 2.0, 3e6},
                                {std::cos(half), 0.6 * std::sin(half), 0.8 * std::sin(half), 0}));
}
BENCHMARK(PolygonPolygon_FarApartNearlyFacing)->Apply(large_polygon_sizes);

// Needles thinner than the tolerance their radii set: two 1000:1 ellipses of k vertices, 4e-11
// long and 4e-14 wide, radius 1, the second turned a quarter about y and 3e-11 beside the first, so
// each crosses the other's plane. Two polygons are solved at their cores' own tolerances
// (pair_setup.hpp, search_tolerances); at the scene's, both were taken whole and swept
// (0.35 s at 8,000 vertices, 1.6-1.9 s at 40,000).
PaddedPolygon needle(int count, double phase, double length = 2e-11) {
  Eigen::MatrixX2d C(count, 2);
  Eigen::VectorXd d(count);
  const auto at = [&](int k) {
    const double angle = phase + 2 * M_PI * k / count;
    return Eigen::Vector2d(1e-3 * length * std::cos(angle), length * std::sin(angle));
  };
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector2d p = at(i), q = at(i + 1);
    const Eigen::Vector2d normal = Eigen::Vector2d(q.y() - p.y(), p.x() - q.x()).normalized();
    C.row(i) = normal.transpose();
    d(i) = normal.dot(p);
  }
  return PaddedPolygon(C, d, 1.0);
}

// Two 1000:1 ellipses of k vertices (semi-axes 1e-3 and 1, radius 1), the second turned to face
// the first 1e8 above it, tilted 1e-5 rad about their long axis and 0.5 along it: level faces,
// laid flat into one plane where they lie 500 apart across their long sides. The sweep along the
// plane, whose bound was the gap along their long axis, took every pair of the near-tie set there
// (1.3 s at 64,000 vertices, growing as k^1.8; a hostile review); every large window is now
// searched in the hierarchies (separated_polygons.cpp, search_large_windows).
void PolygonPolygon_LevelEllipses(benchmark::State& state) {
  const auto count = static_cast<int>(state.range(0));
  const PaddedPolygon ellipse = needle(count, 0.1234, 1.0);
  const double half = 0.5 * (M_PI + 1e-5);
  const Pose facing({0, 0.5, 1e8}, {std::cos(half), 0, std::sin(half), 0});
  for (auto _ : state) benchmark::DoNotOptimize(proximity(ellipse, Pose(), ellipse, facing));
  state.SetComplexityN(count);
}
BENCHMARK(PolygonPolygon_LevelEllipses)->Apply(large_polygon_sizes);

void PolygonPolygon_Needles(benchmark::State& state) {
  const auto count = static_cast<int>(state.range(0));
  const PaddedPolygon a = needle(count, 0.0), b = needle(count, 0.3);
  const Pose origin, beside({3e-11, 0, 0}, {std::sqrt(0.5), 0, std::sqrt(0.5), 0});
  for (auto _ : state) benchmark::DoNotOptimize(proximity(a, origin, b, beside));
  state.SetComplexityN(count);
}
BENCHMARK(PolygonPolygon_Needles)->Apply(large_polygon_sizes);
// The same needles crossing (the second 1e-14 beside the first's middle, through its plane): the
// signed distance's penetration search, at the needles' own tolerance (penetration.hpp).
void PolygonPolygon_SignedDistanceNeedles(benchmark::State& state) {
  const auto count = static_cast<int>(state.range(0));
  const PaddedPolygon a = needle(count, 0.0), b = needle(count, 0.3);
  const Pose origin, crossing({1e-14, 0, 0}, {std::sqrt(0.5), 0, std::sqrt(0.5), 0});
  for (auto _ : state) benchmark::DoNotOptimize(signed_distance(a, origin, b, crossing));
  state.SetComplexityN(count);
}
BENCHMARK(PolygonPolygon_SignedDistanceNeedles)->Apply(large_polygon_sizes);
// The same needles shrunk by 1e-95 (2e-106 long beside radii of 1), below the 1e-100 of the
// frame under which cores keep the frame's tolerances: the signed distance solves them in a frame
// of their own (signed_distance.cpp); at the frame's tolerances every facet tied (1.8 s at 8,000
// vertices, 7.7 s at 16,000).
void PolygonPolygon_SignedDistanceTinyNeedles(benchmark::State& state) {
  const auto count = static_cast<int>(state.range(0));
  const PaddedPolygon a = needle(count, 0.0, 2e-106), b = needle(count, 0.3, 2e-106);
  const Pose origin, crossing({1e-109, 0, 0}, {std::sqrt(0.5), 0, std::sqrt(0.5), 0});
  for (auto _ : state) benchmark::DoNotOptimize(signed_distance(a, origin, b, crossing));
  state.SetComplexityN(count);
}
BENCHMARK(PolygonPolygon_SignedDistanceTinyNeedles)->Apply(large_polygon_sizes);
// Shrunk by 1e-140 more (2e-146 long): below 1e-140 of the frame the cores keep its tolerances,
// which exceed the whole pair, and touch at any gap; they are answered without the penetration
// search, which met every facet as a tie (1.5 s at 8,000 vertices, growing as k^2).
void PolygonPolygon_SignedDistanceSpeckNeedles(benchmark::State& state) {
  const auto count = static_cast<int>(state.range(0));
  const PaddedPolygon a = needle(count, 0.0, 2e-146), b = needle(count, 0.3, 2e-146);
  const Pose origin, crossing({1e-149, 0, 0}, {std::sqrt(0.5), 0, std::sqrt(0.5), 0});
  for (auto _ : state) benchmark::DoNotOptimize(signed_distance(a, origin, b, crossing));
  state.SetComplexityN(count);
}
BENCHMARK(PolygonPolygon_SignedDistanceSpeckNeedles)->Apply(large_polygon_sizes);

// Two k-gons crossing (the signed distance in penetration): the unit-circumradius k-gon at the
// origin, the 0.7 one turned off its plane by 30 to 90 degrees about a random in-plane axis, its
// centre within 0.3 of the first's: 64 such poses, cycled. D has ~k^2 / 2 edge-pair facets; above
// 32 x 32 vertices the search of the edge chains' hierarchies visits only those that can hold the
// nearest one (penetration.hpp).
void PolygonPolygon_SignedDistanceCrossing(benchmark::State& state) {
  const auto count = static_cast<int>(state.range(0));
  const PaddedPolygon large = regular_polygon(count, 1.0, 0.01);
  const PaddedPolygon small = regular_polygon(count, 0.7, 0.01);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<Pose> crossing;
  for (int i = 0; i < 64; ++i) {
    const double in_plane = 2 * M_PI * uniform(rng), tilt = M_PI / 6 + M_PI / 3 * uniform(rng);
    const Eigen::Quaterniond q(
        Eigen::AngleAxisd(tilt, Eigen::Vector3d(std::cos(in_plane), std::sin(in_plane), 0)));
    crossing.emplace_back(
        Eigen::Vector3d(0.3 * uniform(rng), 0.3 * uniform(rng), 0.3 * uniform(rng)),
        Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()));
  }
  const Pose origin;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(signed_distance(large, origin, small, crossing[i]));
    i = (i + 1) % crossing.size();
  }
  state.SetComplexityN(count);
}
BENCHMARK(PolygonPolygon_SignedDistanceCrossing)
    ->RangeMultiplier(4)
    ->Range(8, 32768)
    ->Arg(100000)
    ->Complexity()
    ->Unit(benchmark::kMicrosecond);

// Two k-gons crossing nearly parallel (a hostile review's stall): unit circumradius, the second's
// rows turned by 0.1234 rad in its plane and its plane 1e-11 rad off the first's, through the same
// centre. Most vertices of each lie within the tolerance of the other's support value, and each
// support vertex's shadow is tested against the other face (penetration.cpp, ShadowTest).
void PolygonPolygon_SignedDistanceNearlyParallel(benchmark::State& state) {
  const auto count = static_cast<int>(state.range(0));
  Eigen::MatrixX2d C(count, 2), turned(count, 2);
  for (int i = 0; i < count; ++i) {
    C.row(i) << std::cos(2 * M_PI * i / count), std::sin(2 * M_PI * i / count);
    turned.row(i) << std::cos(0.1234 + 2 * M_PI * i / count),
        std::sin(0.1234 + 2 * M_PI * i / count);
  }
  const PaddedPolygon a(C, Eigen::VectorXd::Ones(count), 0.01);
  const PaddedPolygon b(turned, Eigen::VectorXd::Ones(count), 0.01);
  const Pose flat, tilted(Eigen::Vector3d::Zero(), {std::cos(0.5e-11), std::sin(0.5e-11), 0, 0});
  for (auto _ : state) benchmark::DoNotOptimize(signed_distance(a, flat, b, tilted));
  state.SetComplexityN(count);
}
BENCHMARK(PolygonPolygon_SignedDistanceNearlyParallel)->Apply(large_polygon_sizes);

// proximity_batch over N pose pairs (the first argument: 10^4, 10^5, 10^6) with 1 and 2 threads
// (the second), wall-clock time; the rows cycle through the 1,024 pose pairs above.
struct BatchPoses {
  PositionArray r_a, r_b;
  QuaternionArray q_a, q_b;
};

BatchPoses make_batch_poses(Eigen::Index count) {
  BatchPoses p{PositionArray(count, 3), PositionArray(count, 3), QuaternionArray(count, 4),
               QuaternionArray(count, 4)};
  const Scene& s = scene();
  for (Eigen::Index i = 0; i < count; ++i) {
    const auto k = static_cast<std::size_t>(i % kPoses);
    const auto m = static_cast<std::size_t>((i * 7 + 3) % kPoses);
    p.r_a.row(i) = s.a[k].r().transpose();
    p.q_a.row(i) = s.a[k].q().transpose();
    p.r_b.row(i) = s.b[m].r().transpose();
    p.q_b.row(i) = s.b[m].q().transpose();
  }
  return p;
}

// The poses of one size, made once (10^6 rows are 112 MB).
const BatchPoses& batch_poses(Eigen::Index count) {
  static std::map<Eigen::Index, BatchPoses> made;
  auto found = made.find(count);
  if (found == made.end()) found = made.emplace(count, make_batch_poses(count)).first;
  return found->second;
}

// proximity_batch, or signed_distance_batch (its other measure), over the first argument's rows.
enum class Measure { kPhi, kSignedDistance };

void run_batch(benchmark::State& state, const Shape& a, const Shape& b,
               Measure measure = Measure::kPhi) {
  const Eigen::Index count = state.range(0);
  const BatchPoses& p = batch_poses(count);
  const BatchOptions options{static_cast<int>(state.range(1))};
  Eigen::VectorXd value(count);
  GradientArray gradient(count, 14);
  for (auto _ : state) {
    if (measure == Measure::kPhi) {
      proximity_batch(a, p.r_a, p.q_a, b, p.r_b, p.q_b, value, gradient, options);
    } else {
      signed_distance_batch(a, p.r_a, p.q_a, b, p.r_b, p.q_b, value, gradient, options);
    }
    benchmark::DoNotOptimize(value.data());
  }
  state.SetItemsProcessed(state.iterations() * count);
}

void Batch_CapsuleCapsule(benchmark::State& s) { run_batch(s, kCapsuleA, kCapsuleB); }
void Batch_HexagonHexagon(benchmark::State& s) { run_batch(s, kHexagonA, kHexagonB); }
// A capsule and a polygon: the pool and the in-place rows carry over, the vector kernel (two
// capsules only) does not; each row is the single call.
void Batch_CapsuleHexagon(benchmark::State& s) { run_batch(s, kCapsuleA, kHexagonB); }

// The poses of bench/bench_python.py (a formula both languages evaluate identically), so that the
// Python batch's overhead is measured against identical work here (issue 5: within 1.3x).
void Batch_CapsuleCapsule_PythonPoses(benchmark::State& state) {
  constexpr Eigen::Index kCount = 100000;
  PositionArray r_a(kCount, 3), r_b(kCount, 3);
  QuaternionArray q_a(kCount, 4), q_b(kCount, 4);
  for (Eigen::Index k = 0; k < kCount; ++k) {
    const double i = static_cast<double>(k);
    r_a.row(k) << 1.5 * std::sin(0.37 * i), 1.5 * std::cos(0.11 * i), 1.5 * std::sin(0.05 * i);
    r_b.row(k) << 1.5 * std::cos(0.23 * i), 1.5 * std::sin(0.17 * i), 1.5 * std::cos(0.07 * i);
    q_a.row(k) << std::cos(0.13 * i) + 0.1, std::sin(0.29 * i) + 0.1, std::cos(0.41 * i) + 0.1,
        std::sin(0.07 * i) + 0.1;
    q_b.row(k) << std::sin(0.19 * i) + 0.1, std::cos(0.31 * i) + 0.1, std::sin(0.43 * i) + 0.1,
        std::cos(0.03 * i) + 0.1;
  }
  const BatchOptions options{static_cast<int>(state.range(0))};
  Eigen::VectorXd phi(kCount);
  GradientArray gradient(kCount, 14);
  for (auto _ : state) {
    proximity_batch(kCapsuleA, r_a, q_a, kCapsuleB, r_b, q_b, phi, gradient, options);
    benchmark::DoNotOptimize(phi.data());
  }
  state.SetItemsProcessed(state.iterations() * kCount);
}

// signed_distance_batch of the same capsule rows (the vector kernel's other measure).
void Batch_CapsuleCapsule_SignedDistance(benchmark::State& s) {
  run_batch(s, kCapsuleA, kCapsuleB, Measure::kSignedDistance);
}

// The capsule batch on one thread with the vector kernel held to each instruction set this CPU
// runs (Highway's targets, widest first: the argument indexes them), labelled with its name.
void Batch_CapsuleCapsule_InstructionSet(benchmark::State& state) {
  on_instruction_set(state, [&] {
    const Eigen::Index count = 100000;
    const BatchPoses& p = batch_poses(count);
    Eigen::VectorXd phi(count);
    GradientArray gradient(count, 14);
    for (auto _ : state) {
      proximity_batch(kCapsuleA, p.r_a, p.q_a, kCapsuleB, p.r_b, p.q_b, phi, gradient, {1});
      benchmark::DoNotOptimize(phi.data());
    }
    state.SetItemsProcessed(state.iterations() * count);
  });
}

// The same rows split by OpenMP (libgomp, dynamic schedule) and by oneTBB (parallel_for): the two
// runtimes issue 13 proposed for the persistent pool, measured beside ours (worker_pool.hpp) on
// the same work. Each takes blocks of the size the batch cuts (batch.cpp: n / (16 x hardware
// threads), 16 to 512 rows) and runs proximity_batch on one thread over each, so that every
// runtime's rows go through the vector kernel and the batch's error handling alike; what differs
// is who hands out the blocks. oneTBB gets the block indices with a simple_partitioner, one task a
// block: a blocked_range of rows with the block as its grain was cut at oneTBB's own points, 48
// calls of 156-312 rows at 10^4 rows (OpenMP: 33 blocks of 312, the last shorter) and 64-128
// calls of up to 15,625 rows at 10^5-10^6, not the batch's blocks.
Eigen::Index batch_block_rows(Eigen::Index count) {
  const auto hardware =
      static_cast<Eigen::Index>(std::max(1U, std::thread::hardware_concurrency()));
  return std::clamp<Eigen::Index>(count / (16 * hardware), 16, 512);
}

// Block k of `block` rows (the last one shorter) through proximity_batch on one thread.
void run_block(const BatchPoses& p, Eigen::Index k, Eigen::Index block, Eigen::VectorXd& phi,
               GradientArray& gradient) {
  const Eigen::Index begin = k * block;
  const Eigen::Index rows = std::min(phi.size() - begin, block);
  proximity_batch(kCapsuleA, p.r_a.middleRows(begin, rows), p.q_a.middleRows(begin, rows),
                  kCapsuleB, p.r_b.middleRows(begin, rows), p.q_b.middleRows(begin, rows),
                  phi.segment(begin, rows), gradient.middleRows(begin, rows), {1});
}

void Batch_CapsuleCapsule_OpenMP(benchmark::State& state) {
  const Eigen::Index count = state.range(0);
  const BatchPoses& p = batch_poses(count);
  const int threads = static_cast<int>(state.range(1));
  const Eigen::Index block = batch_block_rows(count);
  const Eigen::Index blocks = (count + block - 1) / block;
  Eigen::VectorXd phi(count);
  GradientArray gradient(count, 14);
  for (auto _ : state) {
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (Eigen::Index k = 0; k < blocks; ++k) {
      run_block(p, k, block, phi, gradient);
    }
    benchmark::DoNotOptimize(phi.data());
  }
  state.SetItemsProcessed(state.iterations() * count);
}

void Batch_CapsuleCapsule_Tbb(benchmark::State& state) {
  const Eigen::Index count = state.range(0);
  const BatchPoses& p = batch_poses(count);
  const Eigen::Index block = batch_block_rows(count);
  const Eigen::Index blocks = (count + block - 1) / block;
  tbb::task_arena arena(static_cast<int>(state.range(1)));
  Eigen::VectorXd phi(count);
  GradientArray gradient(count, 14);
  for (auto _ : state) {
    arena.execute([&] {
      tbb::parallel_for(
          tbb::blocked_range<Eigen::Index>(0, blocks, 1),
          [&](const tbb::blocked_range<Eigen::Index>& indices) {
            for (Eigen::Index k = indices.begin(); k < indices.end(); ++k) {
              run_block(p, k, block, phi, gradient);
            }
          },
          tbb::simple_partitioner());
    });
    benchmark::DoNotOptimize(phi.data());
  }
  state.SetItemsProcessed(state.iterations() * count);
}

BENCHMARK(Batch_CapsuleCapsule)
    ->ArgsProduct({{10000, 100000, 1000000}, {1, 2}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(Batch_CapsuleCapsule_SignedDistance)
    ->ArgsProduct({{10000, 1000000}, {1, 2}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(Batch_CapsuleCapsule_InstructionSet)
    ->DenseRange(0, 4)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(Batch_CapsuleCapsule_OpenMP)
    ->ArgsProduct({{10000, 100000, 1000000}, {1, 2}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(Batch_CapsuleCapsule_Tbb)
    ->ArgsProduct({{10000, 100000, 1000000}, {1, 2}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(Batch_CapsuleCapsule_PythonPoses)
    ->Arg(1)
    ->Arg(2)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(Batch_HexagonHexagon)
    ->ArgsProduct({{10000, 100000}, {1, 2}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(Batch_CapsuleHexagon)
    ->ArgsProduct({{10000, 100000}, {1, 2}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// The motion-planning problems, each solved by ALTRO and by Ipopt (with its limited-memory and
// with its exact Hessian) from the same guess, every solver of a problem over the same number of
// solves (Iterations below: 5 for the car-bus, 3 for the quadrotor, 1 for the arm). One iteration
// is one solve, with Ipopt's setup, Ipopt stopped at the demo's CPU limit; the quadrotor's and the
// arm's Ipopt runs end differently from build to build (BENCHMARKS.md, 2026-11-28), so these time
// whatever run this build gives, and the label says how it ended.
// Targets (issue 13): car-bus ALTRO <= 5 ms, quadrotor <= 30 ms, arm <= 200 ms.

// Times an ALTRO solve() and reports the last run's iLQR iterations and cost as counters, so that
// a change of speed can be told from a change of path.
template <typename Solve>
void time_altro(benchmark::State& state, const Solve& solve) {
  trajopt::AltroResult result;
  for (auto _ : state) {
    result = solve();
    benchmark::DoNotOptimize(result.cost);
  }
  state.counters["iterations"] = result.iterations;
  state.counters["cost"] = result.cost;
}
void CarBus_Altro(benchmark::State& state) {
  const examples::CarBusProblem problem{examples::CarBusScenario{}};
  const std::vector<Eigen::VectorXd> guess = problem.straight_line_controls();
  time_altro(state, [&] { return trajopt::solve(problem, problem.scenario().x0, guess); });
}
// Times solve() (an Ipopt run with the demo's CPU limit, examples::kComparisonCpuSeconds: from
// these guesses its runs on the quadrotor and the arm turn on the last bits, BENCHMARKS.md
// 2026-11-28) and labels the benchmark with how the last run ended ("solved", "time limit (-4)").
template <typename Solve>
void time_ipopt(benchmark::State& state, const Solve& solve) {
  std::string status;
  for (auto _ : state) {
    const examples::IpoptRun run = solve();
    benchmark::DoNotOptimize(run.cost);
    status = run.status;
  }
  state.SetLabel(status);
}
void CarBus_Ipopt(benchmark::State& state) {
  const examples::CarBusProblem problem{examples::CarBusScenario{}};
  const std::vector<Eigen::VectorXd> guess = problem.straight_line_controls();
  const auto hessian = static_cast<examples::IpoptHessian>(state.range(0));
  time_ipopt(state, [&] {
    return examples::solve_with_ipopt(problem, guess, hessian, examples::kComparisonCpuSeconds);
  });
}
// 13 states, 4 thrusts, 51 knots, six obstacles.
void QuadrotorWindow_Altro(benchmark::State& state) {
  const examples::QuadrotorWindowProblem problem{examples::QuadrotorWindowScenario{}};
  const std::vector<Eigen::VectorXd> guess = problem.hover_controls();
  time_altro(state, [&] { return trajopt::solve(problem, problem.scenario().x0, guess); });
}
void QuadrotorWindow_Ipopt(benchmark::State& state) {
  const examples::QuadrotorWindowProblem problem{examples::QuadrotorWindowScenario{}};
  const std::vector<Eigen::VectorXd> guess = problem.hover_controls();
  const auto hessian = static_cast<examples::IpoptHessian>(state.range(0));
  time_ipopt(state, [&] {
    return examples::solve_problem_with_ipopt(problem, problem.scenario().x0, guess, hessian,
                                              examples::kComparisonCpuSeconds);
  });
}
// 7 joints, 41 knots, 85 shape pairs checked at 4 points of every step through the scene query.
void ArmShelf_Altro(benchmark::State& state) {
  const examples::ArmShelfProblem problem{examples::ArmShelfScenario{}};
  const std::vector<Eigen::VectorXd> guess = problem.retreat_controls();
  time_altro(state, [&] {
    return trajopt::solve(problem, problem.scenario().start, guess,
                          examples::ArmShelfProblem::settings());
  });
}
void ArmShelf_Ipopt(benchmark::State& state) {
  const examples::ArmShelfProblem problem{examples::ArmShelfScenario{}};
  const std::vector<Eigen::VectorXd> guess = problem.retreat_controls();
  const auto hessian = static_cast<examples::IpoptHessian>(state.range(0));
  time_ipopt(state, [&] {
    return examples::solve_problem_with_ipopt(problem, problem.scenario().start, guess, hessian,
                                              examples::kComparisonCpuSeconds);
  });
}
// Argument exact:0: Ipopt's limited-memory Hessian, exact:1: the exact one
// (examples::IpoptHessian).
constexpr auto kLimitedMemory = static_cast<std::int64_t>(examples::IpoptHessian::kLimitedMemory);
constexpr auto kExact = static_cast<std::int64_t>(examples::IpoptHessian::kExact);
BENCHMARK(CarBus_Altro)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(CarBus_Ipopt)
    ->Arg(kLimitedMemory)
    ->Arg(kExact)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);
BENCHMARK(QuadrotorWindow_Altro)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(QuadrotorWindow_Ipopt)
    ->ArgName("exact")
    ->Arg(kLimitedMemory)
    ->Arg(kExact)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);
BENCHMARK(ArmShelf_Altro)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(ArmShelf_Ipopt)
    ->Arg(kLimitedMemory)
    ->Arg(kExact)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

BENCHMARK(CapsuleCapsule_FclDistance);
BENCHMARK(CapsuleCapsule_Proximity);
BENCHMARK(CapsuleCapsule_InteriorPoint);
BENCHMARK(CapsuleCapsule_Jacobian);
BENCHMARK(CapsuleCapsule_Hessian);
BENCHMARK(CapsuleCapsule_WithHessian);
BENCHMARK(CapsuleCapsule_WithHessian_InstructionSet)->DenseRange(0, 4);
BENCHMARK(CapsuleHexagon_FclDistance);
BENCHMARK(CapsuleHexagon_Proximity);
BENCHMARK(CapsuleHexagon_InteriorPoint);
BENCHMARK(CapsuleHexagon_Jacobian);
BENCHMARK(CapsuleHexagon_Hessian);
BENCHMARK(CapsuleHexagon_WithHessian);
BENCHMARK(HexagonHexagon_FclDistance);
BENCHMARK(HexagonHexagon_Proximity);
BENCHMARK(HexagonHexagon_Proximity_InstructionSet)->DenseRange(0, 4);
BENCHMARK(HexagonHexagon_InteriorPoint);
BENCHMARK(HexagonHexagon_Jacobian);
BENCHMARK(HexagonHexagon_Hessian);
BENCHMARK(HexagonHexagon_WithHessian);
BENCHMARK(CapsuleCapsule_FclSignedDistance);
BENCHMARK(CapsuleCapsule_SignedDistance);
BENCHMARK(CapsuleHexagon_FclSignedDistance);
BENCHMARK(CapsuleHexagon_SignedDistance);
BENCHMARK(HexagonHexagon_FclSignedDistance);
BENCHMARK(HexagonHexagon_SignedDistance);

}  // namespace

BENCHMARK_MAIN();
