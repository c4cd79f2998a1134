#include "penetration.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "edge_chain_tree.hpp"
#include "segment_segment.hpp"

namespace diffpills::detail {
namespace {

// Two unit vectors closer than this to parallel (|sin| <= 1e-12) have no edge-edge facet: the
// threshold of every parallel test of the fast paths.
constexpr double kParallelSine = 1e-12;
// The normal-cone tests' allowance, a cosine (see the header).
constexpr double kConeSlack = 1e-12;
// How far (relatively) an edge pair's witnesses may be further apart than its facet's depth (the
// header's witness rule).
constexpr double kWitnessRatio = 1e-9;
// Polygon pairs with more edge pairs than this (32 x 32) search the edge chains' hierarchies.
constexpr Eigen::Index kEnumeratedEdgePairs = Eigen::Index{32} * 32;

using Sides = std::array<ClosestFeature, 2>;

// The header's order of candidates: smaller depth, then a face over an edge pair, then larger
// n . (r2 - r1), then larger n . (Q1 e_z), each compared with the tolerance so that rounding does
// not decide.
bool better(const DeepestFacet& candidate, const DeepestFacet& best, const Eigen::Vector3d& offset,
            const Eigen::Vector3d& z1, double tolerance) {
  if (candidate.depth < best.depth - tolerance) return true;
  if (candidate.depth > best.depth + tolerance) return false;
  if (candidate.kind != best.kind) return candidate.kind == DeepestFacet::Kind::kFace;
  const double toward = candidate.normal.dot(offset), best_toward = best.normal.dot(offset);
  if (toward > best_toward + tolerance) return true;
  if (toward < best_toward - tolerance) return false;
  return candidate.normal.dot(z1) > best.normal.dot(z1) + kConeSlack;
}

// Is a point of a polygon's plane in the polygon grown by the tolerance (contains())? A face
// facet tests the shadows of the other core's support vertices, and for nearly parallel faces
// (within a few tolerances over the polygons' size) that is most of a polygon's vertices: testing
// each against every row was quadratic (a hostile review: two 10^5-gons 1e-11 rad from parallel
// took 3 s). Above kDirectRows rows a point is first tested against the rows around the direction
// from the polygon's origin (which is inside it) through the point: the edge that ray leaves by,
// found by a binary search over the vertices' angles, and two rows on either side (a ray near a
// vertex can leave the grown polygon by a neighbour). Only a point that passes is tested against
// every row, at most kFullTests times: O(m log m) in all.
class ShadowTest {
 public:
  ShadowTest(const PolygonView& polygon, double tolerance)
      : polygon_(polygon), tolerance_(tolerance) {}

  bool operator()(const Eigen::Vector2d& y) {
    if (polygon_.size() <= kDirectRows) return contains(polygon_, y, tolerance_);
    if (angles_.empty()) {
      // Vertex i's angle, unwrapped to increase from vertex 0's (the vertices turn
      // counterclockwise about the origin by less than a whole turn in all).
      angles_.resize(static_cast<std::size_t>(polygon_.size()));
      for (Eigen::Index i = 0; i < polygon_.size(); ++i) {
        const Eigen::Vector2d v = polygon_.vertex(i);
        double angle = std::atan2(v.y(), v.x());
        while (i > 0 && angle < angles_[static_cast<std::size_t>(i - 1)]) angle += 2.0 * M_PI;
        angles_[static_cast<std::size_t>(i)] = angle;
      }
    }
    double angle = std::atan2(y.y(), y.x());
    while (angle < angles_.front()) angle += 2.0 * M_PI;
    // Edge j runs from vertex j - 1 to vertex j: the first vertex past the angle ends the edge (0,
    // from the last vertex to vertex 0, past them all).
    const auto past = std::upper_bound(angles_.begin(), angles_.end(), angle);
    const Eigen::Index edge = past == angles_.end() ? 0 : past - angles_.begin();
    const Eigen::Index m = polygon_.size();
    for (Eigen::Index k = -2; k <= 2; ++k) {
      const Eigen::Index j = ((edge + k) % m + m) % m;
      if (polygon_.normal(j).dot(y) > polygon_.offset(j) + tolerance_) return false;
    }
    if (full_tests_ == kFullTests) return false;
    ++full_tests_;
    return contains(polygon_, y, tolerance_);
  }

