// Bodies and scenes (scene.hpp), against computations written apart from the scene code:
//   - the broadphase's box pairs against every pair of boxes tested directly;
//   - a query's contacts against every primitive pair of every checked body pair, each primitive
//     posed here with Eigen's quaternions and asked to signed_distance() directly, on random
//     scenes, margins and rigid motions of the whole scene;
//   - gradients with respect to the body poses against central differences of the query itself;
//   - phi against proximity();
//   - exclusions, filters, empty scenes and the errors.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "diffpills/diffpills.hpp"
#include "scene/box_tree.hpp"
#include "support/address_space.hpp"
#include "support/random_shapes.hpp"
#include "support/scene_helpers.hpp"

namespace diffpills::testing {
namespace {

double uniform(Rng& rng, double low, double high) {
  return std::uniform_real_distribution<double>(low, high)(rng);
}

Eigen::Vector4d random_quaternion(Rng& rng) {
  std::normal_distribution<double> normal;
  Eigen::Vector4d q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q * uniform(rng, 0.5, 2.0) / q.norm();  // not unit: the chain rule must handle that
}

TEST(BoxTree, OverlappingPairsAreEveryOverlappingPair) {
  EXPECT_TRUE(detail::overlapping_pairs({}).empty());
  const detail::Box unit{Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()};
  EXPECT_TRUE(detail::overlapping_pairs({unit}).empty());
  EXPECT_EQ(detail::overlapping_pairs({unit, unit}), (std::vector<std::pair<int, int>>{{0, 1}}));
  Rng rng(5);
  for (int trial = 0; trial < 60; ++trial) {
    const int count = std::uniform_int_distribution<int>(0, 400)(rng);
    std::vector<detail::Box> boxes;
    for (int i = 0; i < count; ++i) {
      // Mixed sizes, some repeated boxes, some flat or point boxes, some sharing a face.
      const Eigen::Vector3d centre(uniform(rng, -5, 5), uniform(rng, -5, 5), uniform(rng, -5, 5));
      Eigen::Vector3d half(uniform(rng, 0, 0.6), uniform(rng, 0, 0.6), uniform(rng, 0, 0.6));
      if (i % 17 == 0) half *= 8.0;
      if (i % 13 == 0) half(i % 3) = 0.0;
      if (i % 11 == 0 && !boxes.empty()) {
        boxes.push_back(boxes.back());
        continue;
      }
      if (i % 7 == 0 && !boxes.empty()) {  // touching the previous box's high x face
        const detail::Box& previous = boxes.back();
        boxes.push_back(
            {Eigen::Vector3d(previous.high.x(), previous.low.y(), previous.low.z()),
             Eigen::Vector3d(previous.high.x() + 1, previous.high.y(), previous.high.z())});
        continue;
      }
      boxes.push_back({centre - half, centre + half});
    }
    std::vector<std::pair<int, int>> expected;
    for (int i = 0; i < count; ++i) {
      for (int j = i + 1; j < count; ++j) {
        const detail::Box& a = boxes[static_cast<std::size_t>(i)];
        const detail::Box& b = boxes[static_cast<std::size_t>(j)];
        bool apart = false;
        for (int k = 0; k < 3; ++k) apart = apart || a.high(k) < b.low(k) || b.high(k) < a.low(k);
        if (!apart) expected.emplace_back(i, j);
      }
    }
    std::vector<std::pair<int, int>> found = detail::overlapping_pairs(boxes);
    std::sort(found.begin(), found.end());
    ASSERT_EQ(found, expected) << "trial " << trial << ", " << count << " boxes";
  }
}

// Pairs allowed by filters and a group predicate, against every pair tested directly: groups of
// several boxes (a body's primitives), categories and masks, excluded group pairs.
TEST(BoxTree, FilteredPairsAreEveryAllowedOverlappingPair) {
  Rng rng(6);
  for (int trial = 0; trial < 40; ++trial) {
    const int count = std::uniform_int_distribution<int>(0, 300)(rng);
    const int groups = std::max(1, count / std::uniform_int_distribution<int>(1, 6)(rng));
    std::vector<detail::Box> boxes;
    std::vector<detail::BoxFilter> filters;
    for (int i = 0; i < count; ++i) {
      const Eigen::Vector3d centre(uniform(rng, -4, 4), uniform(rng, -4, 4), uniform(rng, -4, 4));
      const Eigen::Vector3d half(uniform(rng, 0, 0.8), uniform(rng, 0, 0.8), uniform(rng, 0, 0.8));
      boxes.push_back({centre - half, centre + half});
      const int group = std::uniform_int_distribution<int>(0, groups - 1)(rng);
      // Categories 1, 2 or 4; some boxes not checked against category 2.
      const std::uint32_t category = 1u << (group % 3);
      const std::uint32_t mask = group % 4 == 1 ? ~2u : ~0u;
      filters.push_back({group, category, mask});
    }
    const auto groups_checked = [](int g, int h) { return (g + h) % 5 != 0; };
    std::vector<std::pair<int, int>> expected;
    for (int i = 0; i < count; ++i) {
      for (int j = i + 1; j < count; ++j) {
        const detail::BoxFilter& f = filters[static_cast<std::size_t>(i)];
        const detail::BoxFilter& g = filters[static_cast<std::size_t>(j)];
        if (f.group == g.group || !(f.category & g.mask) || !(g.category & f.mask) ||
            !groups_checked(f.group, g.group)) {
          continue;
        }
        const detail::Box& a = boxes[static_cast<std::size_t>(i)];
        const detail::Box& b = boxes[static_cast<std::size_t>(j)];
        bool apart = false;
        for (int k = 0; k < 3; ++k) apart = apart || a.high(k) < b.low(k) || b.high(k) < a.low(k);
        if (!apart) expected.emplace_back(i, j);
      }
    }
    std::vector<std::pair<int, int>> found =
        detail::overlapping_pairs(boxes, filters, groups_checked);
    std::sort(found.begin(), found.end());
    ASSERT_EQ(found, expected) << "trial " << trial << ", " << count << " boxes";
  }
}

// Clusters far smaller than the whole (a scene with one body 1e9 away, bodies at scales 2^-k)
// are split as finely as the rest: the centres are keyed again in the cluster's own bounds. The
// pairs are every overlapping pair, and boxes whose centres coincide still pair.
TEST(BoxTree, ClustersFarSmallerThanTheWholeAreSplitCorrectly) {
  Rng rng(7);
  std::vector<detail::Box> boxes;
  for (int i = 0; i < 600; ++i) {
    const double scale = std::ldexp(1.0, -(i % 60));  // nested clusters down to 2^-59
    const Eigen::Vector3d centre =
        scale * Eigen::Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    const Eigen::Vector3d half = scale * 0.05 * Eigen::Vector3d::Ones();
    boxes.push_back({centre - half, centre + half});
  }
  boxes.push_back({Eigen::Vector3d::Constant(1e9), Eigen::Vector3d::Constant(1e9 + 1)});
  for (int i = 0; i < 40; ++i) boxes.push_back({Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()});
  std::vector<std::pair<int, int>> expected;
  const int count = static_cast<int>(boxes.size());
  for (int i = 0; i < count; ++i) {
    for (int j = i + 1; j < count; ++j) {
      if (detail::overlap(boxes[static_cast<std::size_t>(i)], boxes[static_cast<std::size_t>(j)])) {
        expected.emplace_back(i, j);
      }
    }
  }
  std::vector<std::pair<int, int>> found = detail::overlapping_pairs(boxes);
  std::sort(found.begin(), found.end());
  EXPECT_EQ(found, expected);
}

// The primitives of one body never pair, however many overlap: a body of 2,000 coincident
// capsules beside another body gives only the pairs across the bodies.
TEST(BoxTree, OneGroupsBoxesNeverPair) {
  const detail::Box unit{Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()};
  std::vector<detail::Box> boxes(2000, unit);
  std::vector<detail::BoxFilter> filters(2000);
  EXPECT_TRUE(detail::overlapping_pairs(boxes, filters, [](int, int) { return true; }).empty());
  boxes.push_back(unit);
  filters.push_back({1, 1u, ~0u});
  EXPECT_EQ(detail::overlapping_pairs(boxes, filters, [](int, int) { return true; }).size(), 2000u);
  EXPECT_TRUE(detail::overlapping_pairs(boxes, filters, [](int, int) { return false; }).empty());
}

// A random scene: bodies of 0 to 3 primitives at random local poses, some excluded pairs and
// filters.
struct RandomScene {
  Scene scene;
  std::vector<Pose> poses;
};

RandomScene random_scene(Rng& rng, int bodies, double spread) {
  std::vector<Body> list;
  for (int i = 0; i < bodies; ++i) {
    std::vector<BodyShape> shapes;
    const int count = std::uniform_int_distribution<int>(i == 0 ? 1 : 0, 3)(rng);
    for (int k = 0; k < count; ++k) {
      const TestShape shape =
          uniform(rng, 0, 1) < 0.5 ? random_capsule(rng, 0.5, 0.1) : random_polygon(rng, 0.5);
      shapes.push_back(
          {shape.shape, Pose(Eigen::Vector3d(uniform(rng, -0.4, 0.4), uniform(rng, -0.4, 0.4),
                                             uniform(rng, -0.4, 0.4)),
                             random_quaternion(rng))});
    }
    CollisionFilter filter;
    if (i % 5 == 1) filter = {2u, 0xFFFFFFFDu};  // category 2, not checked against category 2
    list.emplace_back("body" + std::to_string(i), shapes, filter);
  }
  std::vector<std::pair<std::string, std::string>> exclude;
  for (int i = 0; i + 3 < bodies; i += 4) {
    exclude.emplace_back("body" + std::to_string(i + 3), "body" + std::to_string(i));
  }
  RandomScene out{Scene(list, exclude), {}};
  for (int i = 0; i < bodies; ++i) {
    out.poses.emplace_back(
        Eigen::Vector3d(uniform(rng, -spread, spread), uniform(rng, -spread, spread),
                        uniform(rng, -spread, spread)),
        random_quaternion(rng));
  }
  return out;
}

// A primitive's world pose, composed here with Eigen's quaternions.
Pose compose(const Pose& body, const Pose& local) {
  const Eigen::Quaterniond qb(body.q()(0), body.q()(1), body.q()(2), body.q()(3));
  const Eigen::Quaterniond ql(local.q()(0), local.q()(1), local.q()(2), local.q()(3));
  const Eigen::Quaterniond q = qb.normalized() * ql.normalized();
  return Pose(body.r() + qb.normalized() * local.r(), Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()));
}

using Key = std::tuple<int, int, int, int>;

// Every primitive pair of bodies i < j that are checked, by signed_distance() directly. The
// filters and exclusions are read from how random_scene made them, not from the scene.
std::map<Key, SignedDistance> every_pair(const RandomScene& s, double margin) {
  std::map<Key, SignedDistance> out;
  const int n = s.scene.size();
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      if (i % 5 == 1 && j % 5 == 1) continue;  // both category 2
      if (j == i + 3 && i % 4 == 0) continue;  // excluded
      const auto& a = s.scene.body(i).shapes();
      const auto& b = s.scene.body(j).shapes();
      for (std::size_t ka = 0; ka < a.size(); ++ka) {
        for (std::size_t kb = 0; kb < b.size(); ++kb) {
          const SignedDistance sd = signed_distance(
              a[ka].shape, compose(s.poses[static_cast<std::size_t>(i)], a[ka].pose), b[kb].shape,
              compose(s.poses[static_cast<std::size_t>(j)], b[kb].pose));
          if (sd.distance <= margin) {
            out[{i, j, static_cast<int>(ka), static_cast<int>(kb)}] = sd;
          }
        }
      }
    }
  }
  return out;
}

