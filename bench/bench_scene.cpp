// Scenes of many bodies (issue 11): diffpills' broadphase and whole query beside FCL 0.7's
// DynamicAABBTreeCollisionManager on the same scene, for 10^2 .. 10^4 bodies at a fixed density.
//
// The scene: n bodies of 1 to 3 primitives each (sticks: capsules of length 0.4, radius 0.05;
// plates: squares of half-side 0.15 padded by 0.02), each primitive within 0.3 of its body's
// origin, the bodies at uniform random positions and attitudes in a cube holding one body per
// 0.5 cubic units, so that the density (and each body's number of neighbours) is the same at every
// n. FCL gets the same primitives as collision objects (a capsule, and a box as thick as the
// padded plate), in one manager, set up once at these poses, as a user of it would (each query then
// sets the same poses again and refits: the case most favourable to its incremental tree).
//
//   Scene_Broadphase/n       diffpills: each body's attitude normalized, the world box of every
//                            primitive, the hierarchy built and walked (src/scene/broadphase.hpp):
//                            the pairs of checked bodies whose boxes overlap.
//   Fcl_Broadphase/n         FCL: every object's transform set and its AABB computed, the
//                            manager's update() (refit), and collide() with a callback that
//                            counts the pairs of overlapping AABBs and asks for no narrowphase.
//   *_Broadphase/FarBody/n   the same with body 0 moved alone to (1e9, 1e9, 1e9): the other
//                            centres share one cell of the whole scene's grid (the hierarchy
//                            must split them in their own bounds).
//   Scene_Broadphase_TwoExcludedBodies/n   two excluded bodies of n / 2 overlapping capsules.
//   Scene_Contacts/n         diffpills: Scene::contacts, broadphase and signed distance with the
//                            gradients with respect to the body poses, margin 0.
//   Fcl_BroadphaseDistance/n FCL: the same broadphase, then fcl::distance on every pair it reports
//                            (no gradients).
#include <benchmark/benchmark.h>
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>

#include <Eigen/Geometry>
#include <map>
#include <memory>
#include <random>
#include <vector>

#include "diffpills/diffpills.hpp"
#include "scene/broadphase.hpp"
#include "support/fcl_pose.hpp"

