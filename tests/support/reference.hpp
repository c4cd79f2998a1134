// A brute-force closest-point reference, written apart from the library's algorithm: it
// enumerates the features of the two cores (vertex-face, edge-edge, edge crossing a face) in
// world coordinates, in long double, and keeps the closest pair. It uses only world-frame vertex
// lists, never the library's QP, its rotation code or its polygon reduction.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace diffpills::testing {

using Vec3L = Eigen::Matrix<long double, 3, 1>;

// A core in world coordinates: one point (a sphere), two (a segment) or a convex planar polygon
// given by its vertices in order (three or more).
struct WorldCore {
  std::vector<Vec3L> vertices;
};

struct ClosestPair {
  long double distance = 0;
  Vec3L p1, p2;
};

ClosestPair brute_force_closest(const WorldCore& a, const WorldCore& b);

}  // namespace diffpills::testing