TEST(Scene, ContactsAreEveryPairWithinTheMarginOfCheckedBodies) {
  Rng rng(31);
  int compared = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int bodies = std::uniform_int_distribution<int>(2, 40)(rng);
    const RandomScene s = random_scene(rng, bodies, 0.5 + 0.05 * bodies);
    for (const double margin : {0.0, 0.2, -0.05, 1.0}) {
      const std::vector<Contact> contacts = s.scene.contacts(s.poses, margin);
      const std::map<Key, SignedDistance> expected = every_pair(s, margin);
      ASSERT_EQ(contacts.size(), expected.size()) << "trial " << trial << " margin " << margin;
      // Sorted by bodies, then shapes: the map's order.
      auto it = expected.begin();
      for (const Contact& c : contacts) {
        const Key key{c.bodies[0], c.bodies[1], c.shapes[0], c.shapes[1]};
        ASSERT_EQ(key, it->first);
        // Computed from world poses rounded alike up to a few ulps: equal to 1e-12.
        EXPECT_NEAR(c.distance, it->second.distance, 1e-12);
        EXPECT_LE((c.points[0] - it->second.points[0]).norm(), 1e-9);
        EXPECT_LE((c.normal - it->second.normal).norm(), 1e-9);
        ++it;
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 2000);
}

// world_pose against the Eigen composition above (to rounding), and as the contacts' own
// geometry: signed_distance at the world poses it gives is every contact's distance, points and
// normal, bit for bit, and its gradient taken through the chain rule by hand (scene.hpp) is the
// contact's to rounding.
TEST(Scene, WorldPoseIsTheContactsGeometry) {
  Rng rng(37);
  int compared = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const RandomScene s = random_scene(rng, 12, 1.1);
    const auto world = [&](int body, int shape) {
      const Pose& body_pose = s.poses[static_cast<std::size_t>(body)];
      const Pose& local = s.scene.body(body).shapes()[static_cast<std::size_t>(shape)].pose;
      Pose pose = world_pose(body_pose, local);
      const Pose reference = compose(body_pose, local);
      EXPECT_LE((pose.r() - reference.r()).norm(), 1e-14 * (1 + body_pose.r().norm()));
      EXPECT_LE((pose.q() - reference.q()).norm(), 1e-15);
      return pose;
    };
    for (const Contact& c : s.scene.contacts(s.poses, 0.3)) {
      const Shape& a =
          s.scene.body(c.bodies[0]).shapes()[static_cast<std::size_t>(c.shapes[0])].shape;
      const Shape& b =
          s.scene.body(c.bodies[1]).shapes()[static_cast<std::size_t>(c.shapes[1])].shape;
      const Pose pose_a = world(c.bodies[0], c.shapes[0]), pose_b = world(c.bodies[1], c.shapes[1]);
      const SignedDistance sd = signed_distance(a, pose_a, b, pose_b);
      EXPECT_EQ(sd.distance, c.distance);
      EXPECT_EQ(sd.points[0], c.points[0]);
      EXPECT_EQ(sd.points[1], c.points[1]);
      EXPECT_EQ(sd.normal, c.normal);
      // d/dr of the body is the primitive's; d/dq_body = (d r_p/dq)' g_r + R(q_l)' g_q, here
      // through rotation.hpp's rotate_gradient and the conjugate product (R(q_l)' g = g (x) q_l*)
      // of the unit attitudes, times 1 / |q| for the body's own quaternion.
      for (std::size_t side = 0; side < 2; ++side) {
        const Eigen::Index offset = 7 * static_cast<Eigen::Index>(side);
        const Pose& body_pose = s.poses[static_cast<std::size_t>(c.bodies[side])];
        const Pose& local =
            s.scene.body(c.bodies[side]).shapes()[static_cast<std::size_t>(c.shapes[side])].pose;
        const Eigen::Matrix<double, 7, 1> g = sd.gradient.segment<7>(offset);
        const Eigen::Vector4d q_l = local.q() / local.q().norm();
        const Eigen::Vector4d conjugate(q_l(0), -q_l(1), -q_l(2), -q_l(3));
        const Eigen::Vector4d expected =
            rotate_gradient(body_pose.q(), local.r(), g.head<3>()) +
            quaternion_product(g.tail<4>(), conjugate) / body_pose.q().norm();
        const Eigen::Vector4d found = c.gradient.segment<4>(offset + 3);
        EXPECT_EQ(c.gradient.segment<3>(offset), g.head<3>());
        EXPECT_LE((found - expected).norm(), 1e-12 * (1 + expected.norm()));
      }
      ++compared;
    }
  }
  EXPECT_GT(compared, 100);
}