namespace {

using diffpills::Body;
using diffpills::BodyShape;
using diffpills::Capsule;
using diffpills::PaddedPolygon;
using diffpills::Pose;

constexpr double kStickLength = 0.4, kStickRadius = 0.05;
constexpr double kPlateHalf = 0.15, kPlateRadius = 0.02;
constexpr double kVolumePerBody = 0.5;

PaddedPolygon plate() {
  Eigen::MatrixX2d C(4, 2);
  C << 1, 0, 0, 1, -1, 0, 0, -1;
  return PaddedPolygon(C, Eigen::Vector4d::Constant(kPlateHalf), kPlateRadius);
}

Eigen::Vector4d random_attitude(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  const Eigen::Vector4d q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q.normalized();
}

struct BenchScene {
  diffpills::Scene scene;
  std::vector<Pose> poses;
};

// far_body: the same scene with body 0 moved to (1e9, 1e9, 1e9), alone.
const BenchScene& bench_scene(int bodies, bool far_body = false) {
  static std::map<std::pair<int, bool>, std::unique_ptr<BenchScene>> made;
  auto& slot = made[{bodies, far_body}];
  if (slot) return *slot;
  std::mt19937_64 rng(static_cast<std::uint64_t>(bodies));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double side = std::cbrt(kVolumePerBody * bodies);
  std::vector<Body> list;
  std::vector<Pose> poses;
  for (int i = 0; i < bodies; ++i) {
    std::vector<BodyShape> shapes;
    const int count = 1 + static_cast<int>(3 * unit(rng)) % 3;
    for (int k = 0; k < count; ++k) {
      const Pose local(
          Eigen::Vector3d(0.6 * unit(rng) - 0.3, 0.6 * unit(rng) - 0.3, 0.6 * unit(rng) - 0.3),
          random_attitude(rng));
      if (unit(rng) < 0.5) {
        shapes.push_back({Capsule(kStickLength, kStickRadius), local});
      } else {
        shapes.push_back({plate(), local});
      }
    }
    list.emplace_back("b" + std::to_string(i), shapes);
    poses.emplace_back(Eigen::Vector3d(side * unit(rng), side * unit(rng), side * unit(rng)),
                       random_attitude(rng));
  }
  if (far_body) poses[0] = Pose(Eigen::Vector3d::Constant(1e9), poses[0].q());
  slot = std::make_unique<BenchScene>(BenchScene{diffpills::Scene(list), poses});
  return *slot;
}

// FCL's objects for the scene's primitives, with their world transforms.
struct FclScene {
  std::vector<std::shared_ptr<fcl::CollisionGeometryd>> geometries;
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  std::vector<fcl::Transform3d> transforms;
  std::unique_ptr<fcl::DynamicAABBTreeCollisionManagerd> manager;
};

std::unique_ptr<FclScene> fcl_scene(const BenchScene& s) {
  auto out = std::make_unique<FclScene>();
  const auto stick = std::make_shared<fcl::Capsuled>(kStickRadius, kStickLength);
  const auto box = std::make_shared<fcl::Boxd>(2 * (kPlateHalf + kPlateRadius),
                                               2 * (kPlateHalf + kPlateRadius), 2 * kPlateRadius);
  std::vector<fcl::CollisionObjectd*> raw;
  for (int i = 0; i < s.scene.size(); ++i) {
    for (const BodyShape& shape : s.scene.body(i).shapes()) {
      const bool capsule = std::holds_alternative<Capsule>(shape.shape);
      const Eigen::Quaterniond qb(s.poses[i].q()(0), s.poses[i].q()(1), s.poses[i].q()(2),
                                  s.poses[i].q()(3));
      const Eigen::Quaterniond ql(shape.pose.q()(0), shape.pose.q()(1), shape.pose.q()(2),
                                  shape.pose.q()(3));
      const Eigen::Quaterniond q = qb * ql;
      const Pose world(s.poses[i].r() + qb * shape.pose.r(),
                       Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()));
      fcl::Transform3d t = fcl::Transform3d::Identity();
      t.linear() = q.toRotationMatrix();
      t.translation() = world.r();
      out->transforms.push_back(capsule ? diffpills::testing::fcl_capsule_transform(world) : t);
      out->objects.push_back(std::make_unique<fcl::CollisionObjectd>(
          capsule ? std::shared_ptr<fcl::CollisionGeometryd>(stick)
                  : std::shared_ptr<fcl::CollisionGeometryd>(box)));
      out->objects.back()->setTransform(out->transforms.back());
      out->objects.back()->computeAABB();
      raw.push_back(out->objects.back().get());
    }
  }
  out->manager = std::make_unique<fcl::DynamicAABBTreeCollisionManagerd>();
  out->manager->registerObjects(raw);
  out->manager->setup();
  return out;
}

struct Counter {
  long pairs = 0;
};
bool count_pair(fcl::CollisionObjectd*, fcl::CollisionObjectd*, void* data) {
  ++static_cast<Counter*>(data)->pairs;
  return false;  // go on, no narrowphase
}
bool distance_pair(fcl::CollisionObjectd* a, fcl::CollisionObjectd* b, void* data) {
  fcl::DistanceRequestd request;
  fcl::DistanceResultd result;
  benchmark::DoNotOptimize(fcl::distance(a, b, request, result));
  ++static_cast<Counter*>(data)->pairs;
  return false;
}

void fcl_update(FclScene& f) {
  for (std::size_t i = 0; i < f.objects.size(); ++i) {
    f.objects[i]->setTransform(f.transforms[i]);
    f.objects[i]->computeAABB();
  }
  f.manager->update();
}

