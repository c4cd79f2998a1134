// Feature-level geometry of a reduced polygon in its own body frame (the x-y plane), for the
// fast paths: edges, inside tests, clipping. Edge j is bounded by row j of edge_normals() and runs
// counterclockwise from vertex j - 1 to vertex j (vertex i joins edges i and i + 1).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>

#include "diffpills/shapes.hpp"
#include "posed_core.hpp"
#include "segment_segment.hpp"

namespace diffpills::detail {

// What every polygon type derives from its size(), vertex(i) and normal(j) (CRTP): the walk
// around the boundary and the edges. PolygonView and SubPolygon (sub_polygon.hpp) share it.
template <class Polygon>
class PolygonBoundary {
 public:
  Eigen::Index previous(Eigen::Index i) const { return i == 0 ? self().size() - 1 : i - 1; }
  Eigen::Index next(Eigen::Index i) const { return i + 1 == self().size() ? 0 : i + 1; }
  Eigen::Vector2d edge_start(Eigen::Index j) const { return self().vertex(previous(j)); }
  Eigen::Vector2d edge_end(Eigen::Index j) const { return self().vertex(j); }
  // The edge's unit direction, the outward normal turned a quarter counterclockwise.
  Eigen::Vector2d edge_direction(Eigen::Index j) const {
    const Eigen::Vector2d n = self().normal(j);
    return {-n.y(), n.x()};
  }
  // Edge j as a segment of the body frame (z = 0), its length without a square root.
  Segment edge(Eigen::Index j) const {
    const Eigen::Vector2d start = edge_start(j), end = edge_end(j);
    const Eigen::Vector2d middle = 0.5 * (start + end), direction = edge_direction(j);
    return {{middle.x(), middle.y(), 0.0},
            {direction.x(), direction.y(), 0.0},
            direction.dot(end - start)};
  }

 private:
  const Polygon& self() const { return static_cast<const Polygon&>(*this); }
};

// A polygon in the units of a query's frame (pair_frame.hpp): every length multiplied by `scale`,
// a power of two, so exactly. Nothing is copied.
class PolygonView : public PolygonBoundary<PolygonView> {
 public:
  PolygonView(const PaddedPolygon& polygon, double scale) : polygon_(&polygon), scale_(scale) {}

  Eigen::Index size() const { return polygon_->vertices().rows(); }  // vertices = edges
  Eigen::Vector2d vertex(Eigen::Index i) const {
    return {scale_ * polygon_->vertices()(i, 0), scale_ * polygon_->vertices()(i, 1)};
  }
  Eigen::Vector2d normal(Eigen::Index j) const {  // unit, outward
    return {polygon_->edge_normals()(j, 0), polygon_->edge_normals()(j, 1)};
  }
  double offset(Eigen::Index j) const { return scale_ * polygon_->edge_offsets()(j); }
  double extent() const { return scale_ * polygon_->extent(); }
  // Every edge of the polygon is one of its edges (a SubPolygon also has chords).
  bool is_edge(Eigen::Index) const { return true; }