 private:
  // Up to 32 rows, the polygons the fast paths keep off the heap, every test is direct: the
  // angles' vector allocated (a hostile review counted 4 allocations for a capsule crossing a
  // 17-gon at 16).
  static constexpr Eigen::Index kDirectRows = 32;
  static constexpr int kFullTests = 4;

  const PolygonView& polygon_;
  double tolerance_;
  std::vector<double> angles_;
  int full_tests_ = 0;
};

// A face facet: `face` (core face_core) is a whole polygon, `other` touches the facet with its
// support set, the vertices within the tolerance of other's extreme value along -sign * n, with
// sign = +1 for core 1's face (K2's lowest points) and -1 for core 2's (K1's highest points).
// The pair is x_face = x_other + sign * depth * n, with x_face in the face (to the tolerance);
// none when the support set's shadow misses the face (the facet's nearest point is off it).
std::optional<Sides> face_witnesses(const DeepestFacet& facet, const CoreOutline& face,
                                    const CoreOutline& other, double tolerance) {
  const double sign = facet.face_core == 0 ? 1.0 : -1.0;
  const Eigen::Vector3d shift = sign * facet.depth * facet.normal;
  const Eigen::Vector3d down = -sign * facet.normal;  // other's support direction
  const double extreme = other.support(down);
  Eigen::Index first = -1, last = -1, count = 0;
  for (Eigen::Index i = 0; i < other.vertex_count(); ++i) {
    if (down.dot(other.vertex(i)) >= extreme - tolerance) {
      if (first < 0) first = i;
      last = i;
      ++count;
    }
  }
  const auto ordered = [&](const ClosestFeature& face_side, const ClosestFeature& other_side) {
    return facet.face_core == 0 ? Sides{face_side, other_side} : Sides{other_side, face_side};
  };
  const auto body = [&](const Eigen::Vector3d& x) -> Eigen::Vector2d {
    return (face.posed().attitude.matrix().transpose() * (x - face.posed().r)).head<2>();
  };
  // An edge of `other` parallel to the face: the middle of its part over the face. Vertices i
  // and i + 1 (or the last and the first) bound edge i + 1 (or 0) of a polygon; a segment's two
  // ends bound its edge 0.
  if (count == 2) {
    const bool wraps = other.is_polygon() && first == 0 && last == other.vertex_count() - 1;
    if (wraps || last == first + 1) {
      const Eigen::Index j = wraps ? 0 : (other.is_polygon() ? last : 0);
      const OutlineEdge& edge = other.edge(j);
      const Eigen::Vector2d y0 = body(edge.start + shift);
      const Eigen::Vector2d y1 = body(edge.start + edge.length * edge.direction + shift);
      const auto [low, high] = clip_line(face.polygon(), y0, y1 - y0, tolerance);
      if (low <= high) {
        const double t = 0.5 * (low + high);
        const Eigen::Vector3d x = edge.start + (t * edge.length) * edge.direction;
        return ordered(face.face_side(x + shift), other.edge_side(j, t));
      }
    }
  }
  // A vertex: the first support vertex whose shadow lies on the face (the only one, unless a
  // face of `other` is nearly parallel to this one).
  ShadowTest inside(face.polygon(), tolerance);
  for (Eigen::Index i = first; i <= last; ++i) {
    if (down.dot(other.vertex(i)) >= extreme - tolerance && inside(body(other.vertex(i) + shift))) {
      return ordered(face.face_side(other.vertex(i) + shift), other.vertex_side(i));
    }
  }
  return std::nullopt;
}

// An edge-edge facet: the points of the two edges whose difference is along n, the closest points
// of the edges' lines, which lie on the edges when the facet's nearest point lies on it. They are
// taken from the backward-stable segment solver (segment_segment.hpp), not from the normal: for
// nearly parallel edges (angle alpha) the normal e x f / |e x f| is only known to ~1e-16 / alpha,
// while the closest points are accurate. x1 - x2 is a point of the facet (which lies in D's
// boundary), so |x1 - x2| is at least the depth; it is accepted when it points along n and is at
// most the facet's value (known to within `uncertainty`) times 1 + kWitnessRatio plus the
// tolerance, and the facet's depth and normal are then taken from it.
bool take_edge_witnesses(DeepestFacet& facet, double uncertainty, const CoreOutline& a,
                         const CoreOutline& b, double tolerance) {
  const OutlineEdge& e = a.edge(facet.edges[0]);
  const OutlineEdge& f = b.edge(facet.edges[1]);
  const Segment edge_e{e.start + 0.5 * e.length * e.direction, e.direction, e.length};
  const Segment edge_f{f.start + 0.5 * f.length * f.direction, f.direction, f.length};
  const SegmentParameters closest = closest_segment_parameters(edge_e, edge_f);
  const Eigen::Vector3d across = edge_e.at(closest.s_offset) - edge_f.at(closest.t_offset);
  const double depth = across.norm();
  if (depth <= tolerance || across.dot(facet.normal) <= 0.0 ||
      depth > (facet.depth + uncertainty) * (1.0 + kWitnessRatio) + tolerance) {
    return false;
  }
  facet.depth = depth;
  facet.normal = across / depth;
  facet.witnesses =
      Sides{a.edge_side(facet.edges[0], closest.s), b.edge_side(facet.edges[1], closest.t)};
  return true;
}

// The search keeps the best candidate whose witnesses lie on its facet (`best`, in the header's
// order, with its depth from the witnesses), the candidate of smallest value (`lowest`, the
// fallback) and an upper bound on the depth: the smallest value plus its rounding error (a
// candidate's value is h_D at its normal, at least the depth up to that error).
//
// A candidate's value carries the error of its normal: an edge pair's normal is off by ~2 ulps of
// the edges' directions over their sine, so its value by that times |x_e - x_f|; a face's normal
// is exact to a few ulps. An edge pair admitted by the normal-cone allowance adds what that
// allowance can hide (below).
class FacetSearch final : public NearNormalEdgePairs {
 public:
  FacetSearch(const CoreOutline& a, const CoreOutline& b, double tolerance)
      : a_(a),
        b_(b),
        tolerance_(tolerance),
        value_rounding_(1e-3 * tolerance),
        bound_slack_(tolerance),
        offset_(b.posed().r - a.posed().r),
        z1_(a.face_normal()) {}

