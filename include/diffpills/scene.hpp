// Bodies made of many primitives, and scenes of many bodies (DESIGN.md section 3c).
//
// A Body is a rigid set of primitives (capsules, padded polygons), each posed in the body's own
// frame. A Scene is an immutable list of named bodies with the body pairs never to be checked
// against each other: pairs excluded by name (adjacent links of an arm) and pairs whose collision
// filters do not match (Box2D's categories and masks). Given one pose per body, Scene::contacts
// returns every pair of primitives of two different bodies that are checked against each other
// and whose signed distance (signed_distance.hpp) is at most a margin, with the signed distance,
// phi, the witness points, the normal, and the gradients of both with respect to the two BODY
// poses.
//
// Chain rule. A primitive with local pose (r_l, q_l) on a body at (r, q) is at
//
//     r_p = r + Q(q) r_l,      q_p = q (x) q_l      (Q(q_p) = Q(q) Q(q_l))
//
// so for the primitive pair's gradient g = [g_r, g_q] of one side,
//
//     d/dr = g_r,      d/dq = (d r_p / dq)' g_r + R(q_l)' g_q,
//
// with R(q_l) the right-multiplication matrix (q (x) q_l = R(q_l) q) and d r_p / dq the derivative
// of Q(q / |q|) r_l (rotation.hpp), normalization included: neither q nor q_l need be unit.
//
// phi. Where the cores are apart, phi = |p1 - p2|^2 - (R1 + R2)^2 = distance (distance + 2 (R1 +
// R2)) and d phi = 2 (distance + R1 + R2) d distance; where they intersect, phi = -(R1 + R2)^2
// with a zero gradient: proximity()'s value, derived from the signed distance instead of a second
// query.
//
// Broadphase. Each query bounds every primitive by its world box (the padded core's, grown by half
// the margin when it is positive: two padded shapes within the margin have boxes that overlap so).
// Up to 128 primitives it tests every pair of boxes; above, it builds bounding-volume hierarchies
// over the boxes (linear BVHs: Morton codes of the centres, radix-sorted, split as an octree), one
// per body and one over the bodies' bounds, and walks them for the overlapping pairs of bodies
// checked against each other: about O(n log n) for n primitives at a fixed density, plus the pairs
// found; the primitives of one body, or of two bodies never checked against each other, are never
// walked against each other. Only the pairs found get the narrowphase. (bench_scene: at 10^4
// bodies about as fast as FCL's DynamicAABBTreeCollisionManager refitting and walking its tree on
// the same scene, which reports five times the pairs, BENCHMARKS.md.)
//
// Order. Contacts are sorted by the first body's index, then the second's (bodies[0] < bodies[1],
// the order of the scene), then the shape indices; each pair is computed with the earlier body's
// shape first, so the answer does not depend on the order the broadphase finds pairs in.
//
// Thread safety. A Scene is immutable once built; contacts() is a pure function of the scene, the
// poses and the margin, and may be called from any number of threads at once.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "diffpills/shapes.hpp"

namespace diffpills {

namespace detail {
struct SceneOutlines;  // the primitives as the broadphase reads them (src/scene/scene_outlines.hpp)
}  // namespace detail

// What Scene::contacts throws when a body's pose puts one of its primitives' origins beyond
// kMaxMagnitude: what() reads "body_poses[3] (body 'arm'), shape 1: <reason>"; body(), shape() and
// reason() let a caller that names the poses otherwise (a command's "poses.arm", Python's r[3] and
// q[3]) say it in its own terms.
class BodyPoseError : public std::invalid_argument {
 public:
  BodyPoseError(int body, const std::string& body_name, int shape, std::string reason);
  int body() const { return body_; }
  int shape() const { return shape_; }
  const std::string& reason() const { return reason_; }

 private:
  int body_, shape_;
  std::string reason_;
};

// A primitive of a body and its pose in the body's frame.
struct BodyShape {
  Shape shape;
  Pose pose;
};

// Box2D's collision filtering: two bodies are checked against each other only if each one's
// category shares a bit with the other's mask. The defaults check every pair.
struct CollisionFilter {
  std::uint32_t category = 1;
  std::uint32_t mask = 0xFFFFFFFFu;
};

class Body {
 public:
  // Throws std::invalid_argument for an empty name. A body may have no shapes (it then touches
  // nothing).
  Body(std::string name, std::vector<BodyShape> shapes, CollisionFilter filter = {});

