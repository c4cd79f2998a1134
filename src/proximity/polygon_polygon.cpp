#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "fast_paths.hpp"
#include "polygon_features.hpp"
#include "segment_segment.hpp"

namespace diffpills::detail {
namespace {

// A fixed-capacity array on the stack for up to 32 entries, on the heap beyond: polygons of
// common size cost no allocation per query.
template <class T>
class SmallBuffer {
 public:
  explicit SmallBuffer(Eigen::Index size) : size_(size) {
    if (size_ > kInline) heap_.resize(static_cast<std::size_t>(size_));
  }
  T& operator[](Eigen::Index i) {
    return size_ > kInline ? heap_[static_cast<std::size_t>(i)]
                           : inline_[static_cast<std::size_t>(i)];
  }

 private:
  static constexpr Eigen::Index kInline = 32;
  Eigen::Index size_;
  std::array<T, kInline> inline_;
  std::vector<T> heap_;
};

// One polygon's vertices carried into another frame, x -> rotation [x; 0] + translation.
class TransformedVertices {
 public:
  TransformedVertices(const PaddedPolygon& polygon, const Eigen::Matrix3d& rotation,
                      const Eigen::Vector3d& translation)
      : count_(polygon.vertices().rows()), points_(count_) {
    for (Eigen::Index i = 0; i < count_; ++i) {
      points_[i] = rotation.leftCols<2>() * polygon.vertices().row(i).transpose() + translation;
    }
  }
  Eigen::Vector3d& operator[](Eigen::Index i) { return points_[i]; }
  // Start and end of edge j (edge j runs from vertex j - 1 to vertex j).
  Eigen::Vector3d& start(Eigen::Index j) { return points_[(j + count_ - 1) % count_]; }
  Eigen::Vector3d& end(Eigen::Index j) { return points_[j]; }

