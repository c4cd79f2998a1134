// Closest points of two segments in closed form: the capsule-capsule fast path, and every
// edge-edge candidate of the pairs with a polygon.
#pragma once

#include <Eigen/Core>

namespace diffpills::detail {

// The segment from `start` to start + length * direction, with |direction| = 1 (up to rounding)
// and length >= 0. Passing the unit direction and the length apart, rather than their product,
// keeps every quantity of the solver of degree at most two in lengths.
struct Segment {
  Eigen::Vector3d start;
  Eigen::Vector3d direction;
  double length = 0.0;
};

struct SegmentParameters {
  double s = 0.5;  // P(s) = P.start + s P.length P.direction, s in [0, 1]
  double t = 0.5;  // Q(t), the same for the second segment
  // The segments are parallel and overlap along an interval of positive length, of which (s, t)
  // is the middle: the closest points are not unique.
  bool overlap = false;
  double half_overlap = 0.0;  // half the overlap's length, as a fraction of P's length

};

// argmin over s, t in [0, 1] of |P(s) - Q(t)|^2 (paper eq. capsule_opt). A zero-length segment
// takes the parameter 1/2. Parallel segments (|sin| of the angle <= 1e-12) take the middle of the
// optimal set: the middle of the overlap of their projections when they overlap, the facing end
// points otherwise.
SegmentParameters closest_segment_parameters(const Segment& P, const Segment& Q);

}  // namespace diffpills::detail
