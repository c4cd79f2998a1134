#include "separated_polygons.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

#include "depth_box_tree.hpp"
#include "nearest_on_segment.hpp"
#include "segment_bounds.hpp"

namespace diffpills::detail {

PolygonPairFrame::PolygonPairFrame(const PosedCore& a, const PosedCore& b)
    : PolygonPairFrame(a.attitude.matrix().transpose() * b.attitude.matrix(),
                       a.attitude.matrix().transpose() * (b.r - a.r)) {}

PolygonPairFrame::PolygonPairFrame(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& origin)
    : b_in_a(rotation), b_origin_in_a(origin), a_origin_in_b(-rotation.transpose() * origin) {}

namespace {

Eigen::Vector3d lift(const Eigen::Vector2d& y) { return {y.x(), y.y(), 0.0}; }

// What rules an edge pair out cheaply: two segments are at least |m1 - m2| - h1 - h2 apart (m the
// midpoints, h the half-lengths), and an edge of one polygon that does not cross the other's plane
// is at least its lower end's height above every point of the other (B's edges over A's plane, and
// in visit_all_pairs A's over B's, each a whole row of pairs). The two combine: with A in z = 0,
// the points' difference has a part along A's plane of at least |m1 - m2|_xy - h1 - h2 (projecting
// onto the plane shortens the edges) and a part across it of at least B's edge's height, so
//   distance^2 >= max(0, |m1 - m2|_xy - h1 - h2)^2 + height^2.
// Facing, nearly parallel faces need this one: there every pair's height is about the best
// distance, and the spheres' bound, which spends h1 + h2 of the margin in 3-D, let through every B
// edge within ~sqrt(2 (h1 + h2) d) of an A edge along the plane (~360 of two 10^5-gons' edges per
// A edge, 1 apart); this one only those within h1 + h2 + sqrt(2 d band).
struct EdgeBound {
  Eigen::Vector3d middle;
  double half_length = 0.0;
  double height = 0.0;
};

// The bound of an edge whose ends are at heights z_start and z_end over the other polygon's plane.
EdgeBound edge_bound(const Segment& edge, double z_start, double z_end) {
  const bool crosses = (z_start <= 0.0) != (z_end <= 0.0) || z_start == 0.0;
  return {edge.middle, 0.5 * edge.length,
          crosses ? 0.0 : std::min(std::abs(z_start), std::abs(z_end))};
}

// The bounds of B's edges (in A's frame; W: B's vertices there).
template <class Polygon>
SmallBuffer<EdgeBound> edge_bounds(const SmallBuffer<Segment>& edges,
                                   const CarriedPolygon<Polygon>& W) {
  SmallBuffer<EdgeBound> bounds(edges.size());
  for (Eigen::Index j = 0; j < edges.size(); ++j) {
    bounds[j] = edge_bound(edges[j], W.start(j).z(), W.end(j).z());
  }
  return bounds;
}

enum class Kind {
  kEdges,         // edge i of A at s, edge j of B at t (s, t = 1: the edges' end vertices)
  kBVertexOverA,  // vertex j of B over A's face
  kAVertexOverB,  // vertex i of A over B's face
  kBEdgeOverA,    // the point t of B's edge j over A's face (an interval's middle)
  kAEdgeOverB,    // the point s of A's edge i over B's face (an interval's middle)
};

struct Candidate {
  double distance2 = std::numeric_limits<double>::infinity();
  Kind kind = Kind::kEdges;
  Eigen::Index i = 0, j = 0;  // A's and B's feature
  double s = 1.0, t = 1.0;    // edge parameters
  // An interval's half lengths on A's side and on B's (in A's and B's body frames).
  double half_width_a = 0.0, half_width_b = 0.0;
};

// The best candidate and, apart, the best one standing for a whole interval of closest points,
// and the best vertex over the other's face.
//
// A vertex over the face, its polygon clear of the face's plane (beyond the intersection
// tolerance) and that vertex the nearest to it (offer_over_face), is a closest point: every point
// of its polygon is at least as far from the plane, so no pair is nearer. A pair that comes out
// nearer, within the tie tolerance, does so by rounding, and the vertex wins the tie. Far apart
// that matters: a unit 64-gon 1e8 above a square and tilted 1e-6 rad from it had its vertex tie
// with vertex-edge pairs up to sqrt(2 d ulp(d)) ~ 1.7 along the square, whichever rounding made
// nearest, and the square's point moved by 2 under rigid motions of the scene (a hostile review).
// So does such a vertex off the face by no more than its rounding, in its pair with the face's
// boundary (rim_pair): it may be over the face, and is then within rounding of a closest point.
struct Best {
  Candidate point, interval, vertex_over_face;
  void offer(const Candidate& candidate, bool is_interval) {
    Candidate& kept = is_interval ? interval : point;
    if (candidate.distance2 < kept.distance2) kept = candidate;
  }
  void offer_vertex_over_face(const Candidate& candidate) {
    offer(candidate, false);
    if (candidate.distance2 < vertex_over_face.distance2) vertex_over_face = candidate;
  }
  // The interval wins if it is as close as the point, and a tie within the tie tolerance tau (see
  // fast_paths.hpp) if the point's pair is one of the interval's: each of its two points within
  // the half width of the interval's middle on that side, give or take how far a pair within tau
  // of the optimum can be from the optimal set, sqrt(2 |d| tau) (the distance grows at least
  // quadratically, with curvature 1 / |d|, away from it; a pair 8.7e-6 apart, its planes 1e-5
  // rad apart, had its vertex 1.9e-11 beyond the interval's end), plus the intersection
  // tolerance. A tie in distance alone does not tell the same optimal set from another feature
  // at almost the same distance, which happens where the shapes are far apart compared to their
  // size (pair_frame.hpp). sides_of(candidate): its two sides, each in its body frame.
  template <class SidesOf>
  const Candidate& choice(double tolerance, double tie_tolerance, const SidesOf& sides_of) const {
    if (interval.distance2 <= point.distance2) return interval;
    const double reach = std::sqrt(point.distance2) + tie_tolerance;
    const Candidate& chosen_point =
        vertex_over_face.distance2 <= reach * reach ? vertex_over_face : point;
    if (interval.distance2 > reach * reach) return chosen_point;
    const std::array<ClosestFeature, 2> p = sides_of(chosen_point), i = sides_of(interval);
    const double slack = tolerance + std::sqrt(2.0 * std::sqrt(point.distance2) * tie_tolerance);
    const bool on_a = (p[0].body_point - i[0].body_point).norm() <= interval.half_width_a + slack;
    const bool on_b = (p[1].body_point - i[1].body_point).norm() <= interval.half_width_b + slack;
    return on_a && on_b ? interval : chosen_point;
  }
};

// A support vertex of `polygon` (carried into the frame of `over`, in z = 0) whose shadow y lies
// just off the face, paired with the face's nearest boundary point: edge e of the face at the
// parameter s nearest to y, and the vertex as the end (parameter 1) of its polygon's edge
// `support`. Its distance is the vertex's own, sqrt(z^2 + |y - boundary|^2).
template <class Over>
Candidate rim_pair(const Over& over, const Eigen::Vector3d& vertex, Eigen::Index support,
                   bool polygon_is_b) {
  const Eigen::Vector2d y = vertex.head<2>();
  double lateral2 = std::numeric_limits<double>::infinity(), along = 0.0;
  Eigen::Index edge = 0;
  for (Eigen::Index e = 0; e < over.size(); ++e) {
    const Eigen::Vector2d start = over.edge_start(e), end = over.edge_end(e);
    const double s = nearest_on_segment(y, start, end);
    const double apart2 = (start + s * (end - start) - y).squaredNorm();
    if (apart2 < lateral2) lateral2 = apart2, edge = e, along = s;
  }
  Candidate c;
  c.distance2 = vertex.z() * vertex.z() + lateral2;
  c.kind = Kind::kEdges;
  if (polygon_is_b) {
    c.i = edge, c.s = along, c.j = support, c.t = 1.0;
  } else {
    c.i = support, c.s = 1.0, c.j = edge, c.t = along;
  }
  return c;
}

// The vertices of `polygon` (carried into the other's frame, where the other lies in z = 0) that
// could be a closest point over the other's face: the lowest if the polygon lies above the plane,
// the highest if below. Only a support point in the direction of the plane can be closest over its
// interior (the closest pair's difference is then along the plane's normal and separates the two).
// Its neighbouring edges, if parallel to the plane (|sin| <= 1e-12) and over the face, are the
// interval version. `over` is the polygon lying in z = 0.
//
// "Above" is within the intersection tolerance: a polygon whose lowest vertex is at most that far
// below the plane counts as above it, the vertex as touching. Heights carry rounding of the
// scene's size, and a polygon touching the face with one vertex, its plane 7e-10 rad from the
// face's, has its other vertices within 1e-9 of the scene on both sides: rounding put the touching
// vertex just below, the polygon "met the plane", and no candidate was left over the face (the
// crossing-planes branch had missed the touch too: the section of nearly parallel planes is
// ill-conditioned), so the answer was a gap of 5e-10 of the scene in one order of the shapes and
// a touch in the other (found by fuzz_proximity). A polygon within the band on both sides offers
// both its lowest and its highest vertex.
template <class Polygon, class Over>
void offer_over_face(const CarriedPolygon<Polygon>& polygon, const Over& over, bool polygon_is_b,
                     double tolerance, Best& best) {
  // The extreme vertices by their rises (CarriedPolygon::rise), not by their heights: a rounded
  // rectangle 1 above the face and turned 1e-11 rad from it about its lower straight edge has its
  // corner's first vertices within an ulp of that edge in height (a rise of 3e-17 over 1), and
  // rounding made one of them the lowest; neither edge there is the straight one, and the answer
  // was that vertex, 0.8 from the edge's middle, in most rigid motions of the scene.
  Eigen::Index lowest = 0, highest = 0;
  double lowest_rise = polygon.rise(0), highest_rise = lowest_rise;
  for (Eigen::Index j = 1; j < polygon.size(); ++j) {
    const double rise = polygon.rise(j);
    if (rise < lowest_rise) lowest = j, lowest_rise = rise;
    if (rise > highest_rise) highest = j, highest_rise = rise;
  }
  const auto candidate = [&](Kind b_kind, Kind a_kind, Eigen::Index feature, double parameter,
                             double height, double half_width, double half_shadow) {
    Candidate c{height * height,
                polygon_is_b ? b_kind : a_kind,
                0,
                0,
                parameter,
                parameter,
                polygon_is_b ? half_shadow : half_width,
                polygon_is_b ? half_width : half_shadow};
    (polygon_is_b ? c.j : c.i) = feature;
    return c;
  };
  const auto offer_support = [&](Eigen::Index support) {
    const Eigen::Vector3d& vertex = polygon[support];
    // A support vertex over the face is a candidate at its height; one off the face by no more
    // than the rounding of its coordinates (CarriedPolygon::rounding), which cannot tell whether
    // it is over the face, is in the pair with the face's nearest boundary point (rim_pair), at
    // its true distance. Both win rounding ties (Best) when the polygon is clear of the plane.
    // Far apart that matters: a unit polygon 1e8 above a square with its lowest vertex 1e-10
    // from the square's edge (its coordinates round to 1.5e-8) came out just off the face under
    // some rigid motions of the scene, and then vertex-edge pairs up to ~1.4 along the rim tied
    // with the one below the vertex, and the square's point moved by 1.4 (a hostile review).
    // Only that rounding, and an honest pair: counted as over the face within the intersection
    // tolerance, a vertex 1e-12 beyond the edge and 2e-12 above the face got the face's normal,
    // 26 degrees off the pair's, and one 1e-12 above it was reported touching; and letting a
    // pair within a tie of the vertex's height win (off the face by up to sqrt(2 |z| tau)) put
    // the points 1e-5 of the scene from a unique closest pair of edges that the vertex's edge
    // makes over the face's (the reviews of those versions).
    const double z = std::abs(vertex.z());
    std::optional<Candidate> over_face;
    switch (containment(over, vertex.head<2>(), polygon.rounding())) {
      case Containment::kInside:
        over_face =
            candidate(Kind::kBVertexOverA, Kind::kAVertexOverB, support, 1.0, vertex.z(), 0.0, 0.0);
        break;
      case Containment::kWithinSlack:
        over_face = rim_pair(over, vertex, support, polygon_is_b);
        break;
      case Containment::kOutside:
        break;
    }
    if (over_face) {
      // A vertex within the intersection tolerance of the plane proves nothing beyond it (its
      // polygon may cross the plane by as much, and a pair that touches is as good): a sliver
      // touching a triangle had its vertex win under some rigid motions and a touching edge
      // pair under others, 0.17 apart (a hostile review's fuzzing).
      if (z > tolerance) {
        best.offer_vertex_over_face(*over_face);
      } else {
        best.offer(*over_face, false);
      }
    }
    // The two edges at the support vertex, each an interval of closest points if parallel to the
    // face (its part over the face, one candidate). Both can pass the test when the polygon's
    // plane is within a few 1e-12 rad of the face's (not parallel, or that branch would have
    // taken it). Then the clearly flatter one gives the interval, its slope at most half the
    // other's (an edge exactly parallel to the face, the optimal set, has a slope of rounding
    // beside its neighbour's >= 1e-14), and for slopes within a factor of two of each other
    // neither does: the vertex where they meet is the one closest point (a regular many-sided
    // polygon pointing its vertex down the slope). Compared by height, the lower interval
    // winning, two such intervals tied to rounding, and the points went with the order of the
    // shapes and with rigid motions (hostile reviews: a 133-gon and a 129-gon 6e-12 rad apart,
    // points 0.015 apart; an octagon tilted 1.2e-12 rad about an edge).
    const Eigen::Index following = support + 1 == polygon.size() ? 0 : support + 1;
    std::array<std::optional<Candidate>, 2> intervals;
    std::array<double, 2> slopes = {0.0, 0.0};
    for (std::size_t side = 0; side < 2; ++side) {
      const Eigen::Index j = side == 0 ? support : following;
      const Eigen::Vector3d& start = polygon.start(j);
      const Eigen::Vector3d& end = polygon.end(j);
      const double length = (end - start).norm();
      const double climb = std::abs(polygon.climb(j));
      if (climb > 1e-12 * length) continue;
      const auto [low, high] = clip_line(over, start.head<2>(), (end - start).head<2>(), tolerance);
      if (low <= high) {
        const double middle = 0.5 * (low + high);
        slopes[side] = climb / length;
        // The interval: a part of the polygon's edge, and its shadow on the face.
        const double half = 0.5 * (high - low);
        intervals[side] = candidate(Kind::kBEdgeOverA, Kind::kAEdgeOverB, j, middle,
                                    start.z() + middle * (end.z() - start.z()), half * length,
                                    half * (end - start).head<2>().norm());
      }
    }
    if (intervals[0] && intervals[1]) {
      if (slopes[0] <= 0.5 * slopes[1]) {
        best.offer(*intervals[0], true);
      } else if (slopes[1] <= 0.5 * slopes[0]) {
        best.offer(*intervals[1], true);
      }
      return;
    }
    for (const std::optional<Candidate>& interval : intervals) {
      if (interval) best.offer(*interval, true);
    }
  };
  const bool above = polygon[lowest].z() > -tolerance, below = polygon[highest].z() < tolerance;
  if (above) offer_support(lowest);
  if (below && !(above && highest == lowest)) offer_support(highest);
}

// The two sides of an over-face candidate: `other`'s vertex, or the point of its edge, over the
// face of the polygon in z = 0 of the frame `carried` is in. face_is_a: the face is shape a's.
template <class Other>
std::array<ClosestFeature, 2> over_face_sides(const Candidate& chosen, const Other& other,
                                              const CarriedPolygon<Other>& carried,
                                              bool face_is_a) {
  const Eigen::Index feature = face_is_a ? chosen.j : chosen.i;
  const double parameter = face_is_a ? chosen.t : chosen.s;
  const Eigen::Vector3d point =
      carried.start(feature) + parameter * (carried.end(feature) - carried.start(feature));
  const ClosestFeature on_face = face_point(point.head<2>());
  const ClosestFeature on_other = edge_point(other, feature, parameter);
  if (face_is_a) return {on_face, on_other};
  return {on_other, on_face};
}

// The two sides of a chosen candidate. A and B are PolygonView or SubPolygon, each with its
// vertices carried into the other's frame (W: B's in A's frame, X: A's in B's).
template <class Polygon>
std::array<ClosestFeature, 2> sides(const Candidate& chosen, const Polygon& a, const Polygon& b,
                                    const CarriedPolygon<Polygon>& W,
                                    const CarriedPolygon<Polygon>& X) {
  switch (chosen.kind) {
    case Kind::kBVertexOverA:
    case Kind::kBEdgeOverA:
      return over_face_sides(chosen, b, W, true);
    case Kind::kAVertexOverB:
    case Kind::kAEdgeOverB:
      return over_face_sides(chosen, a, X, false);
    case Kind::kEdges:
      break;
  }
  return {edge_point(a, chosen.i, chosen.s), edge_point(b, chosen.j, chosen.t)};
}

// Above this many vertex pairs, windows of polygon_windows.hpp are searched instead of visited
// all: see search_large_windows.
constexpr Eigen::Index kSearchLimit = Eigen::Index{32} * 32;

// The edge pair (edge i of A, B's edge `other` j) solved and offered; `reach` is the best point
// candidate's distance plus `band`, updated on an improvement.
void solve_edge_pair(const Segment& edge, Eigen::Index i, const Segment& other, Eigen::Index j,
                     double band, double& reach, Best& best) {
  const SegmentParameters closest = closest_segment_parameters(edge, other);
  const double distance2 = (edge.at(closest.s_offset) - other.at(closest.t_offset)).squaredNorm();
  // Parallel edges overlap along intervals of the same length on both.
  const double half_width = closest.half_overlap * edge.length;
  const double before = best.point.distance2;
  best.offer({distance2, Kind::kEdges, i, j, closest.s, closest.t, half_width, half_width},
             closest.overlap);
  if (best.point.distance2 < before) reach = std::sqrt(best.point.distance2) + band;
}

// The same, unless the cheap bounds rule it out: pairs are skipped only when a lower bound exceeds
// the best distance by `band`, so that an interval tying with the best point is still seen.
void offer_edge_pair(const Segment& edge, const EdgeBound& a_bound, Eigen::Index i,
                     const Segment& other, const EdgeBound& b_bound, Eigen::Index j, double band,
                     double& reach, Best& best) {
  // |m_a - m_b| - h_a - h_b >= reach  <=>  |m_a - m_b|^2 >= (reach + h_a + h_b)^2.
  const double half_lengths = a_bound.half_length + b_bound.half_length;
  const double far = reach + half_lengths;
  const Eigen::Vector3d apart = a_bound.middle - b_bound.middle;
  if (b_bound.height >= reach || apart.squaredNorm() >= far * far) return;
  // The bound along A's plane (EdgeBound): out when |m_a - m_b|_xy - h_a - h_b is at least
  // sqrt(reach^2 - height^2), compared squared (both sides positive).
  const double lateral =
      half_lengths + std::sqrt((reach - b_bound.height) * (reach + b_bound.height));
  if (apart.head<2>().squaredNorm() >= lateral * lateral) return;
  solve_edge_pair(edge, i, other, j, band, reach, best);
}

// Every edge pair (a vertex pair is an edge pair's ends), in index order: the small case,
// allocation-free up to 32 vertices. Only the pairs whose lower bound is below the best distance
// so far plus `band` reach the exact solver, the bound starting from an achievable distance:
// every pair within `band` of the closest, each one that the choice between a point and an
// interval can take (Best::choice; band is the tie tolerance, beyond which it takes none), so
// the answer does not depend on which bounds ruled the others out, and few others. On a CPU with
// vectors of 4 doubles or more the bounds are segment_bounds.hpp's, the pairs' distances to
// their margin (100 times the tolerance, far above their error) from the vector kernel, starting
// from the least of them: ~2 of a hexagon pair's 36 edge pairs are solved. With narrower vectors
// that kernel is slower than the scalar bounds it saves (hexagons, SSE4: 780-800 ns against
// ~700), and the bounds are the spheres around the edges, starting from the closest pair of
// vertices: ~7.5 pairs solved.
template <class Polygon>
void visit_all_pairs(const Polygon& a, const CarriedPolygon<Polygon>& W,
                     const CarriedPolygon<Polygon>& X, const SmallBuffer<Segment>& b_edges,
                     double tolerance, double band, Best& best) {
  const Eigen::Index ka = a.size(), kb = b_edges.size();
  SmallBuffer<Segment> a_edges(ka);
  for (Eigen::Index i = 0; i < ka; ++i) a_edges[i] = a.edge(i);
  if (segment_bounds_vectorized()) {
    SegmentColumns a_columns(ka), b_columns(kb);
    for (Eigen::Index i = 0; i < ka; ++i) a_columns.set(i, a_edges[i]);
    for (Eigen::Index j = 0; j < kb; ++j) b_columns.set(j, b_edges[j]);
    const Eigen::Index width = b_columns.padded_size();
    SmallBuffer<double, 32 * 32> lower(ka * width);
    const double least = segment_distance_bounds(a_columns, b_columns, lower.data());
    // The closest pair is at most the least d (a distance of two points of the edges) plus its
    // rounding, or the best candidate over a face.
    const double margin = 100.0 * tolerance;
    double reach = std::sqrt(std::min(least, best.point.distance2)) + margin + band;
    for (Eigen::Index i = 0; i < ka; ++i) {
      for (Eigen::Index j = 0; j < kb; ++j) {
        // sqrt(L) - margin < reach, squared (both sides positive).
        const double within = reach + margin;
        if (lower[i * width + j] < within * within) {
          solve_edge_pair(a_edges[i], i, b_edges[j], j, band, reach, best);
        }
      }
    }
    return;
  }
  double seed = best.point.distance2;
  for (Eigen::Index i = 0; i < ka; ++i) {
    const Eigen::Vector3d vertex = lift(a.vertex(i));
    for (Eigen::Index j = 0; j < kb; ++j) seed = std::min(seed, (vertex - W[j]).squaredNorm());
  }
  double reach = std::sqrt(seed) + band;
  const SmallBuffer<EdgeBound> b_bounds = edge_bounds(b_edges, W);
  for (Eigen::Index i = 0; i < ka; ++i) {
    // A's edge with its heights over B's plane (X: A's vertices in B's frame).
    const EdgeBound a_bound = edge_bound(a_edges[i], X.start(i).z(), X.end(i).z());
    if (a_bound.height >= reach) continue;  // the whole row
    for (Eigen::Index j = 0; j < kb; ++j) {
      offer_edge_pair(a_edges[i], a_bound, i, b_edges[j], b_bounds[j], j, band, reach, best);
    }
  }
}

// Large windows (above kSearchLimit vertex pairs, polygon_windows.hpp's on many-sided polygons):
// their point candidates are searched in depth_box_tree.hpp's hierarchies of their edge chains,
// whose bound holds a pair's depth and its offset across, in two frames: A's normal, in which A's
// chains have no depth and B's only their tilt (the closest pairs of faces over each other), and
// u, the unit direction between the windows' boxes (those to the side, and those far apart).
//
// Why hierarchies. Two sweeps were used here before, each bounding a pair by one part of its
// distance, and each left the pairs the other part decides in as ties, k^2 of them:
//   - along A's plane (the order of B's edges along the direction they spread in, with the height
//     every B edge keeps over A's plane): far apart, where every pair's distance is the distance V
//     between the polygons plus small terms (two 8,000-gons 1e13 times their size apart: 2.6 s);
//     and laid flat or coplanar, with the gap across the line between them (1000:1 ellipses, long
//     sides facing 500 apart in their plane: 1.4-1.8 s at 64,000 vertices, growing as k^1.8; a
//     hostile review);
//   - by depth along the line between the polygons: over A's face (4,000-gons 1e4 apart, 0.5 to
//     the side, tilted 1e-10 rad: 123 ms), and for faces 1e6 to 1e8 apart, tilted 1e-8 to 1e-6
//     rad and a few sizes to the side (16,000-gons 1e7 apart, 1e-6 rad, 2.5 aside: 175 ms).
// Measured on seven poses of unit 32,000-gons (1e4 to 1e8 apart, 1e-10 to 1e-5 rad, 0.5 to 10
// aside), the worst visited 544,000 edge pairs with u alone, 224,000 with A's normal alone and
// 51,000 with both.
//
// The band is 0: a point candidate is taken only if it is closer, never for a tie, so a pair
// that can only tie need not be solved. The tie band matters for intervals, which only parallel
// edges make; those are offer_parallel_edge_pairs'.
//
// Rounding: the depths are dot products with coordinates as large as the distance, so for polygons
// below ~1e-15 of it every depth is the same number to a few ulps, and a computed distance may
// exceed its bound by its own rounding: every pair would be solved (two 8,000-gons 1e30 times their
// size apart: 0.92 s; helper-4). For windows over 1,000 times their extents apart, and specks, a
// pair whose bound is within `slack` (16 ulps of the coordinates, about the rounding of any
// computed distance) of the best distance is a tie at rounding and is left out too. Nearer, the
// slack is 0 and the search returns the least computed distance: where the distance is nearly
// flat along the polygons (1000:1 ellipses 0.05 apart, turned 1e-8 rad about their long axis,
// their lowest points varying by 5e-12 x^2 along it), a slack of 16 ulps moved the point by
// sqrt(slack / 5e-12) = 0.04 along the flat, 6 times what the rounding of the heights does.
template <class Polygon>
void search_point_candidates(const Polygon& a, const CarriedPolygon<Polygon>& W,
                             const SmallBuffer<Segment>& b_edges, const Eigen::Vector3d& u,
                             double slack, Best& best) {
  DepthFrames frames;
  frames[0] << 0, 0, 1, 1, 0, 0, 0, 1, 0;  // A's normal, then A's x and y
  const Eigen::Vector3d e1 = u.unitOrthogonal();
  frames[1].row(0) = u;
  frames[1].row(1) = e1;
  frames[1].row(2) = u.cross(e1);
  const auto a_vertex = [&a](Eigen::Index i) { return lift(a.vertex(i)); };
  const auto b_vertex = [&W](Eigen::Index j) { return W[j]; };
  DepthBoxTree<decltype(a_vertex)> tree_a(a.size(), a_vertex, frames);
  DepthBoxTree<decltype(b_vertex)> tree_b(W.size(), b_vertex, frames);
  // A's edges are formed as the search meets them, once per leaf pair: a window's worth formed in
  // advance cost more in page faults than the search itself where it meets few (two 10^5-gons
  // 1e-11 rad from parallel).
  struct Pairs {
    const Polygon& a;
    const SmallBuffer<Segment>& b_edges;
    double slack;
    Best& best;
    double reach;
    double limit() const { return reach - slack; }
    void visit(Eigen::Index i, Eigen::Index first, Eigen::Index end) {
      const Segment edge = a.edge(i);
      for (Eigen::Index j = first; j < end; ++j) {
        solve_edge_pair(edge, i, b_edges[j], j, 0.0, reach, best);
      }
    }
  } pairs{a, b_edges, slack, best, std::sqrt(best.point.distance2)};
  search_close_edge_pairs(tree_a, tree_b, pairs);
}

// An edge direction's angle in A's plane modulo a half turn, in [0, pi): parallel edges, of
// either sense, have the same one.
constexpr double kHalfTurn = EIGEN_PI;
double half_turn_angle(const Eigen::Vector3d& direction) {
  double angle = std::atan2(direction.y(), direction.x());
  if (angle < 0.0) angle += kHalfTurn;
  return angle >= kHalfTurn ? angle - kHalfTurn : angle;
}

// The interval candidates of large windows: the pairs of parallel edges (closest_segment_
// parameters' test, |u x v| <= 1e-12) within the tie band of the best point. Edge i of A (in
// A's plane, u = (ux, uy, 0)) and edge j of B (v) have
//   |u x v|^2 = vz^2 + (ux vy - uy vx)^2,
// so a parallel pair has |vz| <= 1e-12 (B's edge along A's plane) and the angles of u and of v's
// part along the plane within asin(1e-12 / |v_xy|) of each other modulo a half turn. B's edges
// with |vz| <= kParallel are sorted by that angle and each A edge takes those within kParallel of
// its own: windows twice as wide as the test's (the directions' rounding and atan2's are a few
// ulps), so that no parallel pair is missed; the solver decides each pair taken. A convex polygon's
// edges turn monotonically, so each A edge meets a few B edges (one or two for regular polygons),
// where the sweep that took every pair with a B edge along A's plane within the band met the whole
// tie set (1000:1 ellipses 500 apart in their plane: ~400,000 pairs at 64,000 vertices, all ties).
template <class Polygon>
void offer_parallel_edge_pairs(const Polygon& a, const CarriedPolygon<Polygon>& W,
                               const SmallBuffer<Segment>& b_edges, double band, Best& best) {
  constexpr double kParallel = 2e-12;
  double reach = std::sqrt(best.point.distance2) + band;
  // B's edges along A's plane, less those whose height over it is beyond the reach (their bound
  // rules out every pair; nearly parallel faces keep a few), by angle (then index).
  struct AlongPlane {
    double angle;
    Eigen::Index j;
    EdgeBound bound;
  };
  std::vector<AlongPlane> along_plane;
  for (Eigen::Index j = 0; j < b_edges.size(); ++j) {
    if (std::abs(b_edges[j].direction.z()) > kParallel) continue;
    const EdgeBound bound = edge_bound(b_edges[j], W.start(j).z(), W.end(j).z());
    if (bound.height < reach)
      along_plane.push_back({half_turn_angle(b_edges[j].direction), j, bound});
  }
  if (along_plane.empty()) return;
  const auto by_angle = [](const AlongPlane& x, const AlongPlane& y) {
    return x.angle < y.angle || (x.angle == y.angle && x.j < y.j);
  };
  std::sort(along_plane.begin(), along_plane.end(), by_angle);
  const auto offer_between = [&](const Segment& edge, Eigen::Index i, const EdgeBound& a_bound,
                                 double low, double high) {
    auto it = std::lower_bound(along_plane.begin(), along_plane.end(), low,
                               [](const AlongPlane& x, double value) { return x.angle < value; });
    for (; it != along_plane.end() && it->angle <= high; ++it) {
      offer_edge_pair(edge, a_bound, i, b_edges[it->j], it->bound, it->j, band, reach, best);
    }
  };
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    const Segment edge = a.edge(i);
    const EdgeBound a_bound = edge_bound(edge, 0.0, 0.0);  // its height is not used
    const double angle = half_turn_angle(edge.direction);
    offer_between(edge, i, a_bound, angle - kParallel, angle + kParallel);
    // The window wrapped around the half turn.
    if (angle - kParallel < 0.0) {
      offer_between(edge, i, a_bound, angle - kParallel + kHalfTurn, kHalfTurn);
    }
    if (angle + kParallel >= kHalfTurn) {
      offer_between(edge, i, a_bound, 0.0, angle + kParallel - kHalfTurn);
    }
  }
}

// The candidates of large windows: every closer point, by the hierarchies, then every interval
// within the band. Specks (both windows within 1,000 intersection tolerances, 1e-9 of the scene:
// cores below 1e-100 of the frame's units keep its tolerances, pair_frame.hpp) get no band: ties
// at the tolerance span them whole.
template <class Polygon>
void search_large_windows(const Polygon& a, const CarriedPolygon<Polygon>& W,
                          const SmallBuffer<Segment>& b_edges, double tolerance,
                          double tie_tolerance, Best& best) {
  Eigen::AlignedBox3d box_a, box_b;
  for (Eigen::Index i = 0; i < a.size(); ++i) box_a.extend(lift(a.vertex(i)));
  for (Eigen::Index j = 0; j < W.size(); ++j) box_b.extend(W[j]);
  const Eigen::Vector3d apart = box_b.center() - box_a.center();
  const double extents = box_a.diagonal().norm() + box_b.diagonal().norm();
  // The direction between the boxes, normalized by its largest part first (stableNormalized), so
  // that windows of specks far below the frame's units (1e-154 and less) still have a unit one.
  // Boxes with the same centre (no direction between them) take A's normal.
  const Eigen::Vector3d u =
      apart == Eigen::Vector3d::Zero() ? Eigen::Vector3d::UnitZ() : apart.stableNormalized();
  const bool specks = extents <= 1e3 * tolerance;
  const bool far = apart.norm() > 1e3 * extents;
  const double slack =
      specks || far ? 16 * std::numeric_limits<double>::epsilon() * (apart.norm() + extents) : 0.0;
  search_point_candidates(a, W, b_edges, u, slack, best);
  if (!specks) offer_parallel_edge_pairs(a, W, b_edges, tie_tolerance, best);
}

template <class Polygon>
std::array<ClosestFeature, 2> enumerate(const Polygon& a, const Polygon& b,
                                        const PolygonPairFrame& frame,
                                        const CarriedPolygon<Polygon>& W,
                                        const CarriedPolygon<Polygon>& X, double tolerance,
                                        double tie_tolerance) {
  const Eigen::Index kb = b.size();
  Best best;
  offer_over_face(W, a, true, tolerance, best);
  offer_over_face(X, b, false, tolerance, best);
  // B's edges in A's frame.
  SmallBuffer<Segment> b_edges(kb);
  for (Eigen::Index j = 0; j < kb; ++j) {
    const Segment edge = b.edge(j);
    b_edges[j] = {0.5 * (W.start(j) + W.end(j)), frame.b_in_a * edge.direction, edge.length};
  }
  // Whole polygons (PolygonView) always get every pair: the fast path sends only small ones here,
  // and the tests compare the windows with this full enumeration.
  if (std::is_same_v<Polygon, SubPolygon> && a.size() * kb > kSearchLimit) {
    search_large_windows(a, W, b_edges, tolerance, tie_tolerance, best);
  } else {
    visit_all_pairs(a, W, X, b_edges, tolerance, tie_tolerance, best);
  }
  const auto sides_of = [&](const Candidate& c) { return sides(c, a, b, W, X); };
  return sides(best.choice(tolerance, tie_tolerance, sides_of), a, b, W, X);
}

}  // namespace

