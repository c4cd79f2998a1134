// The exact fast solvers of Method::kDefault, one per pair type. Each returns the two sides of
// the solution for the result builder (pair_result.hpp); none allocates for polygons of up to 32
// vertices. Where the closest points are not unique each returns the middle of the optimal set:
// the midpoint of an interval, the area centroid of a planar region.
#pragma once

#include <array>

#include "core_solution.hpp"
#include "diffpills/shapes.hpp"

namespace diffpills::detail {

// Paper section III in closed form (segment_segment.hpp).
std::array<CoreSolution, 2> solve_capsule_capsule(const Capsule& a, const PosedCore& posed_a,
                                                  const Capsule& b, const PosedCore& posed_b);

// Paper section IV-C by feature enumeration in the polygon's body frame.
std::array<CoreSolution, 2> solve_capsule_polygon(const Capsule& capsule,
                                                  const PosedCore& posed_capsule,
                                                  const PaddedPolygon& polygon,
                                                  const PosedCore& posed_polygon);

// Paper section IV by feature enumeration in the first polygon's body frame.
std::array<CoreSolution, 2> solve_polygon_polygon(const PaddedPolygon& a, const PosedCore& posed_a,
                                                  const PaddedPolygon& b, const PosedCore& posed_b);

}  // namespace diffpills::detail
