// The broadphase of a scene query (scene.hpp): which of n axis-aligned boxes overlap, among the
// pairs a filter allows.
//
// Up to 128 boxes (a robot and its surroundings), every pair is tested directly: cheaper than
// building and walking the trees at that size. Above, bounding-volume hierarchies are built for
// each query (linear BVHs): centres get Morton codes in their bounding box (10 bits per axis,
// interleaved), are sorted by them (radix sort, O(n)), and each range of codes is split where its
// first and last codes first differ: the nodes are the cells of an octree over the centres, down
// to leaves of at most 2 boxes. A range whose codes are all equal but whose centres are not (a
// cluster far smaller than the whole, beside one far-away box) gets new codes in its own bounds
// and is sorted again, so a cluster is split as finely as the rest. Nothing is kept between
// queries: the trees are a function of the boxes.
//
// Two levels, as the filters are per group (a body): one tree per group over its boxes, and one
// tree over the groups' bounds, walked against itself. A node pair of that tree is skipped when
// its boxes do not overlap, when the unions of its groups' categories and masks do not meet, or
// when both are one group each and groups_checked refuses them; only for two groups that may pair
// and whose bounds overlap are their trees walked against each other. At a fixed density that
// visits about O(n log n) node pairs plus the pairs found; a box far larger than the rest (a
// table under many small parts) costs only the pairs it overlaps; the boxes of one group, or of
// two groups never checked against each other (an excluded pair of bodies, categories that never
// meet), cost nothing beyond their trees however much they overlap. What is not pruned: many
// groups at one place whose filters are all different and pair with none (each group's own filter
// is known only at the leaves).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
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

// Which pairs a box may be in: never with a box of its own group (a body's primitives); only with
// boxes whose category shares a bit with its mask and whose mask shares a bit with its category
// (Box2D's filter); and only if the caller's groups_checked(group_a, group_b) allows the groups.
struct BoxFilter {
  int group = 0;
  std::uint32_t category = 1;
  std::uint32_t mask = 0xFFFFFFFFu;
};

// Every pair (i, j), i < j, of overlapping boxes that the filters allow, in no particular order.
// filters has one entry per box; groups_checked is called with two different groups.
std::vector<std::pair<int, int>> overlapping_pairs(
    const std::vector<Box>& boxes, const std::vector<BoxFilter>& filters,
    const std::function<bool(int, int)>& groups_checked);

// Every pair of overlapping boxes (each box its own group, no filter).
std::vector<std::pair<int, int>> overlapping_pairs(const std::vector<Box>& boxes);

}  // namespace diffpills::detail