// The whole scene moved rigidly (every body pose composed with one motion): the same contacts,
// the points moved with it.
TEST(Scene, RigidMotionOfTheWholeScene) {
  Rng rng(32);
  for (int trial = 0; trial < 20; ++trial) {
    const RandomScene s = random_scene(rng, 25, 1.2);
    const Eigen::Quaterniond m = Eigen::Quaterniond(random_quaternion(rng)).normalized();
    const Eigen::Vector3d t(uniform(rng, -5, 5), uniform(rng, -5, 5), uniform(rng, -5, 5));
    std::vector<Pose> moved;
    for (const Pose& p : s.poses) {
      const Eigen::Quaterniond q = m * Eigen::Quaterniond(p.q()(0), p.q()(1), p.q()(2), p.q()(3));
      moved.emplace_back(m * p.r() + t, Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()));
    }
    const std::vector<Contact> before = s.scene.contacts(s.poses, 0.1);
    const std::vector<Contact> after = s.scene.contacts(moved, 0.1);
    ASSERT_FALSE(before.empty());
    // A pair within 1e-12 of the margin may be in one list only.
    std::size_t j = 0;
    for (const Contact& c : before) {
      while (j < after.size() &&
             std::tie(after[j].bodies, after[j].shapes) < std::tie(c.bodies, c.shapes)) {
        EXPECT_NEAR(after[j].distance, 0.1, 1e-12);
        ++j;
      }
      if (j == after.size() || after[j].bodies != c.bodies || after[j].shapes != c.shapes) {
        EXPECT_NEAR(c.distance, 0.1, 1e-12);
        continue;
      }
      EXPECT_NEAR(after[j].distance, c.distance, 1e-12);
      EXPECT_LE((after[j].points[0] - (m * c.points[0] + t)).norm(), 1e-9);
      EXPECT_LE((after[j].normal - m * c.normal).norm(), 1e-9);
      ++j;
    }
  }
}