void Scene_Broadphase(benchmark::State& state, bool far_body) {
  const BenchScene& s = bench_scene(static_cast<int>(state.range(0)), far_body);
  // Made once, as Scene's constructor does.
  const diffpills::detail::SceneOutlines outlines =
      diffpills::detail::make_outlines(s.scene.bodies());
  std::size_t pairs = 0;
  for (auto _ : state) {
    // As Scene::contacts calls it: the bodies' attitudes normalized into a vector of the query's.
    std::vector<diffpills::detail::UnitQuaternion> attitudes;
    pairs = diffpills::detail::broadphase(s.scene, outlines, s.poses, 0.0, attitudes).size();
    benchmark::DoNotOptimize(pairs);
  }
  state.counters["pairs"] = static_cast<double>(pairs);
  state.SetComplexityN(state.range(0));
}

// Two bodies of n / 2 capsules each, interleaved along a line 1e-3 long (every box overlaps every
// other), never checked against each other: no pair, and no walk across the bodies.
void Scene_Broadphase_TwoExcludedBodies(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::vector<BodyShape> even, odd;
  for (int k = 0; k < n; ++k) {
    const Pose pose(Eigen::Vector3d(1e-3 * k / n, 0, 0), Eigen::Vector4d(1, 0, 0, 0));
    (k % 2 ? odd : even).push_back({Capsule(1.0, 0.5), pose});
  }
  const diffpills::Scene scene({Body("even", even), Body("odd", odd)}, {{"even", "odd"}});
  const std::vector<Pose> poses(2);
  const diffpills::detail::SceneOutlines outlines =
      diffpills::detail::make_outlines(scene.bodies());
  std::size_t pairs = 0;
  for (auto _ : state) {
    std::vector<diffpills::detail::UnitQuaternion> attitudes;
    pairs = diffpills::detail::broadphase(scene, outlines, poses, 0.0, attitudes).size();
    benchmark::DoNotOptimize(pairs);
  }
  state.counters["pairs"] = static_cast<double>(pairs);
}

// FCL's query: the poses set and refitted, then its tree walked with `on_pair` for each pair.
void run_fcl(benchmark::State& state, bool far_body, fcl::CollisionCallBack<double> on_pair) {
  const BenchScene& s = bench_scene(static_cast<int>(state.range(0)), far_body);
  const std::unique_ptr<FclScene> f = fcl_scene(s);
  Counter counter;
  for (auto _ : state) {
    fcl_update(*f);
    counter.pairs = 0;
    f->manager->collide(&counter, on_pair);
    benchmark::DoNotOptimize(counter.pairs);
  }
  state.counters["pairs"] = static_cast<double>(counter.pairs);
  state.SetComplexityN(state.range(0));
}

void Fcl_Broadphase(benchmark::State& state, bool far_body) {
  run_fcl(state, far_body, count_pair);
}

void Scene_Contacts(benchmark::State& state) {
  const BenchScene& s = bench_scene(static_cast<int>(state.range(0)));
  std::size_t contacts = 0;
  for (auto _ : state) {
    contacts = s.scene.contacts(s.poses, 0.0).size();
    benchmark::DoNotOptimize(contacts);
  }
  state.counters["contacts"] = static_cast<double>(contacts);
  state.SetComplexityN(state.range(0));
}

void Fcl_BroadphaseDistance(benchmark::State& state) { run_fcl(state, false, distance_pair); }

}  // namespace

#define SCENE_SIZES \
  RangeMultiplier(10)->Range(100, 10000)->Complexity()->Unit(benchmark::kMillisecond)
#define FAR_BODY_SIZES Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond)
BENCHMARK_CAPTURE(Scene_Broadphase, , false)->SCENE_SIZES;
BENCHMARK_CAPTURE(Fcl_Broadphase, , false)->SCENE_SIZES;
BENCHMARK_CAPTURE(Scene_Broadphase, FarBody, true)->FAR_BODY_SIZES;
BENCHMARK_CAPTURE(Fcl_Broadphase, FarBody, true)->FAR_BODY_SIZES;
BENCHMARK(Scene_Broadphase_TwoExcludedBodies)->Arg(64000)->Unit(benchmark::kMillisecond);
BENCHMARK(Scene_Contacts)->SCENE_SIZES;
BENCHMARK(Fcl_BroadphaseDistance)->SCENE_SIZES;

BENCHMARK_MAIN();