  void consider_faces() {
    for (int core = 0; core < 2; ++core) {
      const CoreOutline& face = core == 0 ? a_ : b_;
      if (!face.is_polygon()) continue;
      for (const double sign : {1.0, -1.0}) {
        const Eigen::Vector3d n = sign * face.face_normal();
        DeepestFacet candidate;
        candidate.kind = DeepestFacet::Kind::kFace;
        candidate.depth = a_.support(n) + b_.support(-n);
        candidate.normal = n;
        candidate.face_core = core;
        offer(candidate, value_rounding_);
      }
    }
  }

  void consider_edges(Eigen::Index i, Eigen::Index j) {
    const OutlineEdge& e = a_.edge(i);
    const OutlineEdge& f = b_.edge(j);
    const Eigen::Vector3d c = stable_cross(e.direction, f.direction);
    const double sine = c.norm();
    if (sine <= kParallelSine) return;
    const Eigen::Vector3d n = c / sine;
    const Eigen::Vector3d between = e.start - f.start;
    const double gap = n.dot(between);
    const double rounding = value_rounding_ + kDirectionRounding * between.norm() / sine;
    for (const double sign : {1.0, -1.0}) {
      // How far n leans out of each edge's normal cone (zero for a segment, whose cone is every
      // normal), at most the allowance.
      const double out_a = a_.is_polygon() ? std::max(0.0, -sign * n.dot(e.outward)) : 0.0;
      const double out_b = b_.is_polygon() ? std::max(0.0, sign * n.dot(f.outward)) : 0.0;
      if (out_a > kConeSlack || out_b > kConeSlack) continue;
      DeepestFacet candidate;
      candidate.kind = DeepestFacet::Kind::kEdges;
      candidate.depth = sign * gap;
      candidate.normal = sign * n;
      candidate.edges = {i, j};
      // Admitted out of a cone by `out`, the edge is short of that core's support along n by at
      // most out times the core's diameter (2 size): the value may be that much below h_D(n).
      offer(candidate, rounding + 2.0 * (out_a * a_.posed().size + out_b * b_.posed().size));
    }
  }

  DeepestFacet result() const {
    if (best_.kind != DeepestFacet::Kind::kNone && best_.depth <= reach()) return best_;
    DeepestFacet fallback = lowest_;
    if (fallback.kind == DeepestFacet::Kind::kNone) fallback.depth = 0.0;
    return fallback;
  }