// The gradients of distance and phi with respect to the two body poses, by central differences of
// the query itself (bodies' quaternions and local quaternions not unit).
TEST(Scene, GradientsMatchCentralDifferencesOfBodyPoses) {
  Rng rng(33);
  int checked = 0;
  double worst = 0.0;
  for (int trial = 0; trial < 40; ++trial) {
    const RandomScene s = random_scene(rng, 8, 0.6);
    const std::vector<Contact> contacts = s.scene.contacts(s.poses, 0.3);
    for (const Contact& c : contacts) {
      const auto value = [&](const std::vector<Pose>& poses, bool phi) {
        for (const Contact& d : s.scene.contacts(poses, 10.0)) {
          if (d.bodies == c.bodies && d.shapes == c.shapes) return phi ? d.phi : d.distance;
        }
        ADD_FAILURE() << "contact lost";
        return 0.0;
      };
      const double h = 1e-6;
      for (int side = 0; side < 2; ++side) {
        for (int k = 0; k < 7; ++k) {
          std::vector<Pose> plus = s.poses, minus = s.poses;
          const std::size_t body =
              static_cast<std::size_t>(c.bodies[static_cast<std::size_t>(side)]);
          Eigen::Vector3d r = s.poses[body].r(), r2 = r;
          Eigen::Vector4d q = s.poses[body].q(), q2 = q;
          if (k < 3) {
            r(k) += h, r2(k) -= h;
          } else {
            q(k - 3) += h, q2(k - 3) -= h;
          }
          plus[body] = Pose(r, q);
          minus[body] = Pose(r2, q2);
          const int column = 7 * side + k;
          for (const bool phi : {false, true}) {
            const double numeric = (value(plus, phi) - value(minus, phi)) / (2 * h);
            const double exact = phi ? c.phi_gradient(column) : c.gradient(column);
            // A kink (a change of the closest features) within h: skip, rarely.
            const double error = std::abs(numeric - exact) / (1.0 + std::abs(exact));
            worst = std::max(worst, error);
            EXPECT_LE(error, 1e-5) << "trial " << trial << " column " << column << " phi " << phi;
          }
        }
      }
      ++checked;
    }
  }
  std::cout << "[scene] " << checked << " contacts, worst gradient error " << worst << "\n";
  EXPECT_GT(checked, 100);
}

