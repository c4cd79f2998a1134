// Bounds on the distances between the segments of two sets, several pairs per instruction
// (issue 13): what lets the small polygons' edge enumeration (separated_polygons.cpp) hand only
// the edge pairs near the closest one to the exact segment solver.
//
// For a pair whose directions are more than ~0.6 degrees apart (sin^2 > 1e-4) the pair's points
// by segment_segment.cpp's first regime (Ericson's clamping: the infinite lines' closest point on
// the first segment, clamped, the second's from it, and the first again from the second where
// that one clamps) are the exact minimizer up to rounding, a few eps S / |sin| in lengths (S the
// pair's size), so their distance d exceeds the pair's true distance by at most a few of those
// (the distance grows at most at rate 1 along each segment), below 1e-13 S for |sin| >= 1e-2:
// the true distance is at least d - margin for any margin above that. Nearer parallel (and for
// the zero-length padding) the bound is the boxes' around the spheres around the segments: the
// true distance is at least max_k |m1_k - m2_k| - h1 - h2 (m the middles, h the half lengths),
// less the margin. No square root is taken: both bounds are given squared, before the margin.
// Computed in the widest vectors the CPU runs (Google Highway with run-time dispatch, as the
// capsule batches' kernel); fixed-width vectors only (not Highway's SVE or RVV targets).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "segment_segment.hpp"

namespace diffpills::detail {

// Segments as columns (middles, unit directions, half lengths), padded with zero-length segments
// at the origin to a whole number of the widest vectors (8 doubles). On the stack up to 32
// segments (not zeroed first: every entry is set), on the heap beyond.
class SegmentColumns {
 public:
  explicit SegmentColumns(Eigen::Index count)
      : count_(count), padded_((count + 7) / 8 * 8), data_(inline_) {
    if (padded_ > kInline) {
      heap_.resize(static_cast<std::size_t>(7 * padded_));
      data_ = heap_.data();
    }
    for (int r = 0; r < 7; ++r) {
      for (Eigen::Index j = count_; j < padded_; ++j) data_[r * padded_ + j] = 0.0;
    }
  }
  SegmentColumns(const SegmentColumns&) = delete;
  SegmentColumns& operator=(const SegmentColumns&) = delete;
  void set(Eigen::Index j, const Segment& segment) {
    for (int i = 0; i < 3; ++i) {
      data_[i * padded_ + j] = segment.middle(i);
      data_[(3 + i) * padded_ + j] = segment.direction(i);
    }
    data_[6 * padded_ + j] = 0.5 * segment.length;
  }
  Eigen::Index size() const { return count_; }
  Eigen::Index padded_size() const { return padded_; }
  // Row r of the columns: 0-2 the middle, 3-5 the direction, 6 the half length.
  const double* row(int r) const { return data_ + r * padded_; }

 private:
  static constexpr Eigen::Index kInline = 32;
  Eigen::Index count_, padded_;
  double inline_[7 * kInline];
  std::vector<double> heap_;
  double* data_;
};

// For every segment i of `first` and j of `second`, in row i of `lower` (second.padded_size()
// entries a row, the padding's written too): a value L with
//   true distance >= sqrt(L) - margin
// (d^2 or the boxes' bound squared, above). Returns the least d^2 over the pairs, the squared
// distance of two points of the segments, so that the closest pair is at most its square root
// plus the rounding; infinity if no pair has one (every pair exactly parallel: 0 / 0).
double segment_distance_bounds(const SegmentColumns& first, const SegmentColumns& second,
                               double* lower);

// True where segment_distance_bounds runs in vectors of 4 doubles or more (AVX2, AVX-512): where
// it is faster than the scalar bounds it replaces (separated_polygons.cpp).
bool segment_bounds_vectorized();

// The instruction set segment_distance_bounds runs on in this process (Highway's name), for tests.
const char* segment_bounds_target();

}  // namespace diffpills::detail