  // NearNormalEdgePairs. A pair's witnessed depth is |x1 - x2|, which must be at most limit() to
  // count. For the nearest facet x1 - x2 = depth * n is normal to both edges up to rounding; a
  // facet tied with it (depth within the tolerance) leans off its normal by at most
  // sqrt(|x1 - x2|^2 - value^2) <= sqrt(limit^2 - (limit - 2 tolerance)^2), and is kept too
  // (unless its value is uncertain, nearly parallel edges: ties may then be broken otherwise
  // than by visiting every pair).
  double distance_bound() const override { return limit() + bound_slack_; }
  double normal_slack() const override {
    const double bound = std::max(limit(), 0.0);
    const double low = std::max(bound - 2.0 * tolerance_, 0.0);
    return std::sqrt(bound * bound - low * low) + bound_slack_;
  }
  void visit(Eigen::Index edge_a, Eigen::Index edge_b) override { consider_edges(edge_a, edge_b); }

 private:
  // Witnessed depths are taken up to this: the bound on the depth plus what a witnessed depth may
  // exceed the value by.
  double reach() const { return depth_bound_ * (1.0 + kWitnessRatio) + tolerance_; }
  // A candidate counts only if its depth is at most this (it must tie with or beat `best`).
  double limit() const {
    return best_.kind == DeepestFacet::Kind::kNone ? reach()
                                                   : std::min(reach(), best_.depth + tolerance_);
  }

  void offer(DeepestFacet candidate, double uncertainty) {
    if (lowest_.kind == DeepestFacet::Kind::kNone ||
        better(candidate, lowest_, offset_, z1_, tolerance_)) {
      lowest_ = candidate;
    }
    depth_bound_ = std::min(depth_bound_, candidate.depth + uncertainty);
    if (candidate.depth - uncertainty > limit()) return;
    if (candidate.depth > tolerance_ && !take_witnesses(candidate, uncertainty)) return;
    if (best_.kind == DeepestFacet::Kind::kNone ||
        better(candidate, best_, offset_, z1_, tolerance_)) {
      best_ = candidate;
    }
  }

  bool take_witnesses(DeepestFacet& candidate, double uncertainty) const {
    if (candidate.kind == DeepestFacet::Kind::kEdges) {
      return take_edge_witnesses(candidate, uncertainty, a_, b_, tolerance_);
    }
    candidate.witnesses = candidate.face_core == 0 ? face_witnesses(candidate, a_, b_, tolerance_)
                                                   : face_witnesses(candidate, b_, a_, tolerance_);
    return candidate.witnesses.has_value();
  }

  // An edge pair's normal e x f / |e x f| is off by ~2 ulps of the directions over the sine.
  static constexpr double kDirectionRounding = 1e-15;

  const CoreOutline& a_;
  const CoreOutline& b_;
  double tolerance_;
  // Relative to the tolerance, 1e-12 of the length the search works at (the frame's scene, or two
  // polygons' own: pair_setup.hpp, search_tolerances): a value's rounding, a few ulps of it; and
  // how far the edge-pair search's bounds are kept above what they bound, far above the rounding
  // of the sums that form them. As constants of the scene where the radii make it, both exceeded
  // a needle's width (4e-14 beside radii of 1), the hierarchies ruled no pair out, and two
  // crossing needles of 64,000 vertices took 11 s.
  double value_rounding_, bound_slack_;
  Eigen::Vector3d offset_, z1_;
  DeepestFacet lowest_, best_;
  double depth_bound_ = std::numeric_limits<double>::infinity();
};

}  // namespace

Eigen::Vector3d stable_cross(const Eigen::Vector3d& e, const Eigen::Vector3d& f) {
  return e.cross(e.dot(f) >= 0.0 ? Eigen::Vector3d(f - e) : Eigen::Vector3d(f + e));
}

DeepestFacet deepest_facet(const CoreOutline& a, const CoreOutline& b, double tolerance,
                           EdgePairVisits visits) {
  FacetSearch search(a, b, tolerance);
  search.consider_faces();
  if (visits == EdgePairVisits::kPruned && a.is_polygon() && b.is_polygon() &&
      a.edge_count() * b.edge_count() > kEnumeratedEdgePairs) {
    const EdgeChainTree tree_a(a), tree_b(b);
    search_near_normal_edge_pairs(tree_a, tree_b, search);
  } else {
    for (Eigen::Index i = 0; i < a.edge_count(); ++i) {
      for (Eigen::Index j = 0; j < b.edge_count(); ++j) search.consider_edges(i, j);
    }
  }
  return search.result();
}

}  // namespace diffpills::detail
