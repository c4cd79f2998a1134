#include "sub_polygon.hpp"

#include <utility>

namespace diffpills::detail {

// A real edge keeps the full polygon's normal; a chord's outward normal is its direction turned a
// quarter clockwise (the polygon runs counterclockwise). The chord is divided by its largest
// component before it is normalized: a polygon far smaller than the scene has vertices of order
// 1e-200 in the frame's units, whose squares underflow (Eigen's normalized() then returns the
// vector unchanged, and the row would hold every point). A chord between vertices that coincide
// in the frame gets the zero row 0 . y <= 0, which constrains nothing; polygon_windows.cpp takes
// a polygon that small whole, so that its windows have no such chord.
SubPolygon::SubPolygon(const PolygonView& full, std::vector<Eigen::Index> indices)
    : full_(&full), indices_(std::move(indices)) {
  normals_.resize(indices_.size());
  offsets_.resize(indices_.size());
  for (Eigen::Index j = 0; j < size(); ++j) {
    const auto index = static_cast<std::size_t>(j);
    if (is_edge(j)) {
      normals_[index] = full.normal(full_index(j));
      offsets_[index] = full.offset(full_index(j));
    } else {
      const Eigen::Vector2d chord = edge_end(j) - edge_start(j);
      const double largest = chord.lpNorm<Eigen::Infinity>();
      const Eigen::Vector2d direction =
          largest > 0.0 ? Eigen::Vector2d((chord / largest).normalized()) : Eigen::Vector2d::Zero();
      normals_[index] = Eigen::Vector2d(direction.y(), -direction.x());
      offsets_[index] = normals_[index].dot(edge_start(j));
    }
  }
}

}  // namespace diffpills::detail
