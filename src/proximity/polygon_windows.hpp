// Separated polygons with many vertices: the feature enumeration restricted to windows of their
// vertices, grown until a separating-plane certificate proves the answer, in time about linear in
// the vertex counts (the full enumeration of separated_polygons.hpp is O(ka kb)).
#pragma once

#include <array>

#include "separated_polygons.hpp"

namespace diffpills::detail {

// The same answer as closest_separated(a, b, W, X, tolerance), for polygons that do not
// intersect. W: B carried into A's frame.
std::array<ClosestFeature, 2> closest_separated_by_windows(const PolygonView& a,
                                                           const PolygonView& b,
                                                           const PolygonPairFrame& frame,
                                                           const CarriedPolygon<PolygonView>& W,
                                                           double tolerance, double tie_tolerance);

}  // namespace diffpills::detail
