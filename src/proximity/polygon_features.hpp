// Feature-level geometry of a reduced polygon in its own body frame (the x-y plane), for the
// fast paths: edges, inside tests, clipping. Row j of edge_normals() bounds edge j, which runs
// counterclockwise from vertex j - 1 to vertex j (vertex i joins edges i and i + 1).
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "core_solution.hpp"
#include "diffpills/shapes.hpp"

namespace diffpills::detail {

// Start and end vertex of edge j.
Eigen::Vector2d edge_start(const PaddedPolygon& polygon, Eigen::Index j);
Eigen::Vector2d edge_end(const PaddedPolygon& polygon, Eigen::Index j);

// Is y in the closed polygon? Exact comparisons: the fast paths need no tolerance here, because
// a point on the boundary is also found by the edge candidates.
bool contains(const PaddedPolygon& polygon, const Eigen::Vector2d& y);

// The parameter interval {s in [0, 1] : y0 + s w in the polygon} (Cyrus-Beck clipping); empty
// when the returned low > high.
std::array<double, 2> clip_line(const PaddedPolygon& polygon, const Eigen::Vector2d& y0,
                                const Eigen::Vector2d& w);

// The centre of the convex region polygon /\ {other's vertices}: the area centroid when the
// region has area, else the mean of its vertices (a segment or a point where the outlines only
// touch). `other` lists a convex polygon's vertices counterclockwise. Returns false if the two
// do not overlap.
bool overlap_centre(const PaddedPolygon& polygon, const std::vector<Eigen::Vector2d>& other,
                    Eigen::Vector2d& centre);

// The side of a polygon whose closest point is y: a face point (free in the body x-y plane), a
// point of edge j (free along it) or vertex j (fixed).
CoreSolution face_point(const Eigen::Vector2d& y);
CoreSolution edge_point(const PaddedPolygon& polygon, Eigen::Index j, double t);

// The side of a capsule of `length` at parameter s (u = [(s - 1/2) L, 0, 0]): free along its
// axis strictly inside, fixed at an end or for a sphere.
CoreSolution segment_point(double length, double s);

}  // namespace diffpills::detail
