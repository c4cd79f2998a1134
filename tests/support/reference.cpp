#include "reference.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace diffpills::testing {
namespace {

struct Segment {
  Vec3L a, b;
};

ClosestPair make_pair(const Vec3L& p1, const Vec3L& p2) { return {(p1 - p2).norm(), p1, p2}; }

void keep_closer(ClosestPair& best, const ClosestPair& candidate) {
  if (candidate.distance < best.distance) best = candidate;
}

Vec3L closest_on_segment(const Vec3L& p, const Segment& s) {
  const Vec3L d = s.b - s.a;
  const long double length2 = d.squaredNorm();
  if (length2 == 0) return s.a;
  const long double t = std::clamp((p - s.a).dot(d) / length2, 0.0L, 1.0L);
  return s.a + t * d;
}

// Segment to segment: an endpoint of one against the other (four cases), or both interior, where
// the connecting vector is perpendicular to both lines (solved only when the lines are not
// parallel; parallel interior pairs are matched by an endpoint pair at the same distance).
ClosestPair segment_segment(const Segment& s, const Segment& t) {
  ClosestPair best{std::numeric_limits<long double>::infinity(), {}, {}};
  keep_closer(best, make_pair(s.a, closest_on_segment(s.a, t)));
  keep_closer(best, make_pair(s.b, closest_on_segment(s.b, t)));
  keep_closer(best, make_pair(closest_on_segment(t.a, s), t.a));
  keep_closer(best, make_pair(closest_on_segment(t.b, s), t.b));
  const Vec3L u = s.b - s.a;
  const Vec3L v = t.b - t.a;
  const Vec3L w = s.a - t.a;
  const long double a = u.dot(u), b = u.dot(v), c = v.dot(v), d = u.dot(w), e = v.dot(w);
  const long double det = a * c - b * b;
  if (det > 1e-24L * a * c) {
    const long double sp = (b * e - c * d) / det;
    const long double tp = (a * e - b * d) / det;
    if (sp > 0 && sp < 1 && tp > 0 && tp < 1) {
      keep_closer(best, make_pair(s.a + sp * u, t.a + tp * v));
    }
  }
  return best;
}

// Newell's method about the first vertex (about the world origin, the cross products of a tiny
// polygon far away would cancel), scaled by its largest component before normalizing so that a
// polygon of any size keeps a unit normal.
Vec3L polygon_normal(const std::vector<Vec3L>& v) {
  Vec3L n = Vec3L::Zero();
  for (std::size_t i = 1; i + 1 < v.size(); ++i) {
    n += (v[i] - v[0]).cross(v[i + 1] - v[0]);
  }
  return (n / n.cwiseAbs().maxCoeff()).normalized();
}

// Is a point of the polygon's plane inside the (counterclockwise about n) polygon?
bool inside_polygon(const Vec3L& p, const std::vector<Vec3L>& v, const Vec3L& n) {
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Vec3L edge = v[(i + 1) % v.size()] - v[i];
    if (edge.cross(p - v[i]).dot(n) < 0) return false;
  }
  return true;
}

std::vector<Segment> edges(const WorldCore& core) {
  std::vector<Segment> out;
  const auto& v = core.vertices;
  if (v.size() == 1) {
    out.push_back({v[0], v[0]});
  } else if (v.size() == 2) {
    out.push_back({v[0], v[1]});
  } else {
    for (std::size_t i = 0; i < v.size(); ++i) out.push_back({v[i], v[(i + 1) % v.size()]});
  }
  return out;
}

// Feature pairs of `a` against the polygon `b` that the edge-edge pairs miss: a vertex of `a`
// over the face of `b`, and an edge of `a` crossing the face of `b`.
void against_face(const WorldCore& a, const WorldCore& b, bool swapped, ClosestPair& best) {
  if (b.vertices.size() < 3) return;
  const Vec3L n = polygon_normal(b.vertices);
  const Vec3L& origin = b.vertices[0];
  auto keep = [&](const Vec3L& on_a, const Vec3L& on_b) {
    keep_closer(best, swapped ? make_pair(on_b, on_a) : make_pair(on_a, on_b));
  };
  for (const Vec3L& p : a.vertices) {
    const Vec3L projected = p - (p - origin).dot(n) * n;
    if (inside_polygon(projected, b.vertices, n)) keep(p, projected);
  }
  for (const Segment& e : edges(a)) {
    const long double ha = (e.a - origin).dot(n);
    const long double hb = (e.b - origin).dot(n);
    if ((ha < 0 && hb > 0) || (ha > 0 && hb < 0)) {
      const Vec3L crossing = e.a + (ha / (ha - hb)) * (e.b - e.a);
      const Vec3L in_plane = crossing - (crossing - origin).dot(n) * n;
      if (inside_polygon(in_plane, b.vertices, n)) keep(crossing, crossing);
    }
  }
}

}  // namespace

