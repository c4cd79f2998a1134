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

// One polygon's vertices in the other's body frame: on the stack for up to 32 vertices.
class TransformedVertices {
 public:
  TransformedVertices(const PaddedPolygon& polygon, const Eigen::Matrix3d& rotation,
                      const Eigen::Vector3d& translation)
      : count_(polygon.vertices().rows()) {
    if (count_ > kInline) heap_.resize(static_cast<std::size_t>(count_));
    for (Eigen::Index i = 0; i < count_; ++i) {
      (*this)[i] = rotation.leftCols<2>() * polygon.vertices().row(i).transpose() + translation;
    }
  }
  Eigen::Vector3d& operator[](Eigen::Index i) {
    return count_ > kInline ? heap_[static_cast<std::size_t>(i)]
                            : inline_[static_cast<std::size_t>(i)];
  }
  // Start and end of edge j (edge j runs from vertex j - 1 to vertex j).
  Eigen::Vector3d& start(Eigen::Index j) { return (*this)[(j + count_ - 1) % count_]; }
  Eigen::Vector3d& end(Eigen::Index j) { return (*this)[j]; }

 private:
  static constexpr Eigen::Index kInline = 32;
  Eigen::Index count_;
  std::array<Eigen::Vector3d, kInline> inline_;
  std::vector<Eigen::Vector3d> heap_;
};

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
  const Eigen::Matrix3d b_in_a = posed_a.rotation.transpose() * posed_b.rotation;
  const Eigen::Vector3d b_origin_in_a = posed_a.rotation.transpose() * (posed_b.r - posed_a.r);
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
    for (Eigen::Index j = 0; j < kb; ++j) shadow.push_back(W[j].head<2>());
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

  double best = std::numeric_limits<double>::infinity();
  std::array<CoreSolution, 2> sides;
  for (Eigen::Index j = 0; j < kb; ++j) {  // B's vertices over A's face
    if (W[j].z() * W[j].z() < best && contains(a, W[j].head<2>())) {
      best = W[j].z() * W[j].z();
      sides = {face_point(W[j].head<2>()), edge_point(b, j, 1.0)};
    }
  }
  for (Eigen::Index i = 0; i < ka; ++i) {  // A's vertices over B's face
    if (X[i].z() * X[i].z() < best && contains(b, X[i].head<2>())) {
      best = X[i].z() * X[i].z();
      sides = {edge_point(a, i, 1.0), face_point(X[i].head<2>())};
    }
  }
  for (Eigen::Index i = 0; i < ka; ++i) {  // edge against edge
    const Eigen::Vector3d start = lift(edge_start(a, i));
    const Eigen::Vector3d edge = lift(edge_end(a, i)) - start;
    for (Eigen::Index j = 0; j < kb; ++j) {
      const Eigen::Vector3d other_edge = W.end(j) - W.start(j);
      const SegmentParameters closest =
          closest_segment_parameters(start, edge, W.start(j), other_edge);
      const double distance2 =
          (start + closest.s * edge - W.start(j) - closest.t * other_edge).squaredNorm();
      if (distance2 < best) {
        best = distance2;
        sides = {edge_point(a, i, closest.s), edge_point(b, j, closest.t)};
      }
    }
  }
  return sides;
}

}  // namespace diffpills::detail