  const std::string& name() const { return name_; }
  const std::vector<BodyShape>& shapes() const { return shapes_; }
  const CollisionFilter& filter() const { return filter_; }

 private:
  std::string name_;
  std::vector<BodyShape> shapes_;
  CollisionFilter filter_;
};

// One pair of primitives within the margin. Gradients are with respect to the two bodies' poses,
// [dr (3), dq (4)] of bodies[0], then of bodies[1] (the layout of signed_distance's gradient).
struct Contact {
  std::array<int, 2> bodies = {0, 0};     // scene indices, bodies[0] < bodies[1]
  std::array<int, 2> shapes = {0, 0};     // each body's shape index
  double distance = 0.0;                  // signed distance (signed_distance.hpp)
  double phi = 0.0;                       // |p1 - p2|^2 - (R1 + R2)^2 of the cores (proximity.hpp)
  std::array<Eigen::Vector3d, 2> points;  // witness points on the two surfaces, world frame
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, from bodies[0]'s shape to the other
  Eigen::Matrix<double, 14, 1> gradient = Eigen::Matrix<double, 14, 1>::Zero();  // of distance
  Eigen::Matrix<double, 14, 1> phi_gradient = Eigen::Matrix<double, 14, 1>::Zero();
};

class Scene {
 public:
  // An empty scene.
  Scene();
  // Throws std::invalid_argument for two bodies of one name ("bodies[3].name: 'arm' is also the
  // name of bodies[1]"), or an excluded pair naming an unknown body or one body twice
  // ("exclude[0]: ...").
  explicit Scene(std::vector<Body> bodies,
                 const std::vector<std::pair<std::string, std::string>>& exclude = {});
  // Copies share the immutable broadphase outlines. A scene moved from is the empty scene (not a
  // scene left without them).
  Scene(const Scene&) = default;
  Scene& operator=(const Scene&) = default;
  Scene(Scene&& other) noexcept;
  Scene& operator=(Scene&& other) noexcept;
  ~Scene() = default;

  int size() const { return static_cast<int>(bodies_.size()); }
  const std::vector<Body>& bodies() const { return bodies_; }
  const Body& body(int index) const { return bodies_[static_cast<std::size_t>(index)]; }
  // The index of the body of that name, or -1.
  int index_of(const std::string& name) const;
  // Are bodies i and j (i != j) checked against each other: not excluded, filters matching?
  bool checked(int i, int j) const;
  // The excluded pairs as scene indices (i < j), sorted.
  const std::vector<std::pair<int, int>>& excluded() const { return excluded_; }

  // Every primitive pair of two checked bodies whose signed distance is <= margin, sorted (see
  // above). body_poses holds one pose per body, in the scene's order. Throws
  // std::invalid_argument for a count that is not the scene's ("body_poses: ..."), a margin that
  // is not finite or beyond kMaxMagnitude ("margin: ..."), and throws BodyPoseError (an
  // std::invalid_argument) for a primitive whose world position is beyond kMaxMagnitude
  // ("body_poses[3] (body 'arm'), shape 1: ...").
  std::vector<Contact> contacts(const std::vector<Pose>& body_poses, double margin = 0.0) const;

 private:
  std::vector<Body> bodies_;
  std::vector<std::pair<int, int>> excluded_;
  std::vector<std::pair<std::string, int>> names_;  // sorted by name, for index_of
  std::shared_ptr<const detail::SceneOutlines>
      outlines_;  // immutable, shared by copies, never null
};

// The world pose of a primitive fixed at `local` on a body at `body` ("Chain rule" above):
// r + Q(q) r_l with the unit attitude q^ (x) q_l / |q_l| (q^ = q / |q|; the unit quaternion is
// always a valid Pose, where q (x) q_l could leave Pose's range). Scene::contacts poses every
// primitive so, bit for bit: a caller that queries a contact's pair again (for
// signed_distance_hessian, for a drawing) gets the contact's own geometry. Throws
// std::invalid_argument (Pose's message) if the position is beyond 1e100 in magnitude.
Pose world_pose(const Pose& body, const Pose& local);

}  // namespace diffpills
