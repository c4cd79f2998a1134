#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "diffpills/shapes.hpp"
#include "validation.hpp"

namespace diffpills {
namespace {

struct DualPoint {
  Eigen::Vector2d point;  // unit normal / offset
  int row;                // index into the normalized rows
};

// z-component of (b - a) x (c - a): > 0 when a, b, c turn counterclockwise.
double turn(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const Eigen::Vector2d u = b - a;
  const Eigen::Vector2d v = c - a;
  return u.x() * v.y() - u.y() * v.x();
}

// Andrew's monotone chain: the strictly convex hull, counterclockwise. A middle point b is dropped
// when it lies within 1e-12 * size of the chord from a to c (turn(a, b, c) = |c - a| times that
// distance): a dual point on or near a hull edge is a row through an existing vertex, and
// duplicates that differ by rounding (a row given twice at different scales) would otherwise
// survive as a sliver edge whose vertex lies near infinity.
std::vector<DualPoint> convex_hull(std::vector<DualPoint> points) {
  double size = 0.0;
  for (const DualPoint& p : points) size = std::max(size, p.point.norm());
  const auto keeps_convexity = [size](const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                                      const Eigen::Vector2d& c) {
    return turn(a, b, c) > 1e-12 * size * (c - a).norm();
  };
  std::sort(points.begin(), points.end(), [](const DualPoint& a, const DualPoint& b) {
    return a.point.x() < b.point.x() || (a.point.x() == b.point.x() && a.point.y() < b.point.y());
  });
  if (points.size() < 3) {
    return points;
  }
  std::vector<DualPoint> hull(2 * points.size());
  std::size_t k = 0;
  for (const DualPoint& p : points) {  // lower hull
    while (k >= 2 && !keeps_convexity(hull[k - 2].point, hull[k - 1].point, p.point)) {
      --k;
    }
    hull[k++] = p;
  }
  const std::size_t lower_size = k + 1;
  for (auto it = points.rbegin() + 1; it != points.rend(); ++it) {  // upper hull
    while (k >= lower_size && !keeps_convexity(hull[k - 2].point, hull[k - 1].point, it->point)) {
      --k;
    }
    hull[k++] = *it;
  }
  hull.resize(k - 1);  // the last point repeats the first
  return hull;
}

}  // namespace

PaddedPolygon::PaddedPolygon(const Eigen::MatrixX2d& C, const Eigen::VectorXd& d, double radius)
    : C_(C), d_(d), radius_(radius) {
  detail::require_nonnegative(radius, [] { return "polygon.radius"; });
  const Eigen::Index m = C.rows();
  if (m < 3) {
    detail::fail("polygon.C", "needs at least 3 rows (got " + std::to_string(m) + ")");
  }
  if (d.size() != m) {
    detail::fail("polygon.d", "must have one entry per row of C (C has " + std::to_string(m) +
                                  " rows, d has " + std::to_string(d.size()) + " entries)");
  }
  std::vector<DualPoint> dual;
  dual.reserve(static_cast<std::size_t>(m));
  std::vector<Eigen::Vector2d> unit_normals(static_cast<std::size_t>(m));
  std::vector<double> unit_offsets(static_cast<std::size_t>(m));
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto row = [i] { return "[" + std::to_string(i) + "]"; };
    detail::require_finite(C(i, 0), [&] { return "polygon.C" + row() + "[0]"; });
    detail::require_finite(C(i, 1), [&] { return "polygon.C" + row() + "[1]"; });
    detail::require_finite(d(i), [&] { return "polygon.d" + row(); });
    if (!(d(i) > 0.0)) {
      detail::fail("polygon.d" + row(),
                   "must be > 0 so that the body origin lies strictly inside the polygon (got " +
                       std::to_string(d(i)) + ")");
    }
    const double norm = C.row(i).norm();
    if (norm == 0.0) {
      continue;  // 0 <= d(i) holds everywhere: the row constrains nothing
    }
    const auto index = static_cast<std::size_t>(i);
    unit_normals[index] = C.row(i).transpose() / norm;
    unit_offsets[index] = d(i) / norm;
    dual.push_back({unit_normals[index] / unit_offsets[index], static_cast<int>(i)});
  }

  const std::vector<DualPoint> hull = convex_hull(dual);
  // Bounded <=> the origin is strictly inside the dual hull. The margin test is relative to the
  // hull's size so that it means the same at every scale: an origin within 1e-12 of the hull's
  // diameter from an edge is a polygon with a vertex near infinity, reported as unbounded.
  double hull_size = 0.0;
  for (const DualPoint& p : hull) {
    hull_size = std::max(hull_size, p.point.norm());
  }
  bool bounded = hull.size() >= 3;
  for (std::size_t i = 0; bounded && i < hull.size(); ++i) {
    const Eigen::Vector2d& a = hull[i].point;
    const Eigen::Vector2d& b = hull[(i + 1) % hull.size()].point;
    bounded = turn(a, b, Eigen::Vector2d::Zero()) > 1e-12 * (b - a).norm() * hull_size;
  }
  if (!bounded) {
    detail::fail("polygon.C", "the rows C y <= d do not bound a polygon (it is unbounded)");
  }

  const auto k = static_cast<Eigen::Index>(hull.size());
  normals_.resize(k, 2);
  offsets_.resize(k);
  vertices_.resize(k, 2);
  for (Eigen::Index i = 0; i < k; ++i) {
    const auto row = static_cast<std::size_t>(hull[static_cast<std::size_t>(i)].row);
    normals_.row(i) = unit_normals[row].transpose();
    offsets_(i) = unit_offsets[row];
  }
  // Vertex i solves n_i . y = b_i and n_j . y = b_j (j = i + 1) by Cramer's rule; the determinant
  // n_i x n_j is positive because consecutive hull normals turn counterclockwise by less than pi.
  for (Eigen::Index i = 0; i < k; ++i) {
    const Eigen::Index j = (i + 1) % k;
    const Eigen::Vector2d ni = normals_.row(i).transpose();
    const Eigen::Vector2d nj = normals_.row(j).transpose();
    const double det = ni.x() * nj.y() - ni.y() * nj.x();
    vertices_(i, 0) = (offsets_(i) * nj.y() - offsets_(j) * ni.y()) / det;
    vertices_(i, 1) = (ni.x() * offsets_(j) - nj.x() * offsets_(i)) / det;
    extent_ = std::max(extent_, vertices_.row(i).norm());
  }
  if (!(extent_ <= kMaxMagnitude)) {  // nearly parallel rows can put a vertex near infinity
    detail::fail("polygon.C", "a vertex lies farther than 1e100 from the origin");
  }
}

}  // namespace diffpills
