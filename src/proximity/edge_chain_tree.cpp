#include "edge_chain_tree.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace diffpills::detail {
namespace {

// A chain's cone is kept while its directions turn by less than a sixth of a turn (cosine above
// 1/2 between the first and every later direction). Checked step by step, each step turning by less
// than a half turn (a convex polygon's exterior angle), the test cannot mistake a chain turning by
// almost a whole turn, whose first and last directions are again close, for a short one.
constexpr double kConeCosine = 0.5;

bool within_cone(const Eigen::Vector3d& first, const Eigen::Vector3d& direction,
                 const Eigen::Vector3d& normal) {
  return first.cross(direction).dot(normal) >= 0.0 && first.dot(direction) > kConeCosine;
}

// The smallest ball holding two balls.
void enclose(const Eigen::Vector3d& c1, double r1, const Eigen::Vector3d& c2, double r2,
             Eigen::Vector3d& center, double& radius) {
  const double apart = (c2 - c1).norm();
  if (apart + r2 <= r1) {
    center = c1;
    radius = r1;
  } else if (apart + r1 <= r2) {
    center = c2;
    radius = r2;
  } else {
    radius = 0.5 * (apart + r1 + r2);
    center = c1 + ((radius - r1) / apart) * (c2 - c1);
  }
  // Rounding of the centre and of the sums: a relative margin far above it.
  radius *= 1.0 + 1e-12;
}

struct Bounds {
  double lower = 0.0;  // |c| - r
  Eigen::Vector3d between = Eigen::Vector3d::Zero();
  double radii = 0.0;
};

Bounds bounds(const EdgeChainTree::Node& a, const EdgeChainTree::Node& b) {
  Bounds result;
  result.between = a.center - b.center;
  result.radii = a.radius + b.radius;
  result.lower = result.between.norm() - result.radii;
  return result;
}

// No w = x - y of the two balls has |w . e| <= slack for a direction e of the chain's cone.
bool never_normal(const EdgeChainTree::Node& chain, const Bounds& b, double slack) {
  if (chain.spread >= 2.0) return false;
  return std::abs(b.between.dot(chain.axis)) > b.between.norm() * chain.spread + b.radii + slack;
}

void search(const EdgeChainTree& a, int index_a, const EdgeChainTree& b, int index_b,
            NearNormalEdgePairs& pairs) {
  const EdgeChainTree::Node& node_a = a.node(index_a);
  const EdgeChainTree::Node& node_b = b.node(index_b);
  const Bounds here = bounds(node_a, node_b);
  if (here.lower > pairs.distance_bound()) return;
  const double slack = pairs.normal_slack();
  if (never_normal(node_a, here, slack) || never_normal(node_b, here, slack)) return;
  if (node_a.is_leaf() && node_b.is_leaf()) {
    for (Eigen::Index i = node_a.first; i < node_a.end; ++i) {
      for (Eigen::Index j = node_b.first; j < node_b.end; ++j) pairs.visit(i, j);
    }
    return;
  }
  // Split the larger chain (the only one that can be split, if the other is a leaf).
  const bool split_a = node_b.is_leaf() || (!node_a.is_leaf() && node_a.radius >= node_b.radius);
  const EdgeChainTree::Node& split = split_a ? node_a : node_b;
  int first = split.children[0], second = split.children[1];
  const auto lower = [&](int child) {
    return split_a ? bounds(a.node(child), node_b).lower : bounds(node_a, b.node(child)).lower;
  };
  if (lower(second) < lower(first)) std::swap(first, second);
  for (const int child : {first, second}) {
    if (split_a) {
      search(a, child, b, index_b, pairs);
    } else {
      search(a, index_a, b, child, pairs);
    }
  }
}

}  // namespace

EdgeChainTree::EdgeChainTree(const CoreOutline& polygon) : polygon_(&polygon) {
  nodes_.reserve(static_cast<std::size_t>(4 * (polygon.edge_count() / kLeafEdges + 1)));
  build(0, polygon.edge_count());
}

int EdgeChainTree::build(Eigen::Index first, Eigen::Index end) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  nodes_.back().first = first;
  nodes_.back().end = end;
  if (end - first <= kLeafEdges) {
    // The chain's vertices: the start of its first edge, then every edge's end.
    Eigen::Vector3d low = polygon_->edge(first).start, high = low;
    for (Eigen::Index j = first; j < end; ++j) {
      const OutlineEdge& edge = polygon_->edge(j);
      const Eigen::Vector3d tip = edge.start + edge.length * edge.direction;
      low = low.cwiseMin(tip);
      high = high.cwiseMax(tip);
    }
    Node& leaf = nodes_.back();
    leaf.center = 0.5 * (low + high);
    for (Eigen::Index j = first; j < end; ++j) {
      const OutlineEdge& edge = polygon_->edge(j);
      leaf.radius = std::max({leaf.radius, (edge.start - leaf.center).norm(),
                              (edge.start + edge.length * edge.direction - leaf.center).norm()});
    }
    leaf.radius *= 1.0 + 1e-12;
    set_cone(leaf);
    return index;
  }
  const Eigen::Index middle = first + (end - first) / 2;
  const int left = build(first, middle);
  const int right = build(middle, end);
  Node& node = nodes_[static_cast<std::size_t>(index)];  // after the children's emplace_back
  node.children[0] = left;
  node.children[1] = right;
  enclose(nodes_[static_cast<std::size_t>(left)].center,
          nodes_[static_cast<std::size_t>(left)].radius,
          nodes_[static_cast<std::size_t>(right)].center,
          nodes_[static_cast<std::size_t>(right)].radius, node.center, node.radius);
  set_cone(node);
  return index;
}

void EdgeChainTree::set_cone(Node& node) const {
  const Eigen::Vector3d normal = polygon_->face_normal();
  const Eigen::Vector3d start = polygon_->edge(node.first).direction;
  const Eigen::Vector3d last = polygon_->edge(node.end - 1).direction;
  bool narrow;
  if (node.is_leaf()) {
    narrow = true;
    for (Eigen::Index j = node.first + 1; j < node.end && narrow; ++j) {
      narrow = within_cone(start, polygon_->edge(j).direction, normal);
    }
  } else {
    // Each child turns by less than a sixth of a turn and the step between them by less than a
    // half turn, so the chain turns by less than 5/6 of a turn: the test on its ends is then
    // unambiguous.
    narrow = nodes_[static_cast<std::size_t>(node.children[0])].spread < 2.0 &&
             nodes_[static_cast<std::size_t>(node.children[1])].spread < 2.0 &&
             within_cone(start, last, normal);
  }
  if (!narrow) return;
  node.axis = (start + last).normalized();
  node.spread = (start - node.axis).norm() * (1.0 + 1e-12) + 1e-15;
}

void search_near_normal_edge_pairs(const EdgeChainTree& a, const EdgeChainTree& b,
                                   NearNormalEdgePairs& pairs) {
  search(a, 0, b, 0, pairs);
}

}  // namespace diffpills::detail
