// Closest points of two segments in closed form: the capsule-capsule fast path, and every
// edge-edge candidate of the pairs with a polygon.
#pragma once

#include <Eigen/Core>

namespace diffpills::detail {

// The segment of points middle + x direction, |x| <= length / 2, with |direction| = 1 (up to
// rounding) and length >= 0. Anchored at its middle, not at an end: a point near the middle of a
// long segment is then computed to the rounding of its own offset, not of half the length (a
// point 1 from the middle of a 1e20-long capsule). Passing the unit direction and the length
// apart, rather than their product, keeps every quantity of the solver of degree at most two in
// lengths.
struct Segment {
  Eigen::Vector3d middle;
  Eigen::Vector3d direction;
  double length = 0.0;
  // The point `offset` from the middle along the direction.
  Eigen::Vector3d at(double offset) const { return middle + offset * direction; }
};

struct SegmentParameters {
  double s = 0.5;  // P at s in [0, 1]: P.at((s - 1/2) P.length)
  double t = 0.5;  // Q at t, the same for the second segment
  // The same points as offsets from the middles, in length units: P.at(s_offset), Q.at(t_offset).
  // Exact where s and t round (s - 1/2 loses the digits of an offset far below the length).
  double s_offset = 0.0, t_offset = 0.0;
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
