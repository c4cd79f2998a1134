// A bounding hierarchy over a polygon's edges, for the penetration search of two large polygons
// (penetration.cpp): each node is a chain of consecutive edges with a ball holding every point of
// them and a cone holding their directions.
//
// What the search asks of two chains, one of each polygon: can an edge e of the first and an edge
// f of the second hold points x, y whose difference w = x - y is (nearly) normal to both e and f,
// at a distance |w| below a bound? Only such pairs can be the nearest facet of the cores'
// Minkowski difference (penetration.hpp: its nearest point is x - y with x - y = depth * n,
// n normal to both edges). With the balls (centres c1, c2, radii r1, r2) and a chain's cone
// (every direction e within |e - e0| <= beta of its axis e0), write c = c1 - c2, r = r1 + r2,
// w = c + delta with |delta| <= r and e = e0 + eps with |eps| <= beta; then
//
//     |w| >= |c| - r,       |w . e - c . e0| <= |c . eps| + |delta . e| <= |c| beta + r,
//
// so the chains hold no such pair when |c| - r exceeds the bound, or when |c . e0| exceeds
// |c| beta + r plus the allowed |w . e| (for either chain). Halving the chains shrinks r and beta
// together, so only chain pairs near points where both w . e and w . f vanish survive: for a pair
// of polygons in general position that is a few places, and the search costs about
// O((m1 + m2) log) instead of the m1 m2 of visiting every pair (a polygon pair with a continuum of
// such points, e.g. an edge along the axis of a regular polygon, costs O(m) leaves).
//
// Directions. The edges of a convex polygon turn counterclockwise about its normal N, so a chain's
// directions sweep the arc from its first direction s to its last t; when that arc is shorter than
// a half turn, the bisector e0 = (s + t) / |s + t| is within half of it of every direction:
// beta = |s - e0|. A sub-chain turns by less than a whole turn, so its arc is shorter than a half
// turn exactly when (s x t) . N > 0 (or s = t); longer chains get no cone (beta = 2, no bound).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core_outline.hpp"

namespace diffpills::detail {

class EdgeChainTree {
 public:
  struct Node {
    Eigen::Index first = 0, end = 0;  // edges first .. end - 1
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    double radius = 0.0;                             // the ball holds the chain's edges
    Eigen::Vector3d axis = Eigen::Vector3d::Zero();  // e0, unit (when spread < 2)
    double spread = 2.0;                             // beta: |e - axis| <= spread
    int children[2] = {-1, -1};                      // -1: a leaf
    bool is_leaf() const { return children[0] < 0; }
  };

  // Chains of at most this many edges are leaves, whose edge pairs the search visits one by one.
  static constexpr Eigen::Index kLeafEdges = 8;

  // `polygon` is a polygon's outline (is_polygon()); it must outlive the tree.
  explicit EdgeChainTree(const CoreOutline& polygon);

  const Node& root() const { return nodes_.front(); }
  const Node& node(int index) const { return nodes_[static_cast<std::size_t>(index)]; }

 private:
  int build(Eigen::Index first, Eigen::Index end);
  void set_cone(Node& node) const;

  const CoreOutline* polygon_;
  std::vector<Node> nodes_;
};

// What the search reports to and asks of its caller: the bounds, read again at each step so
// that a caller lowering them as it finds better pairs prunes more, and the edge pairs.
class NearNormalEdgePairs {
 public:
  virtual ~NearNormalEdgePairs() = default;
  virtual double distance_bound() const = 0;  // |w| <= this
  virtual double normal_slack() const = 0;    // |w . e|, |w . f| <= this
  virtual void visit(Eigen::Index edge_a, Eigen::Index edge_b) = 0;
};

// Calls pairs.visit(i, j) for every edge i of tree a's polygon and j of tree b's in a pair of
// leaves the bounds above do not rule out. Of the two halves of a split, the nearer (by |c| - r)
// is searched first.
void search_near_normal_edge_pairs(const EdgeChainTree& a, const EdgeChainTree& b,
                                   NearNormalEdgePairs& pairs);

}  // namespace diffpills::detail
