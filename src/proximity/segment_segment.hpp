// Closest points of two segments in closed form: the capsule-capsule fast path, and every
// edge-edge candidate of the pairs with a polygon.
#pragma once

#include <Eigen/Core>

namespace diffpills::detail {

struct SegmentParameters {
  double s = 0.5;  // P(s) = p + s u
  double t = 0.5;  // Q(t) = q + t v
};

// argmin over s, t in [0, 1] of |P(s) - Q(t)|^2 (paper eq. capsule_opt). A zero-length segment
// takes the parameter 1/2. Parallel segments (|sin| of the angle <= 1e-12) take the middle of the
// optimal set: the middle of the overlap of their projections when they overlap, the facing end
// points otherwise.
SegmentParameters closest_segment_parameters(const Eigen::Vector3d& p, const Eigen::Vector3d& u,
                                             const Eigen::Vector3d& q, const Eigen::Vector3d& v);

}  // namespace diffpills::detail