ClosestPair brute_force_closest(const WorldCore& a, const WorldCore& b) {
  ClosestPair best{std::numeric_limits<long double>::infinity(), {}, {}};
  for (const Segment& s : edges(a)) {
    for (const Segment& t : edges(b)) keep_closer(best, segment_segment(s, t));
  }
  against_face(a, b, false, best);
  against_face(b, a, true, best);
  return best;
}

long double distance_to_core(const Eigen::Vector3d& point, const WorldCore& core) {
  return brute_force_closest({{point.cast<long double>()}}, core).distance;
}

SignedCoreDistance brute_force_signed_distance(const WorldCore& a, const WorldCore& b,
                                               long double scale) {
  const ClosestPair closest = brute_force_closest(a, b);
  if (closest.distance > 1e-10L * scale) {
    return {closest.distance, (closest.p2 - closest.p1) / closest.distance};
  }
  std::vector<Vec3L> w;
  for (const auto& va : a.vertices) {
    for (const auto& vb : b.vertices) w.emplace_back(va - vb);
  }
  const long double slack = 1e-12L * scale;
  SignedCoreDistance best{std::numeric_limits<long double>::infinity(), Vec3L::Zero()};
  const std::size_t n = w.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      for (std::size_t k = j + 1; k < n; ++k) {
        Vec3L normal = (w[j] - w[i]).cross(w[k] - w[i]);
        const long double length = normal.norm();
        if (length <= 1e-9L * scale * scale) continue;  // (nearly) collinear points
        normal /= length;
        const long double offset = normal.dot(w[i]);
        long double low = offset, high = offset;
        for (const auto& x : w) {
          low = std::min(low, normal.dot(x));
          high = std::max(high, normal.dot(x));
        }
        // A supporting plane: the outward normal points away from the points' side.
        if (high <= offset + slack && offset < best.s) best = {offset, normal};
        if (low >= offset - slack && -offset < best.s) best = {-offset, -normal};
      }
    }
  }
  if (best.s == std::numeric_limits<long double>::infinity()) return {0, Vec3L::Zero()};
  return {-best.s, best.normal};
}

namespace {

long double support(const WorldCore& core, const Vec3L& n) {
  long double best = -std::numeric_limits<long double>::infinity();
  for (const auto& v : core.vertices) best = std::max(best, n.dot(v));
  return best;
}

// The core's edge directions (unnormalized): a segment's one, a polygon's every side.
std::vector<Vec3L> edge_directions(const WorldCore& core) {
  std::vector<Vec3L> edges;
  const std::size_t n = core.vertices.size();
  if (n == 2) edges.emplace_back(core.vertices[1] - core.vertices[0]);
  if (n >= 3) {
    for (std::size_t i = 0; i < n; ++i)
      edges.emplace_back(core.vertices[(i + 1) % n] - core.vertices[i]);
  }
  return edges;
}

// A polygon's unit normal (from its first three vertices, which are not collinear for a reduced
// polygon), or none.
std::vector<Vec3L> face_normals(const WorldCore& core) {
  if (core.vertices.size() < 3) return {};
  const Vec3L n = (core.vertices[1] - core.vertices[0]).cross(core.vertices[2] - core.vertices[0]);
  return {n / n.norm()};
}

}  // namespace

long double brute_force_penetration_depth(const WorldCore& a, const WorldCore& b) {
  std::vector<Vec3L> axes = face_normals(a);
  for (const Vec3L& n : face_normals(b)) axes.push_back(n);
  for (const Vec3L& e : edge_directions(a)) {
    for (const Vec3L& f : edge_directions(b)) {
      const Vec3L c = e.cross(f);

      if (c.norm() > 1e-15L * e.norm() * f.norm()) axes.emplace_back(c / c.norm());
    }
  }
  long double depth = std::numeric_limits<long double>::infinity();
  for (const Vec3L& n : axes) {
    depth = std::min(depth, support(a, n) + support(b, -n));
    depth = std::min(depth, support(a, -n) + support(b, n));
  }
  return depth == std::numeric_limits<long double>::infinity() ? 0 : std::max(depth, 0.0L);
}

}  // namespace diffpills::testing