TEST(Scene, PhiIsTheProximitysPhi) {
  Rng rng(34);
  int compared = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const RandomScene s = random_scene(rng, 12, 0.6);
    for (const Contact& c : s.scene.contacts(s.poses, 0.5)) {
      const BodyShape& a =
          s.scene.body(c.bodies[0]).shapes()[static_cast<std::size_t>(c.shapes[0])];
      const BodyShape& b =
          s.scene.body(c.bodies[1]).shapes()[static_cast<std::size_t>(c.shapes[1])];
      const Proximity p =
          proximity(a.shape, compose(s.poses[static_cast<std::size_t>(c.bodies[0])], a.pose),
                    b.shape, compose(s.poses[static_cast<std::size_t>(c.bodies[1])], b.pose));
      EXPECT_NEAR(c.phi, p.phi, 1e-12);
      ++compared;
    }
  }
  EXPECT_GT(compared, 100);
}

TEST(Scene, ExclusionsAndFiltersAreHonoured) {
  const Capsule stick(1.0, 0.1);
  const auto body = [&](const std::string& name, CollisionFilter filter = {}) {
    return Body(name, {{stick, Pose()}}, filter);
  };
  // Four sticks on top of each other: every pair overlaps.
  const std::vector<Pose> stacked(4, Pose());
  const Scene all({body("a"), body("b"), body("c"), body("d")});
  EXPECT_EQ(all.contacts(stacked).size(), 6u);
  const Scene excluded({body("a"), body("b"), body("c"), body("d")}, {{"c", "a"}, {"b", "d"}});
  std::vector<std::array<int, 2>> pairs;
  for (const Contact& c : excluded.contacts(stacked)) pairs.push_back(c.bodies);
  EXPECT_EQ(pairs, (std::vector<std::array<int, 2>>{{0, 1}, {0, 3}, {1, 2}, {2, 3}}));
  EXPECT_FALSE(excluded.checked(2, 0));
  EXPECT_TRUE(excluded.checked(0, 1));
  // Category 2 bodies ignore each other; the rest see them.
  const Scene filtered({body("a"), body("b", {2, ~2u}), body("c", {2, ~2u}), body("d")});
  pairs.clear();
  for (const Contact& c : filtered.contacts(stacked)) pairs.push_back(c.bodies);
  EXPECT_EQ(pairs, (std::vector<std::array<int, 2>>{{0, 1}, {0, 2}, {0, 3}, {1, 3}, {2, 3}}));
  // Shapes of one body never touch each other.
  const Scene one({Body("pile", {{stick, Pose()}, {stick, Pose()}, {square(0.5, 0.1), Pose()}})});
  EXPECT_TRUE(one.contacts({Pose()}).empty());
}