 private:
  Eigen::Index count_;
  SmallBuffer<Eigen::Vector3d> points_;
};

// What rules an edge pair out cheaply: two segments are at least |m1 - m2| - h1 - h2 apart (m the
// midpoints, h the half-lengths), and an edge of B that does not cross A's plane is at least its
// lower end's height above every point of A.
struct EdgeBound {
  Eigen::Vector3d middle;
  double half_length = 0.0;
  double height = 0.0;
};

EdgeBound edge_bound(const Eigen::Vector3d& start, const Eigen::Vector3d& end) {
  const bool crosses = (start.z() <= 0.0) != (end.z() <= 0.0) || start.z() == 0.0;
  return {0.5 * (start + end), 0.5 * (end - start).norm(),
          crosses ? 0.0 : std::min(std::abs(start.z()), std::abs(end.z()))};
}

Eigen::Vector3d lift(const Eigen::Vector2d& y) { return {y.x(), y.y(), 0.0}; }

}  // namespace

// Everything happens in A's body frame, where A is {(y, 0) : y in A}, with B's vertices W_j
// carried over (and A's vertices X_i carried into B's frame for the symmetric tests). The closest
// pair is one of
//   - the intersection, where an edge of one crosses the other's plane inside it (distance zero);
//   - a vertex of one over the face of the other (distance |height|);
//   - an edge of each (segment_segment.hpp).
// Two degenerate sets of closest pairs get their middle:
//   - parallel planes (B's normal within |sin| <= 1e-12 of A's: heights vary linearly with a
//     tilt, so the threshold is on the sine) whose shadows overlap: every point of the overlap is
//     closest, and its area centroid is returned;
//   - crossing planes: the intersection is a segment along n_A x n_B whose ends are crossing
//     points; its midpoint is returned.
std::array<CoreSolution, 2> solve_polygon_polygon(const PaddedPolygon& a, const PosedCore& posed_a,
                                                  const PaddedPolygon& b,
                                                  const PosedCore& posed_b) {
  const Eigen::Matrix3d b_in_a = posed_a.attitude.matrix().transpose() * posed_b.attitude.matrix();
  const Eigen::Vector3d b_origin_in_a =
      posed_a.attitude.matrix().transpose() * (posed_b.r - posed_a.r);
  const Eigen::Vector3d a_origin_in_b = -b_in_a.transpose() * b_origin_in_a;
  TransformedVertices W(b, b_in_a, b_origin_in_a);
  TransformedVertices X(a, b_in_a.transpose(), a_origin_in_b);
  const auto in_b = [&](const Eigen::Vector3d& point_in_a) -> Eigen::Vector2d {
    return (b_in_a.transpose() * point_in_a + a_origin_in_b).head<2>();
  };
  const Eigen::Index ka = a.vertices().rows();
  const Eigen::Index kb = b.vertices().rows();
  const Eigen::Vector3d b_normal = b_in_a.col(2);

  if (b_normal.head<2>().norm() <= 1e-12) {
    std::vector<Eigen::Vector2d> shadow;  // B's outline seen from A's normal, counterclockwise
    for (Eigen::Index j = 0; j < kb; ++j) shadow.emplace_back(W[j].head<2>());
    if (b_normal.z() < 0.0) std::reverse(shadow.begin(), shadow.end());
    Eigen::Vector2d centre;
    if (overlap_centre(a, shadow, centre)) {
      return {face_point(centre), face_point(in_b(lift(centre)))};
    }
  }

  // Crossings, as points of A's plane, extremes kept along the intersection line.
  const Eigen::Vector3d line = Eigen::Vector3d::UnitZ().cross(b_normal);
  double low = std::numeric_limits<double>::infinity(), high = -low;
  Eigen::Vector3d low_point = Eigen::Vector3d::Zero(), high_point = Eigen::Vector3d::Zero();
  const auto add_crossing = [&](const Eigen::Vector3d& point) {
    const double along = line.dot(point);
    if (along < low) low = along, low_point = point;
    if (along > high) high = along, high_point = point;
  };
  for (Eigen::Index j = 0; j < kb; ++j) {
    const Eigen::Vector3d& s = W.start(j);
    const Eigen::Vector3d& e = W.end(j);
    if ((s.z() < 0.0 && e.z() > 0.0) || (s.z() > 0.0 && e.z() < 0.0)) {
      const Eigen::Vector3d crossing = s + (s.z() / (s.z() - e.z())) * (e - s);
      if (contains(a, crossing.head<2>())) add_crossing(lift(crossing.head<2>()));
    }
  }
  for (Eigen::Index i = 0; i < ka; ++i) {
    const Eigen::Vector3d& s = X.start(i);
    const Eigen::Vector3d& e = X.end(i);
    if ((s.z() < 0.0 && e.z() > 0.0) || (s.z() > 0.0 && e.z() < 0.0)) {
      const double t = s.z() / (s.z() - e.z());
      if (contains(b, (s + t * (e - s)).head<2>())) {
        add_crossing(lift(edge_start(a, i) + t * (edge_end(a, i) - edge_start(a, i))));
      }
    }
  }
  if (low <= high) {
    const Eigen::Vector3d middle = 0.5 * (low_point + high_point);
    return {face_point(middle.head<2>()), face_point(in_b(middle))};
  }

  // The closest pair among the remaining features, kept as indices until the end. The closest
  // pair of vertices seeds it: an achievable distance, so that the lower bounds below rule most
  // edge pairs out from the start.
  enum class Kind { kVertices, kBVertexOverA, kAVertexOverB, kEdges };
  struct Candidate {
    double distance2 = std::numeric_limits<double>::infinity();
    Kind kind = Kind::kVertices;
    Eigen::Index i = 0, j = 0;  // A's and B's feature
    double s = 1.0, t = 1.0;    // edge parameters (1 = the edge's end vertex)
  } best;
  for (Eigen::Index i = 0; i < ka; ++i) {
    const Eigen::Vector3d vertex = lift(a.vertices().row(i).transpose());
    for (Eigen::Index j = 0; j < kb; ++j) {
      const double distance2 = (vertex - W[j]).squaredNorm();
      if (distance2 < best.distance2) best = {distance2, Kind::kVertices, i, j, 1.0, 1.0};
    }
  }
  for (Eigen::Index j = 0; j < kb; ++j) {  // B's vertices over A's face
    if (W[j].z() * W[j].z() < best.distance2 && contains(a, W[j].head<2>())) {
      best = {W[j].z() * W[j].z(), Kind::kBVertexOverA, 0, j, 1.0, 1.0};
    }
  }
  for (Eigen::Index i = 0; i < ka; ++i) {  // A's vertices over B's face
    if (X[i].z() * X[i].z() < best.distance2 && contains(b, X[i].head<2>())) {
      best = {X[i].z() * X[i].z(), Kind::kAVertexOverB, i, 0, 1.0, 1.0};
    }
  }
  SmallBuffer<EdgeBound> b_bounds(kb);
  for (Eigen::Index j = 0; j < kb; ++j) b_bounds[j] = edge_bound(W.start(j), W.end(j));
  double best_distance = std::sqrt(best.distance2);
  for (Eigen::Index i = 0; i < ka; ++i) {  // edge against edge
    const Eigen::Vector3d start = lift(edge_start(a, i));
    const Eigen::Vector3d edge = lift(edge_end(a, i)) - start;
    const EdgeBound a_bound = edge_bound(start, start + edge);
    for (Eigen::Index j = 0; j < kb; ++j) {
      const EdgeBound& b_bound = b_bounds[j];
      // Skip when a lower bound reaches the best distance, compared without a square root:
      // |m_a - m_b| - h_a - h_b >= best  <=>  |m_a - m_b|^2 >= (best + h_a + h_b)^2.
      const double reach = best_distance + a_bound.half_length + b_bound.half_length;
      if (b_bound.height >= best_distance ||
          (a_bound.middle - b_bound.middle).squaredNorm() >= reach * reach) {
        continue;
      }
      const Eigen::Vector3d other_edge = W.end(j) - W.start(j);
      const SegmentParameters closest =
          closest_segment_parameters(start, edge, W.start(j), other_edge);
      const double distance2 =
          (start + closest.s * edge - W.start(j) - closest.t * other_edge).squaredNorm();
      if (distance2 < best.distance2) {
        best = {distance2, Kind::kEdges, i, j, closest.s, closest.t};
        best_distance = std::sqrt(distance2);
      }
    }
  }
  switch (best.kind) {
    case Kind::kBVertexOverA:
      return {face_point(W[best.j].head<2>()), edge_point(b, best.j, 1.0)};
    case Kind::kAVertexOverB:
      return {edge_point(a, best.i, 1.0), face_point(X[best.i].head<2>())};
    case Kind::kVertices:
    case Kind::kEdges:
      break;
  }
  return {edge_point(a, best.i, best.s), edge_point(b, best.j, best.t)};
}

}  // namespace diffpills::detail
