// The broadphase of a scene query (scene.hpp): which of n axis-aligned boxes overlap.
//
// A bounding-volume hierarchy is built over the boxes for each query (a linear BVH): the boxes'
// centres get Morton codes in their bounding box (10 bits per axis, interleaved), are sorted by
// them (radix sort, O(n)), and each range of codes is split where its first and last codes first
// differ: the nodes are the cells of an octree over the centres, down to leaves of at most 4 boxes
// (a range of equal codes is split in the middle). Bounds come from below, O(n). The tree is then
// walked against itself: a node's pairs are its two children's own pairs plus the pairs across
// them, and two nodes whose boxes do not overlap hold no pair across; at a fixed density of boxes
// that visits about O(n log n) node pairs, plus the pairs found. A box far larger than the rest (a
// table under many small parts) costs only the pairs it overlaps. Nothing is kept between
// queries: the tree is a function of the boxes.
#pragma once

#include <Eigen/Core>
#include <utility>
#include <vector>

namespace diffpills::detail {

struct Box {
  Eigen::Vector3d low, high;  // low <= high
};

// The smallest box holding both.
Box merged(const Box& a, const Box& b);

// Do the closed boxes share a point? (Written out: the broadphase's innermost test.)
inline bool overlap(const Box& a, const Box& b) {
  return a.low.x() <= b.high.x() && b.low.x() <= a.high.x() && a.low.y() <= b.high.y() &&
         b.low.y() <= a.high.y() && a.low.z() <= b.high.z() && b.low.z() <= a.high.z();
}

// Every pair (i, j), i < j, of overlapping boxes, in no particular order.
std::vector<std::pair<int, int>> overlapping_pairs(const std::vector<Box>& boxes);

}  // namespace diffpills::detail
