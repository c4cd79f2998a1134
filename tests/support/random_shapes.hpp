// Seeded random shapes and poses for the tests, each shape with its core's body-frame vertices
// computed here (not by the library) so that the brute-force reference stays independent.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "diffpills/shapes.hpp"
#include "reference.hpp"

namespace diffpills::testing {

using Rng = std::mt19937_64;

struct TestShape {
  Shape shape;
  std::vector<Eigen::Vector3d> body_vertices;  // 1 (sphere), 2 (segment) or >= 3 (polygon, CCW)
  double size = 0.0;                           // characteristic length
};

// A capsule of length in [0.2, 2] * scale (0 with probability sphere_probability) and radius in
// [0, 0.3] * scale.
TestShape random_capsule(Rng& rng, double scale, double sphere_probability = 0.0);

// A convex polygon: 3 to 8 vertices at sorted random angles on a circle of radius in
// [0.3, 1] * scale, stretched by a random linear map and shifted so that a random interior point
// is the body origin; C and d are the edges' outward normals and offsets, with an occasional
// redundant row (a duplicate or a loose copy) added. Radius in [0, 0.3] * scale.
TestShape random_polygon(Rng& rng, double scale);

// Uniform position in [-spread, spread]^3 and a random quaternion of norm in [0.5, 2].
Pose random_pose(Rng& rng, double spread);

// The pose after a rigid motion of the whole scene: turned by `turn` about the world origin, then
// shifted (the attitude turn * q, q's norm kept).
Pose rigidly_moved(const Pose& pose, const Eigen::Quaterniond& turn, const Eigen::Vector3d& shift);

// The core in world coordinates, through Eigen's own quaternion rotation in long double.
WorldCore to_world(const TestShape& shape, const Pose& pose);

}  // namespace diffpills::testing
