// A bounding hierarchy over a polygon's edges for the closest pair of two large windows of
// polygons (separated_polygons.cpp), near or far apart: each node is a chain of consecutive edges
// with, in each of a few orthonormal frames, the interval of its depths along the frame's first
// axis u and the box of its points across u.
//
// The bound. Write a point's coordinates in a frame (u, e1, e2): depth z = u . p and the part
// across, w = (e1 . p, e2 . p). For points p, q of two chains,
//
//     |q - p|^2 = (z_q - z_p)^2 + |w_q - w_p|^2 >= gap_depth^2 + gap_across^2,
//
// gap_depth the distance between the two depth intervals (0 if they overlap) and gap_across the
// distance between the two boxes. This holds in every frame, and the largest over the frames is
// kept. It is tight when u is near the direction of the closest pairs and the chains are short: a
// chain of length s has a depth interval about s times its plane's slope to u, and a box's
// looseness changes a pair's distance by about s times the pair's offset across u over their
// distance. Far apart (distance V far above the polygons' size), every pair's distance is V plus
// small terms, a slope along u on each polygon and the offset across, offset^2 / (2 V); a bound by
// depth alone misses the last and a bound along one polygon's plane alone misses the first, and
// either left in every pair of two nearly facing, slightly tilted polygons (two unit
// 32,000-gons 3e6 apart, 2.5 to the side, tilted 1e-6 rad: 0.66 s by depth). With both, the pairs
// left in are those within the looseness of leaf chains of the best distance.
//
// Built lazily: a chain's extents are computed when the search first asks for them, from its
// vertices up to kDirectEdges edges and from its halves above, so that a search that stays near
// the closest pairs reads every vertex once (for the root) and the few chains it descends into,
// and stores only those. Built whole, the nodes of two 3,000-gons' windows took 2 ms per query in
// page faults and initialisation, 8 times what the search needed (1e7 apart, 1e-3 rad, 2.5 aside).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

namespace diffpills::detail {

// The frames the bound is taken in: each one's rows are u, e1 and e2, orthonormal.
constexpr int kDepthFrames = 2;
using DepthFrames = std::array<Eigen::Matrix3d, kDepthFrames>;

// A chain's points in each frame: the interval of each coordinate (depth along u, then across).
struct ChainExtents {
  struct Interval {
    double low, high;
  };
  Interval coordinates[kDepthFrames][3];
};

// The bound above for two chains: the largest over the frames.
double distance_bound(const ChainExtents& a, const ChainExtents& b);

// A polygon's chains of edges. Vertex: a callable giving vertex i (0 .. count - 1) in the frame
// the DepthFrames rotate from; edge j runs from vertex j - 1 to vertex j (edge 0 from the last
// vertex). The frames must outlive the tree.
template <class Vertex>
class DepthBoxTree {
 public:
  // Chains of at most this many edges are leaves, whose edge pairs the search visits one by one.
  static constexpr Eigen::Index kLeafEdges = 4;
  // Chains of at most this many edges have their extents computed from their vertices.
  static constexpr Eigen::Index kDirectEdges = 64;

  // The edges first .. end - 1; the root is node 0, and node n's halves are nodes 2n + 1, 2n + 2.
  struct Chain {
    std::size_t node;
    Eigen::Index first, end;
    bool is_leaf() const { return end - first <= kLeafEdges; }
    std::array<Chain, 2> halves() const {
      const Eigen::Index middle = first + (end - first) / 2;
      return {Chain{2 * node + 1, first, middle}, Chain{2 * node + 2, middle, end}};
    }
  };

  DepthBoxTree(Eigen::Index count, Vertex vertex, const DepthFrames& frames)
      : count_(count), vertex_(std::move(vertex)), frames_(&frames) {
    // Chains halve until they have at most kLeafEdges edges: levels + 1 levels of nodes.
    int levels = 0;
    while (((count - 1) >> levels) + 1 > kLeafEdges) ++levels;
    slots_.assign((std::size_t{2} << levels) - 1, -1);
  }

  Chain root() const { return {0, 0, count_}; }