 private:
  const PaddedPolygon* polygon_;
  double scale_;
};

// The rows of a polygon grown by a slack s meet beyond a vertex of interior angle a at s / sin(a /
// 2) from it: near a spike (a sliver's apex, a ~ 1e-16) that is far more than s, and "within the
// tolerance of the polygon" would take in points a whole scene away. So the grown polygon is also
// cut by a bevel at every vertex where the boundary turns by more than a quarter (its normals n_i,
// n_{i+1} at more than 90 degrees, a < 90): the row m . y <= m . v_i + s with m the unit bisector
// of the normals, which passes through the vertex and cuts nothing of the polygon itself. Grown
// rows and bevels then stay within s sqrt(2) of the polygon. n_i + n_{i+1} is exact where its
// components cancel (Sterbenz), so m is as accurate as the normals even for a ~1e-16 apex. Its
// length is normalized stably (scaled by its largest component first): at an apex of ~1e-172 its
// squared norm underflows to 0, and Eigen's normalized() then returns it unscaled, a bevel of
// length 1e-172 that cut nothing (fuzz_proximity: the interior-point reference's point 1.2 beyond
// such a needle's tip passed the check, phi 1.41 too small). Returns false where vertex i is no
// spike.
template <class Polygon>
bool spike_bevel(const Polygon& polygon, Eigen::Index i, Eigen::Vector2d& normal, double& offset) {
  const Eigen::Vector2d n = polygon.normal(i), next = polygon.normal(polygon.next(i));
  if (!(n.dot(next) < 0.0)) return false;
  normal = (n + next).stableNormalized();
  offset = normal.dot(polygon.vertex(i));
  return true;
}

// Where y is against the polygon and the polygon grown by `slack` >= 0 (every row n . y <= b +
// slack, and every spike's bevel, see above), in one pass over the rows: in the polygon itself,
// only in the grown one, or outside both. Polygon is a PolygonView or a SubPolygon
// (sub_polygon.hpp).
enum class Containment { kInside, kWithinSlack, kOutside };
template <class Polygon>
Containment containment(const Polygon& polygon, const Eigen::Vector2d& y, double slack) {
  bool beyond_a_row = false;
  const auto outside = [&](double height, double offset) {
    if (height > offset + slack) return true;
    beyond_a_row = beyond_a_row || height > offset;
    return false;
  };
  for (Eigen::Index j = 0; j < polygon.size(); ++j) {
    if (outside(polygon.normal(j).dot(y), polygon.offset(j))) return Containment::kOutside;
  }
  Eigen::Vector2d normal;
  double offset = 0.0;
  for (Eigen::Index i = 0; i < polygon.size(); ++i) {
    if (spike_bevel(polygon, i, normal, offset) && outside(normal.dot(y), offset)) {
      return Containment::kOutside;
    }
  }
  return beyond_a_row ? Containment::kWithinSlack : Containment::kInside;
}

// Is y in the polygon grown by `slack`?
template <class Polygon>
bool contains(const Polygon& polygon, const Eigen::Vector2d& y, double slack) {
  return containment(polygon, y, slack) != Containment::kOutside;
}

// The parameter interval {s in [0, 1] : y0 + s w in the polygon grown by `slack`} (Cyrus-Beck
// clipping, the spikes' bevels included as rows, see above); empty when the returned low > high.
// Each row n.(y0 + s w) <= b + slack bounds s from one side: s <= room / n.w when n.w > 0, from
// below when n.w < 0; a row parallel to w either holds for every s or for none.
template <class Polygon>
std::array<double, 2> clip_line(const Polygon& polygon, const Eigen::Vector2d& y0,
                                const Eigen::Vector2d& w, double slack) {
  double low = 0.0, high = 1.0;
  const auto clip = [&](const Eigen::Vector2d& n, double offset) {
    const double along = n.dot(w);
    const double room = offset + slack - n.dot(y0);
    if (along > 0.0) {
      high = std::min(high, room / along);
    } else if (along < 0.0) {
      low = std::max(low, room / along);
    } else if (room < 0.0) {
      low = 1.0, high = 0.0;
    }
  };
  for (Eigen::Index j = 0; j < polygon.size() && low <= high; ++j) {
    clip(polygon.normal(j), polygon.offset(j));
  }
  Eigen::Vector2d normal;
  double offset = 0.0;
  for (Eigen::Index i = 0; i < polygon.size() && low <= high; ++i) {
    if (spike_bevel(polygon, i, normal, offset)) clip(normal, offset);
  }
  return {low, high};
}

// The side of a polygon whose closest point is y: a face point (free in the body x-y plane), a
// point of edge j (free along it) or vertex j (fixed).
ClosestFeature face_point(const Eigen::Vector2d& y);
template <class Polygon>
ClosestFeature edge_point(const Polygon& polygon, Eigen::Index j, double t) {
  const Eigen::Vector2d start = polygon.edge_start(j), end = polygon.edge_end(j);
  const Eigen::Vector2d point = start + t * (end - start);
  if (t > 0.0 && t < 1.0 && !polygon.is_edge(j)) return face_point(point);  // inside a chord
  ClosestFeature side;
  side.body_point << point, 0.0;
  if (t > 0.0 && t < 1.0) {
    side.free_dimensions = 1;
    side.free_directions.col(0) << polygon.edge_direction(j), 0.0;
  }
  return side;
}

// The side of a capsule of `length` at `offset` from its middle (u = [offset, 0, 0], |offset| <=
// L / 2): free along its axis strictly inside, fixed at an end or for a sphere.
ClosestFeature segment_point_at(double length, double offset);
// The same at parameter s in [0, 1] (offset (s - 1/2) L).
inline ClosestFeature segment_point(double length, double s) {
  return segment_point_at(length, (s - 0.5) * length);
}

}  // namespace diffpills::detail
