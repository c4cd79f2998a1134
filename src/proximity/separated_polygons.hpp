// The closest points of two polygons known not to intersect, by enumerating their features in
// the first polygon's body frame: the enumeration behind polygon_polygon.cpp, on whole polygons
// (PolygonView) or on windows of their vertices (SubPolygon, for polygon_windows.cpp).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <limits>

#include "polygon_features.hpp"
#include "posed_core.hpp"
#include "small_buffer.hpp"
#include "sub_polygon.hpp"

namespace diffpills::detail {

// Polygon B's placement in polygon A's body frame, and A's in B's.
struct PolygonPairFrame {
  PolygonPairFrame(const PosedCore& a, const PosedCore& b);
  // B's attitude (rotation) and body origin in A's frame given directly.
  PolygonPairFrame(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& origin);
  Eigen::Matrix3d b_in_a;         // rotation from B's body frame to A's
  Eigen::Vector3d b_origin_in_a;  // B's body origin in A's frame
  Eigen::Vector3d a_origin_in_b;  // A's body origin in B's frame
  // A point of A's frame in B's body x-y plane coordinates.
  Eigen::Vector2d in_b(const Eigen::Vector3d& point_in_a) const {
    return (b_in_a.transpose() * point_in_a + a_origin_in_b).head<2>();
  }
};

// One polygon's vertices carried into the other's body frame, x -> rotation [x; 0] + translation.
// Holds the polygon it was made from, which must outlive it.
template <class Polygon>
class CarriedPolygon {
 public:
  CarriedPolygon(const Polygon& polygon, const Eigen::Matrix3d& rotation,
                 const Eigen::Vector3d& translation)
      : polygon_(&polygon),
        rise_(rotation.template block<1, 2>(2, 0)),
        count_(polygon.size()),
        vertices_(count_) {
    double reach = 0.0;
    for (Eigen::Index i = 0; i < count_; ++i) {
      vertices_[i] = rotation.template leftCols<2>() * polygon.vertex(i) + translation;
      reach = std::max(reach, polygon.vertex(i).cwiseAbs().maxCoeff());
    }
    magnitude_ = translation.cwiseAbs().maxCoeff() + reach;
  }
  const Eigen::Vector3d& operator[](Eigen::Index i) const { return vertices_[i]; }
  // Vertex i's height turned but not translated: [vertex i].z() less the translation's z, without
  // the rounding of that sum. Heights of a polygon a distance h above the plane round to ulps of
  // h, and for one tilted 1e-11 rad from the plane that is more than the rise of the vertices next
  // to its lowest. The rises carry only the rounding of the rotation's row z, a few 1e-16 per unit
  // of the polygon's size whatever h is.
  double rise(Eigen::Index i) const { return rise_.dot(polygon_->vertex(i)); }
  // How far edge j climbs from its start to its end, from the rises.
  double climb(Eigen::Index j) const { return rise(j) - rise(j == 0 ? count_ - 1 : j - 1); }
  // Start and end of edge j (edge j runs from vertex j - 1 to vertex j).
  const Eigen::Vector3d& start(Eigen::Index j) const {
    return vertices_[j == 0 ? count_ - 1 : j - 1];
  }
  const Eigen::Vector3d& end(Eigen::Index j) const { return vertices_[j]; }
  Eigen::Index size() const { return count_; }
  // How far a carried vertex can be from where exact arithmetic puts it, generously: each
  // coordinate rounds to a few ulps of the translation plus the vertex (the rotation, the sum,
  // and the pose's own rounding from the frame), ~4 times less than this. A rigid motion of the
  // whole scene, rounded where the caller applies it, moves the vertex by ulps of the caller's
  // coordinates, which this covers only for scenes near the world origin (a scene 1e10 from it
  // and 1e8 across rounds at 1e10). 16 ulps of that magnitude.
  double rounding() const { return 16 * std::numeric_limits<double>::epsilon() * magnitude_; }

 private:
  const Polygon* polygon_;
  Eigen::RowVector2d rise_;  // the rotation's row z in the polygon's plane
  Eigen::Index count_;
  SmallBuffer<Eigen::Vector3d> vertices_;
  double magnitude_ = 0.0;  // the translation's largest coordinate plus the vertices'
};

// W: B's vertices carried into A's frame (frame.b_in_a), X: A's into B's. The candidates (see
// polygon_polygon.cpp): a support vertex of one over the other's face (or, for an edge parallel to
// that face, the middle of its part over it), and every pair of edges (the middle of their overlap
// when parallel), the pairs whose lower bound exceeds the best distance by the tie band skipped
// (the tie tolerance), up to 32 x 32 vertex pairs with segment_bounds.hpp's vector bounds where
// the CPU has 4 lanes. Windows larger than that are searched in depth_box_tree.hpp's hierarchies
// for every closer pair, and their pairs of parallel edges, the only ones that make an interval,
// are taken apart within the band. Candidates for a whole interval win ties within the tie
// tolerance (pair_frame.hpp), and a vertex over the other's face, its polygon clear of that plane,
// wins them against other pairs (it is a closest point; what ties with it does by rounding), as
// does its pair with the face's boundary when it lies off the face within its own rounding.
std::array<ClosestFeature, 2> closest_separated(const PolygonView& a, const PolygonView& b,
                                                const PolygonPairFrame& frame,
                                                const CarriedPolygon<PolygonView>& W,
                                                const CarriedPolygon<PolygonView>& X,
                                                double tolerance, double tie_tolerance);
std::array<ClosestFeature, 2> closest_separated(const SubPolygon& a, const SubPolygon& b,
                                                const PolygonPairFrame& frame,
                                                const CarriedPolygon<SubPolygon>& W,
                                                const CarriedPolygon<SubPolygon>& X,
                                                double tolerance, double tie_tolerance);

// When the face of one polygon is its whole support face (the closest points' difference is along
// its normal), the closest pairs are the other's support vertex over that face, or the middle of
// the part over it of a support edge parallel to it: the over-face candidates of the window
// `other` (carried into the face's frame) against the whole face. face_is_a: the face is shape
// a's. Returns false if no such candidate lies over the face (the pair is then on its boundary,
// also when the nearest support lies just off it).
bool closest_over_face(const PolygonView& face, const SubPolygon& other,
                       const CarriedPolygon<SubPolygon>& carried, bool face_is_a, double tolerance,
                       double tie_tolerance, std::array<ClosestFeature, 2>& out);

}  // namespace diffpills::detail