  // The chain's extents, computed when first asked for. The reference is good until the next
  // call on this tree.
  const ChainExtents& extents(const Chain& chain) {
    int& slot = slots_[chain.node];
    if (slot >= 0) return computed_[static_cast<std::size_t>(slot)];
    ChainExtents out;
    if (chain.end - chain.first <= kDirectEdges) {
      for (auto& frame : out.coordinates) {
        for (auto& interval : frame) {
          interval = {std::numeric_limits<double>::infinity(),
                      -std::numeric_limits<double>::infinity()};
        }
      }
      // The chain's points are its edges' ends: vertices first - 1 .. end - 1.
      for (Eigen::Index i = chain.first - 1; i < chain.end; ++i) {
        const Eigen::Vector3d point = vertex_(i < 0 ? count_ - 1 : i);
        for (int f = 0; f < kDepthFrames; ++f) {
          const Eigen::Vector3d in_frame = (*frames_)[static_cast<std::size_t>(f)] * point;
          for (int axis = 0; axis < 3; ++axis) {
            ChainExtents::Interval& interval = out.coordinates[f][axis];
            interval.low = std::min(interval.low, in_frame(axis));
            interval.high = std::max(interval.high, in_frame(axis));
          }
        }
      }
    } else {
      const std::array<Chain, 2> halves = chain.halves();
      const ChainExtents left = extents(halves[0]);  // a copy: the next call may move it
      const ChainExtents& right = extents(halves[1]);
      for (int f = 0; f < kDepthFrames; ++f) {
        for (int axis = 0; axis < 3; ++axis) {
          out.coordinates[f][axis] = {
              std::min(left.coordinates[f][axis].low, right.coordinates[f][axis].low),
              std::max(left.coordinates[f][axis].high, right.coordinates[f][axis].high)};
        }
      }
    }
    slot = static_cast<int>(computed_.size());
    computed_.push_back(out);
    return computed_.back();
  }

 private:
  Eigen::Index count_;
  Vertex vertex_;
  const DepthFrames* frames_;
  std::vector<int> slots_;  // per node: its place in computed_, or -1
  std::vector<ChainExtents> computed_;
};

// Searches the two halves of a split in order of their bounds, the lower first, so that the
// limit falls early: search(half, its bound) for each.
template <class Chain, class BoundOf, class Search>
void search_nearer_half_first(const std::array<Chain, 2>& halves, const BoundOf& bound_of,
                              const Search& search) {
  const double first = bound_of(halves[0]), second = bound_of(halves[1]);
  if (second < first) {
    search(halves[1], second);
    search(halves[0], first);
  } else {
    search(halves[0], first);
    search(halves[1], second);
  }
}

// search_close_edge_pairs below, for two chains whose bound is known.
template <class TreeA, class TreeB, class Pairs>
void search_close_edge_pairs(TreeA& a, const typename TreeA::Chain& chain_a, TreeB& b,
                             const typename TreeB::Chain& chain_b, double bound, Pairs& pairs) {
  if (bound >= pairs.limit()) return;
  if (chain_a.is_leaf() && chain_b.is_leaf()) {
    for (Eigen::Index i = chain_a.first; i < chain_a.end; ++i) {
      pairs.visit(i, chain_b.first, chain_b.end);
    }
    return;
  }
  // Split the longer chain (a leaf is never split).
  const bool split_a = !chain_a.is_leaf() && (chain_b.is_leaf() || chain_a.end - chain_a.first >=
                                                                       chain_b.end - chain_b.first);
  if (split_a) {
    search_nearer_half_first(
        chain_a.halves(),
        [&](const auto& half) { return distance_bound(a.extents(half), b.extents(chain_b)); },
        [&](const auto& half, double half_bound) {
          search_close_edge_pairs(a, half, b, chain_b, half_bound, pairs);
        });
  } else {
    search_nearer_half_first(
        chain_b.halves(),
        [&](const auto& half) { return distance_bound(a.extents(chain_a), b.extents(half)); },
        [&](const auto& half, double half_bound) {
          search_close_edge_pairs(a, chain_a, b, half, half_bound, pairs);
        });
  }
}

// Calls pairs.visit(i, first, end), for edge i of tree a's polygon against edges first .. end - 1
// of tree b's, for every pair of leaves whose bound is below pairs.limit(), the limit read again at
// each step so that a caller lowering it as it finds closer pairs prunes more.
template <class TreeA, class TreeB, class Pairs>
void search_close_edge_pairs(TreeA& a, TreeB& b, Pairs& pairs) {
  search_close_edge_pairs(a, a.root(), b, b.root(),
                          distance_bound(a.extents(a.root()), b.extents(b.root())), pairs);
}

}  // namespace diffpills::detail
