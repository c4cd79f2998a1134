#include "fast_paths.hpp"
#include "segment_segment.hpp"

namespace diffpills::detail {

// Each core is the segment from b_i = r_i - Q_i [L_i/2, 0, 0] (theta = 0) along the body x axis
// Q_i e_x (the paper's EndPoints, with p_i = b_i + theta_i L_i Q_i e_x).
std::array<ClosestFeature, 2> solve_capsule_capsule(const PosedCore& a, const PosedCore& b) {
  const Eigen::Vector3d axis_a = a.attitude.matrix().col(0);
  const Eigen::Vector3d axis_b = b.attitude.matrix().col(0);
  const SegmentParameters closest =
      closest_segment_parameters({a.r, axis_a, a.size}, {b.r, axis_b, b.size});
  return {segment_point_at(a.size, closest.s_offset), segment_point_at(b.size, closest.t_offset)};
}

}  // namespace diffpills::detail
