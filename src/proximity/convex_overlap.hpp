// The common region of two convex polygons of one plane, and its centre: what two parallel
// polygons whose shadows overlap have as their set of closest points.
#pragma once

#include <Eigen/Core>

namespace diffpills::detail {

struct HalfPlane {
  Eigen::Vector2d normal;  // unit, outward: normal . y <= offset
  double offset = 0.0;
};

// The half-planes of a polygon of up to 32 vertices, its rows and at most 3 spike bevels
// (polygon_features.hpp): what a caller's buffers hold on the stack.
constexpr Eigen::Index kInlineHalfPlanes = 32 + 3;

// The centre of {y : normal . y <= offset + slack for every half-plane of both lists}, where each
// list bounds a convex polygon: its area centroid, or, for a region thinner than a few `slack`
// (polygons that only touch along an edge), the middle of its longest extent; the point itself
// where the polygons touch at one. Returns false if the region is empty. O(n log n) in the total
// number n of half-planes; allocates nothing for up to kInlineHalfPlanes per list (a hostile
// review counted 4 allocations for two 31-gons, 34 half-planes each, when the bound was 34 in all
// less the box's 4). first_extent bounds the distance of the first polygon's vertices from the
// origin.
bool overlap_centre(const HalfPlane* first, Eigen::Index first_count, double first_extent,
                    const HalfPlane* second, Eigen::Index second_count, double slack,
                    Eigen::Vector2d& centre);

}  // namespace diffpills::detail
