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

// The distance of a world point from a core (the point as a core of one vertex).
long double distance_to_core(const Eigen::Vector3d& point, const WorldCore& core);

// The signed distance of the cores, s = dist(0, D) when the cores are apart and minus the distance
// from 0 to D's boundary when they intersect, with D = conv{va - vb} the cores' Minkowski
// difference. Apart: brute_force_closest. Intersecting: every plane through three points of D's
// vertex set {va - vb} that has all of them on one side is a facet plane of D; the depth is the
// smallest distance of such a plane from 0 (0 when D is flat or a segment). O(n^4) in the n = na nb
// vertex differences: for small cores only. `scale` is the scene's length scale (tolerances).
struct SignedCoreDistance {
  long double s = 0;
  Vec3L normal = Vec3L::Zero();  // from core a to core b (zero where D has no facet)
};
SignedCoreDistance brute_force_signed_distance(const WorldCore& a, const WorldCore& b,
                                               long double scale);

// The penetration depth of intersecting cores by separating axes, for cores of many vertices where
// the hull above is too slow: the smallest h_a(n) + h_b(-n) (support functions, max over the
// vertices) over the candidate axes +-n: each polygon's normal and every cross product of an edge
// of a with an edge of b (a segment is one edge). For any axis h_a(n) + h_b(-n) >= depth, and the
// normals of D's facets are among the candidates, so the smallest is the depth, with no facet
// tests. O(ea eb (na + nb)). Only meaningful when the cores intersect; 0 when D is flat.
long double brute_force_penetration_depth(const WorldCore& a, const WorldCore& b);

}  // namespace diffpills::testing