std::array<ClosestFeature, 2> closest_separated(const PolygonView& a, const PolygonView& b,
                                                const PolygonPairFrame& frame,
                                                const CarriedPolygon<PolygonView>& W,
                                                const CarriedPolygon<PolygonView>& X,
                                                double tolerance, double tie_tolerance) {
  return enumerate(a, b, frame, W, X, tolerance, tie_tolerance);
}

std::array<ClosestFeature, 2> closest_separated(const SubPolygon& a, const SubPolygon& b,
                                                const PolygonPairFrame& frame,
                                                const CarriedPolygon<SubPolygon>& W,
                                                const CarriedPolygon<SubPolygon>& X,
                                                double tolerance, double tie_tolerance) {
  return enumerate(a, b, frame, W, X, tolerance, tie_tolerance);
}

bool closest_over_face(const PolygonView& face, const SubPolygon& other,
                       const CarriedPolygon<SubPolygon>& carried, bool face_is_a, double tolerance,
                       double tie_tolerance, std::array<ClosestFeature, 2>& out) {
  Best best;
  offer_over_face(carried, face, face_is_a, tolerance, best);
  const auto sides_of = [&](const Candidate& c) -> std::array<ClosestFeature, 2> {
    if (c.kind != Kind::kEdges) return over_face_sides(c, other, carried, face_is_a);
    if (face_is_a) return {edge_point(face, c.i, c.s), edge_point(other, c.j, c.t)};
    return {edge_point(other, c.i, c.s), edge_point(face, c.j, c.t)};
  };
  const Candidate& chosen = best.choice(tolerance, tie_tolerance, sides_of);
  // A support just off the face (rim_pair) is on its boundary too: the caller then takes the
  // whole face into its window, and the enumeration weighs that pair against the face's edges.
  if (chosen.distance2 == std::numeric_limits<double>::infinity() || chosen.kind == Kind::kEdges) {
    return false;
  }
  out = over_face_sides(chosen, other, carried, face_is_a);
  return true;
}

}  // namespace diffpills::detail
