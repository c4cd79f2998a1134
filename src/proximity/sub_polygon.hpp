// The convex polygon spanned by some of a polygon's vertices (a window), for the large-polygon
// path of polygon_windows.cpp: the same accessors as PolygonView, in the same body frame, so that
// the feature enumeration runs on it unchanged. Its edges between vertices that are not
// neighbours in the full polygon are chords, which run through the full polygon's interior.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "polygon_features.hpp"
#include "segment_segment.hpp"

namespace diffpills::detail {

class SubPolygon : public PolygonBoundary<SubPolygon> {
 public:
  // `indices`: at least three of the full polygon's vertex indices, increasing (counterclockwise).
  SubPolygon(const PolygonView& full, std::vector<Eigen::Index> indices);

  Eigen::Index size() const { return static_cast<Eigen::Index>(indices_.size()); }
  Eigen::Vector2d vertex(Eigen::Index i) const { return full_->vertex(full_index(i)); }
  Eigen::Vector2d normal(Eigen::Index j) const { return normals_[static_cast<std::size_t>(j)]; }
  double offset(Eigen::Index j) const { return offsets_[static_cast<std::size_t>(j)]; }
  // Is edge j (from vertex j - 1 to vertex j) an edge of the full polygon, not a chord?
  bool is_edge(Eigen::Index j) const {
    return full_->next(full_index(previous(j))) == full_index(j);
  }
  // The full polygon's index of vertex i.
  Eigen::Index full_index(Eigen::Index i) const { return indices_[static_cast<std::size_t>(i)]; }

 private:
  const PolygonView* full_;
  std::vector<Eigen::Index> indices_;
  std::vector<Eigen::Vector2d> normals_;
  std::vector<double> offsets_;
};

}  // namespace diffpills::detail
