#include "polygon_features.hpp"

#include <algorithm>
#include <cmath>

namespace diffpills::detail {

Eigen::Vector2d edge_start(const PaddedPolygon& polygon, Eigen::Index j) {
  const Eigen::Index k = polygon.vertices().rows();
  return polygon.vertices().row((j + k - 1) % k).transpose();
}

Eigen::Vector2d edge_end(const PaddedPolygon& polygon, Eigen::Index j) {
  return polygon.vertices().row(j).transpose();
}

bool contains(const PaddedPolygon& polygon, const Eigen::Vector2d& y) {
  const auto& normals = polygon.edge_normals();
  const auto& offsets = polygon.edge_offsets();
  for (Eigen::Index j = 0; j < normals.rows(); ++j) {
    if (normals(j, 0) * y.x() + normals(j, 1) * y.y() > offsets(j)) return false;
  }
  return true;
}

// Each row n.(y0 + s w) <= b bounds s from one side: s <= (b - n.y0) / n.w when n.w > 0, from
// below when n.w < 0; a row parallel to w either holds for every s or for none.
std::array<double, 2> clip_line(const PaddedPolygon& polygon, const Eigen::Vector2d& y0,
                                const Eigen::Vector2d& w) {
  double low = 0.0, high = 1.0;
  const auto& normals = polygon.edge_normals();
  const auto& offsets = polygon.edge_offsets();
  for (Eigen::Index j = 0; j < normals.rows() && low <= high; ++j) {
    const double along = normals(j, 0) * w.x() + normals(j, 1) * w.y();
    const double room = offsets(j) - (normals(j, 0) * y0.x() + normals(j, 1) * y0.y());
    if (along > 0.0) {
      high = std::min(high, room / along);
    } else if (along < 0.0) {
      low = std::max(low, room / along);
    } else if (room < 0.0) {
      return {1.0, 0.0};
    }
  }
  return {low, high};
}

// Sutherland-Hodgman: clip `other` by each of the polygon's half-planes in turn, then the
// centroid of the clipped polygon, sum over its fan triangles of area * (a + b + c) / 3.
bool overlap_centre(const PaddedPolygon& polygon, const std::vector<Eigen::Vector2d>& other,
                    Eigen::Vector2d& centre) {
  std::vector<Eigen::Vector2d> region = other, next;
  const auto& normals = polygon.edge_normals();
  const auto& offsets = polygon.edge_offsets();
  for (Eigen::Index j = 0; j < normals.rows() && !region.empty(); ++j) {
    const Eigen::Vector2d n = normals.row(j).transpose();
    next.clear();
    for (std::size_t i = 0; i < region.size(); ++i) {
      const Eigen::Vector2d& a = region[i];
      const Eigen::Vector2d& b = region[(i + 1) % region.size()];
      const double da = n.dot(a) - offsets(j), db = n.dot(b) - offsets(j);
      if (da <= 0.0) next.push_back(a);
      if ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) {
        next.emplace_back(a + (da / (da - db)) * (b - a));
      }
    }
    region.swap(next);
  }
  if (region.empty()) return false;
  double area = 0.0;
  Eigen::Vector2d weighted = Eigen::Vector2d::Zero(), mean = Eigen::Vector2d::Zero();
  double size = 0.0;
  for (std::size_t i = 0; i < region.size(); ++i) {
    mean += region[i];
    size = std::max(size, (region[i] - region[0]).norm());
    if (i + 2 < region.size()) {
      const Eigen::Vector2d u = region[i + 1] - region[0], v = region[i + 2] - region[0];
      const double triangle = 0.5 * (u.x() * v.y() - u.y() * v.x());
      area += triangle;
      weighted += triangle * (region[0] + region[i + 1] + region[i + 2]) / 3.0;
    }
  }
  // A region thinner than 1e-12 of its own diameter has no usable centroid: use the vertex mean.
  centre = area > 1e-12 * size * size ? Eigen::Vector2d(weighted / area)
                                      : Eigen::Vector2d(mean / static_cast<double>(region.size()));
  return true;
}

CoreSolution face_point(const Eigen::Vector2d& y) {
  CoreSolution side;
  side.body_point << y, 0.0;
  side.free_dimensions = 2;
  side.free_directions.col(0) = Eigen::Vector3d::UnitX();
  side.free_directions.col(1) = Eigen::Vector3d::UnitY();
  return side;
}

CoreSolution edge_point(const PaddedPolygon& polygon, Eigen::Index j, double t) {
  const Eigen::Vector2d start = edge_start(polygon, j), end = edge_end(polygon, j);
  CoreSolution side;
  side.body_point << start + t * (end - start), 0.0;
  if (t > 0.0 && t < 1.0) {
    side.free_dimensions = 1;
    side.free_directions.col(0) << (end - start).normalized(), 0.0;
  }
  return side;
}

CoreSolution segment_point(double length, double s) {
  CoreSolution side;
  side.body_point.x() = (s - 0.5) * length;
  if (length > 0.0 && s > 0.0 && s < 1.0) {
    side.free_dimensions = 1;
    side.free_directions.col(0) = Eigen::Vector3d::UnitX();
  }
  return side;
}

}  // namespace diffpills::detail
