#include "depth_box_tree.hpp"

#include <algorithm>

namespace diffpills::detail {

// Each frame's bound is the length of (gap in depth, gap across in e1, gap across in e2), each gap
// between the two chains' intervals (0 if they overlap). The length is taken scaled by its largest
// part: chains of specks far below the frame's units (cores below 1e-140 of their radii keep the
// frame of the radii, pair_frame.hpp) have gaps whose squares underflow to 0, and a bound of 0
// against a limit squared to 0 would have ruled every pair out.
double distance_bound(const ChainExtents& a, const ChainExtents& b) {
  double bound = 0.0;
  for (int f = 0; f < kDepthFrames; ++f) {
    Eigen::Vector3d gaps;
    for (int axis = 0; axis < 3; ++axis) {
      const ChainExtents::Interval& ia = a.coordinates[f][axis];
      const ChainExtents::Interval& ib = b.coordinates[f][axis];
      gaps(axis) = std::max({0.0, ib.low - ia.high, ia.low - ib.high});
    }
    const double largest = gaps.maxCoeff();
    if (largest > 0.0) bound = std::max(bound, largest * (gaps / largest).norm());
  }
  return bound;
}

}  // namespace diffpills::detail
