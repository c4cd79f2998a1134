#include "fast_paths.hpp"
#include "polygon_features.hpp"
#include "segment_segment.hpp"

namespace diffpills::detail {

// Each core is the segment from b_i = r_i - Q_i [L_i/2, 0, 0] (theta = 0) along
// d_i = Q_i [L_i, 0, 0] (the paper's EndPoints, with p_i = b_i + theta_i d_i).
std::array<CoreSolution, 2> solve_capsule_capsule(const Capsule& a, const PosedCore& posed_a,
                                                  const Capsule& b, const PosedCore& posed_b) {
  const Eigen::Vector3d axis_a = posed_a.attitude.matrix().col(0) * a.length();
  const Eigen::Vector3d axis_b = posed_b.attitude.matrix().col(0) * b.length();
  const SegmentParameters closest = closest_segment_parameters(posed_a.r - 0.5 * axis_a, axis_a,
                                                               posed_b.r - 0.5 * axis_b, axis_b);
  return {segment_point(a.length(), closest.s), segment_point(b.length(), closest.t)};
}

}  // namespace diffpills::detail
