#include "penetration.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "segment_segment.hpp"

namespace diffpills::detail {
namespace {

// Two unit vectors closer than this to parallel (|sin| <= 1e-12) have no edge-edge facet: the
// threshold of every parallel test of the fast paths.
constexpr double kParallelSine = 1e-12;
// The normal-cone tests' allowance, a cosine (see the header).
constexpr double kConeSlack = 1e-12;
// An edge pair whose normal is within this angle of a polygon's face normal is left to the face.
constexpr double kSliverAngle = 1e-10;

// Is n within kSliverAngle of +-(the face normal of `core`)? Such an edge-pair facet is a sliver
// beside the face's facet (their normals' arcs meet at the face's pole), whose nearest point a
// rounding moves off it (fuzz_proximity found its witnesses a third of the scene apart). Leaving
// it out changes the depth by at most the angle times D's reach: 1e-10 of the scene.
bool along_a_face(const Eigen::Vector3d& n, const CoreOutline& core) {
  return core.is_polygon() && n.cross(core.face_normal()).norm() <= kSliverAngle;
}

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

// A face facet: `face` (core face_core) is a whole polygon, `other` touches the facet with its
// support set, the vertices within the tolerance of other's extreme value along -sign * n, with
// sign = +1 for core 1's face (K2's lowest points) and -1 for core 2's (K1's highest points).
// The pair is x_face = x_other + sign * depth * n.
std::array<ClosestFeature, 2> face_witnesses(const DeepestFacet& facet, const CoreOutline& face,
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
    return facet.face_core == 0 ? std::array<ClosestFeature, 2>{face_side, other_side}
                                : std::array<ClosestFeature, 2>{other_side, face_side};
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
  // face of `other` is parallel to this one, where D is flat and the caller does not ask).
  Eigen::Index chosen = first;
  for (Eigen::Index i = first; i <= last; ++i) {
    if (down.dot(other.vertex(i)) >= extreme - tolerance &&
        contains(face.polygon(), body(other.vertex(i) + shift), tolerance)) {
      chosen = i;
      break;
    }
  }
  return ordered(face.face_side(other.vertex(chosen) + shift), other.vertex_side(chosen));
}

// An edge-edge facet: the points of the two edges whose difference is along n, the closest points
// of the edges' lines, which lie on the edges for the nearest facet. They are taken from the
// backward-stable segment solver (segment_segment.hpp), not from the normal: for nearly parallel
// edges (angle alpha) the normal e x f / |e x f| is only known to ~1e-16 / alpha, while the closest
// points are accurate; the caller then takes the normal from them.
std::array<ClosestFeature, 2> edge_witnesses(const DeepestFacet& facet, const CoreOutline& a,
                                             const CoreOutline& b) {
  const OutlineEdge& e = a.edge(facet.edges[0]);
  const OutlineEdge& f = b.edge(facet.edges[1]);
  const SegmentParameters closest =
      closest_segment_parameters({e.start + 0.5 * e.length * e.direction, e.direction, e.length},
                                 {f.start + 0.5 * f.length * f.direction, f.direction, f.length});
  return {a.edge_side(facet.edges[0], closest.s), b.edge_side(facet.edges[1], closest.t)};
}

}  // namespace

Eigen::Vector3d stable_cross(const Eigen::Vector3d& e, const Eigen::Vector3d& f) {
  return e.cross(e.dot(f) >= 0.0 ? Eigen::Vector3d(f - e) : Eigen::Vector3d(f + e));
}

DeepestFacet deepest_facet(const CoreOutline& a, const CoreOutline& b, double tolerance) {
  const Eigen::Vector3d offset = b.posed().r - a.posed().r;
  const Eigen::Vector3d z1 = a.face_normal();
  DeepestFacet best;
  best.depth = std::numeric_limits<double>::infinity();
  const auto consider = [&](const DeepestFacet& candidate) {
    if (best.kind == DeepestFacet::Kind::kNone || better(candidate, best, offset, z1, tolerance)) {
      best = candidate;
    }
  };
  for (int core = 0; core < 2; ++core) {
    const CoreOutline& face = core == 0 ? a : b;
    if (!face.is_polygon()) continue;
    for (const double sign : {1.0, -1.0}) {
      const Eigen::Vector3d n = sign * face.face_normal();
      consider({DeepestFacet::Kind::kFace, a.support(n) + b.support(-n), n, core, {0, 0}});
    }
  }
  for (Eigen::Index i = 0; i < a.edge_count(); ++i) {
    const OutlineEdge& e = a.edge(i);
    for (Eigen::Index j = 0; j < b.edge_count(); ++j) {
      const OutlineEdge& f = b.edge(j);
      const Eigen::Vector3d c = stable_cross(e.direction, f.direction);
      const double sine = c.norm();
      if (sine <= kParallelSine) continue;
      const Eigen::Vector3d n = c / sine;
      if (along_a_face(n, a) || along_a_face(n, b)) continue;
      const double gap = n.dot(e.start - f.start);
      for (const double sign : {1.0, -1.0}) {
        if (a.is_polygon() && sign * n.dot(e.outward) < -kConeSlack) continue;
        if (b.is_polygon() && sign * n.dot(f.outward) > kConeSlack) continue;
        consider({DeepestFacet::Kind::kEdges, sign * gap, sign * n, 0, {i, j}});
      }
    }
  }
  if (best.kind == DeepestFacet::Kind::kNone) best.depth = 0.0;
  return best;
}

std::array<ClosestFeature, 2> facet_witnesses(const DeepestFacet& facet, const CoreOutline& a,
                                              const CoreOutline& b, double tolerance) {
  if (facet.kind == DeepestFacet::Kind::kEdges) return edge_witnesses(facet, a, b);
  return facet.face_core == 0 ? face_witnesses(facet, a, b, tolerance)
                              : face_witnesses(facet, b, a, tolerance);
}

}  // namespace diffpills::detail
