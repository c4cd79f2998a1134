// The exact fast solvers of Method::kDefault, one per pair type, working in a query's frame
// (pair_frame.hpp). Each returns the two sides of the solution for the result builder
// (pair_result.hpp); none allocates for polygons of up to 32 vertices.
//
// Where the closest points are not unique each returns the middle of the optimal set: the
// midpoint of an interval, the area centroid of a planar region. The optimal set is found from
// the features that tie with the best one: candidates whose distances differ by at most the
// frame's tie tolerance (pair_frame.hpp: 2e-12 of the larger core's size plus 64 ulps of the
// scene's) count as equal, and a candidate that stands for a whole interval (parallel features)
// wins such a tie over one that stands for a point of it. The answer therefore does not depend on
// the order of the shapes or on the frame the features were enumerated in. `tolerance` is the
// frame's intersection tolerance, `tie_tolerance` its tie tolerance.
#pragma once

#include <array>

#include "polygon_features.hpp"
#include "posed_core.hpp"

namespace diffpills::detail {

// Paper section III in closed form (segment_segment.hpp). A capsule's size is its length.
std::array<ClosestFeature, 2> solve_capsule_capsule(const PosedCore& a, const PosedCore& b);

// Paper section IV-C by feature enumeration in the polygon's body frame.
std::array<ClosestFeature, 2> solve_capsule_polygon(const PosedCore& capsule,
                                                    const PolygonView& polygon,
                                                    const PosedCore& posed_polygon,
                                                    double tolerance, double tie_tolerance);

// Paper section IV by feature enumeration in the first polygon's body frame.
std::array<ClosestFeature, 2> solve_polygon_polygon(const PolygonView& a, const PosedCore& posed_a,
                                                    const PolygonView& b, const PosedCore& posed_b,
                                                    double tolerance, double tie_tolerance);

}  // namespace diffpills::detail
