// A core as a polytope in a query's frame (pair_frame.hpp): its vertices, its edges and, for a
// polygon, its face normal, all in the frame's coordinates. The signed distance's penetration
// search (penetration.hpp) reads cores this way; the result builder reads the body-frame
// features (ClosestFeature) it hands back.
//
// A capsule's segment has its two ends as vertices 0 (s = 0) and 1 (s = 1) and one edge from
// vertex 0 to vertex 1; a sphere (length 0) has one vertex and no edge. A polygon has its
// vertices counterclockwise and edge j from vertex j - 1 to vertex j (polygon_features.hpp).
#pragma once

#include <Eigen/Core>

#include "polygon_features.hpp"
#include "posed_core.hpp"
#include "small_buffer.hpp"

namespace diffpills::detail {

struct OutlineEdge {
  Eigen::Vector3d start;
  Eigen::Vector3d direction;  // unit
  double length = 0.0;
  // A polygon edge's outward normal in the polygon's plane (unit); zero for a segment.
  Eigen::Vector3d outward = Eigen::Vector3d::Zero();
};

class CoreOutline {
 public:
  // The capsule's segment; `posed` must outlive the outline.
  explicit CoreOutline(const PosedCore& posed);
  // The polygon; `polygon` and `posed` must outlive the outline. No allocation up to 32 vertices.
  CoreOutline(const PolygonView& polygon, const PosedCore& posed);

  bool is_polygon() const { return polygon_ != nullptr; }
  const PolygonView& polygon() const { return *polygon_; }  // polygons only
  const PosedCore& posed() const { return *posed_; }
  // Q e_z: a polygon's normal; perpendicular to a capsule's axis Q e_x.
  Eigen::Vector3d face_normal() const { return posed_->attitude.matrix().col(2); }

  Eigen::Index vertex_count() const { return vertices_.size(); }
  const Eigen::Vector3d& vertex(Eigen::Index i) const { return vertices_[i]; }
  Eigen::Index edge_count() const { return edges_.size(); }
  const OutlineEdge& edge(Eigen::Index j) const { return edges_[j]; }
  // The support value max_i n . vertex(i).
  double support(const Eigen::Vector3d& n) const;

  // The features as the result builder wants them: vertex i, the point at parameter t of edge j
  // (free along it for 0 < t < 1), a point of the face (polygons only), given in the frame.
  ClosestFeature vertex_side(Eigen::Index i) const;
  ClosestFeature edge_side(Eigen::Index j, double t) const;
  ClosestFeature face_side(const Eigen::Vector3d& point) const;

 private:
  const PosedCore* posed_;
  const PolygonView* polygon_ = nullptr;
  SmallBuffer<Eigen::Vector3d> vertices_;
  SmallBuffer<OutlineEdge> edges_;
};

}  // namespace diffpills::detail