TEST(Scene, EmptyScenesAndEmptyBodies) {
  EXPECT_TRUE(Scene().contacts({}).empty());
  EXPECT_TRUE(Scene({}, {}).contacts({}, 1.0).empty());
  const Scene with_empty({Body("frame", {}), Body("stick", {{Capsule(1, 0.1), Pose()}})});
  EXPECT_TRUE(with_empty.contacts({Pose(), Pose()}, 1.0).empty());
  EXPECT_EQ(with_empty.index_of("stick"), 1);
  EXPECT_EQ(with_empty.index_of("nobody"), -1);
}

// A scene moved from is the empty scene, usable (it once kept no outlines and crashed), and the
// scene moved to answers as the original.
TEST(Scene, AMovedFromSceneIsTheEmptyScene) {
  const std::vector<Body> bodies = {Body("a", {{Capsule(1, 0.1), Pose()}}),
                                    Body("b", {{Capsule(1, 0.1), Pose()}})};
  const std::vector<Pose> poses = {Pose(),
                                   Pose(Eigen::Vector3d(0, 0.15, 0), Eigen::Vector4d(1, 0, 0, 0))};
  // NOLINTBEGIN(clang-analyzer-cplusplus.Move): the moved-from scenes' state is the subject.
  Scene source(bodies);
  const Scene moved(std::move(source));
  EXPECT_EQ(source.size(), 0);  // NOLINT(bugprone-use-after-move): the state is the subject
  EXPECT_TRUE(source.contacts({}, 1.0).empty());
  EXPECT_EQ(source.index_of("a"), -1);
  ASSERT_EQ(moved.contacts(poses, 0.0).size(), 1u);
  Scene assigned(bodies);
  Scene target;
  target = std::move(assigned);
  EXPECT_EQ(assigned.size(), 0);  // NOLINT(bugprone-use-after-move)
  EXPECT_TRUE(assigned.contacts({}, 1.0).empty());
  // NOLINTEND(clang-analyzer-cplusplus.Move)
  EXPECT_NEAR(target.contacts(poses, 0.0).at(0).distance, -0.05, 1e-15);
  const Scene copy = target;  // copies share the outlines and both answer
  EXPECT_EQ(copy.contacts(poses, 0.0).size(), 1u);
  EXPECT_EQ(target.contacts(poses, 0.0).size(), 1u);
}

