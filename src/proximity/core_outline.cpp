#include "core_outline.hpp"

#include <algorithm>
#include <limits>

namespace diffpills::detail {

CoreOutline::CoreOutline(const PosedCore& posed)
    : posed_(&posed), vertices_(posed.size > 0.0 ? 2 : 1), edges_(posed.size > 0.0 ? 1 : 0) {
  const Eigen::Vector3d axis = posed.attitude.matrix().col(0);
  if (posed.size > 0.0) {
    vertices_[0] = posed.r - 0.5 * posed.size * axis;
    vertices_[1] = posed.r + 0.5 * posed.size * axis;
    edges_[0] = {vertices_[0], axis, posed.size, Eigen::Vector3d::Zero()};
  } else {
    vertices_[0] = posed.r;
  }
}

CoreOutline::CoreOutline(const PolygonView& polygon, const PosedCore& posed)
    : posed_(&posed), polygon_(&polygon), vertices_(polygon.size()), edges_(polygon.size()) {
  const Eigen::Matrix3d& R = posed.attitude.matrix();
  const auto lift = [&](const Eigen::Vector2d& y) -> Eigen::Vector3d {
    return R.leftCols<2>() * y;
  };
  for (Eigen::Index i = 0; i < polygon.size(); ++i)
    vertices_[i] = posed.r + lift(polygon.vertex(i));
  for (Eigen::Index j = 0; j < polygon.size(); ++j) {
    const Eigen::Vector2d direction = polygon.edge_direction(j);
    edges_[j] = {vertices_[polygon.previous(j)], lift(direction),
                 direction.dot(polygon.edge_end(j) - polygon.edge_start(j)),
                 lift(polygon.normal(j))};
  }
}

double CoreOutline::support(const Eigen::Vector3d& n) const {
  double best = -std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < vertices_.size(); ++i) best = std::max(best, n.dot(vertices_[i]));
  return best;
}

ClosestFeature CoreOutline::vertex_side(Eigen::Index i) const {
  if (!is_polygon()) return segment_point(posed_->size, vertices_.size() == 1 ? 0.5 : double(i));
  ClosestFeature side;
  side.body_point << polygon_->vertex(i), 0.0;
  return side;
}

ClosestFeature CoreOutline::edge_side(Eigen::Index j, double t) const {
  if (!is_polygon()) return segment_point(posed_->size, t);
  return edge_point(*polygon_, j, t);
}

ClosestFeature CoreOutline::face_side(const Eigen::Vector3d& point) const {
  return face_point((posed_->attitude.matrix().transpose() * (point - posed_->r)).head<2>());
}

}  // namespace diffpills::detail