// Memory grows with the contacts a query finds, not with the pairs its broadphase finds: 3,000
// parallel sticks along a diagonal, 0.003 apart, have every pair's boxes overlapping (4.5 million
// pairs) and no contact at margin 0. With a contact reserved per pair (336 bytes each, 1.5 GB)
// the query threw std::bad_alloc under this limit (a hostile review); it needs ~40 MB for its
// pairs. Run in a child process whose address space may grow by 600 MB.
TEST(Scene, ContactsTakeMemoryForContactsNotForPairs) {
  if (kSanitized) GTEST_SKIP() << "address-space limit under a sanitizer";
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  constexpr int kSticks = 3000;
  std::vector<Body> bodies;
  std::vector<Pose> poses;
  const Eigen::Vector4d diagonal(std::cos(-M_PI / 8), 0, std::sin(-M_PI / 8), 0);  // x to (1,0,1)
  for (int i = 0; i < kSticks; ++i) {
    bodies.emplace_back("stick" + std::to_string(i),
                        std::vector<BodyShape>{{Capsule(10.0, 0.001), Pose()}});
    const double across = 0.003 * i * std::sqrt(0.5);  // along (1, 0, -1) / sqrt(2)
    poses.emplace_back(Eigen::Vector3d(across, 0.0, -across), diagonal);
  }
  const Scene scene(std::move(bodies));
  EXPECT_EXIT(
      {
        limit_address_space(600 << 20);
        std::exit(scene.contacts(poses, 0.0).empty() ? 0 : 1);
      },
      ::testing::ExitedWithCode(0), "");
}

TEST(Scene, ErrorsNameTheField) {
  const auto message = [](const auto& make) {
    try {
      make();
    } catch (const std::invalid_argument& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  const Body a("a", {{Capsule(1, 0.1), Pose()}});
  EXPECT_EQ(message([] { Body("", {}); }), "body.name: must not be empty");
  EXPECT_EQ(message([&] {
              Scene({a, Body("b", {}), a});
            }),
            "bodies[2].name: 'a' is also the name of bodies[0]");
  EXPECT_EQ(message([&] { Scene({a}, {{"a", "x"}}); }), "exclude[0]: no body is named 'x'");
  EXPECT_EQ(message([&] { Scene({a}, {{"a", "a"}}); }), "exclude[0]: names body 'a' twice");
  const Scene scene(
      {a, Body("b", {{Capsule(1, 0.1), Pose(Eigen::Vector3d(1e100, 0, 0), kIdentity)}})});
  EXPECT_EQ(message([&] { scene.contacts({Pose()}); }),
            "body_poses: expected one pose per body, 2, got 1");
  EXPECT_EQ(message([&] {
              scene.contacts({Pose(), Pose()}, std::nan(""));
            }),
            "margin: must be finite, of magnitude at most 1e100");
  const std::string far = message([&] {
    scene.contacts({Pose(), Pose(Eigen::Vector3d(1e100, 0, 0), kIdentity)});
  });
  EXPECT_EQ(far,
            "body_poses[1] (body 'b'), shape 0: its world position is beyond 1e100 in magnitude");
  // A NUL in a name is written \u0000: read back through what(), a C string, the message ended
  // there ("... no body is named 'x").
  const std::string nul_name("x\0y", 3);
  EXPECT_EQ(message([&] {
              Scene({a}, {{"a", nul_name}});
            }),
            "exclude[0]: no body is named 'x\\u0000y'");
  const Body named_nul(nul_name,
                       {{Capsule(1, 0.1), Pose(Eigen::Vector3d(1e100, 0, 0), kIdentity)}});
  EXPECT_EQ(message([&] {
              Scene({named_nul, named_nul});
            }),
            "bodies[1].name: 'x\\u0000y' is also the name of bodies[0]");
  EXPECT_EQ(
      message([&] {
        Scene({a, named_nul}).contacts({Pose(), Pose(Eigen::Vector3d(1e100, 0, 0), kIdentity)});
      }),
      "body_poses[1] (body 'x\\u0000y'), shape 0: its world position is beyond 1e100 in "
      "magnitude");
}

}  // namespace
}  // namespace diffpills::testing
