#include "convex_overlap.hpp"

#include <algorithm>
#include <cmath>

#include "small_buffer.hpp"

namespace diffpills::detail {
namespace {

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// The order of directions by angle in [0, 2 pi), without atan2: the upper half first, then the
// lower, each by the sign of the cross product.
bool angle_less(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const bool upper_a = a.y() > 0.0 || (a.y() == 0.0 && a.x() > 0.0);
  const bool upper_b = b.y() > 0.0 || (b.y() == 0.0 && b.x() > 0.0);
  if (upper_a != upper_b) return upper_a;
  return cross(a, b) > 0.0;
}

// The point where the boundary lines of a and b meet, for non-parallel a, b: on a's line,
// y = a.offset a.normal + t p with p = (-a.normal.y, a.normal.x) along it, and b.normal . y =
// b.offset gives
//   t = (b.offset - a.offset (a.normal . b.normal)) / (a.normal x b.normal).
// The point lies on a's line to rounding whatever the angle; only t, along the line, carries the
// error eps / angle. Cramer's rule, ((a.offset perp(b.normal) - b.offset perp(a.normal)) / (a x
// b)), divides an error of eps in every direction by the angle: for rows a few 1e-12 from
// parallel (two identical 51-gons turned a half turn against each other, 6e-12 rad) the corners
// left their lines by 2e-5, and the region's centroid moved by 8e-7 of its size, differently in
// the two orders of the shapes (found by fuzz_proximity).
Eigen::Vector2d meet(const HalfPlane& a, const HalfPlane& b) {
  const double t = (b.offset - a.offset * a.normal.dot(b.normal)) / cross(a.normal, b.normal);
  return a.offset * a.normal + t * Eigen::Vector2d(-a.normal.y(), a.normal.x());
}

bool outside(const HalfPlane& h, const Eigen::Vector2d& point) {
  return h.normal.dot(point) > h.offset;
}

// Boundary lines within 1e-12 of parallel: their meeting point is not usable.
bool parallel(const HalfPlane& a, const HalfPlane& b) {
  return std::abs(cross(a.normal, b.normal)) <= 1e-12;
}

// Both lists' half-planes and the box's 4, on the stack for two polygons of up to 32 vertices.
constexpr Eigen::Index kInlinePlanes = 2 * kInlineHalfPlanes + 4;

// Half-plane intersection by angle (the sort-and-sweep algorithm): half-planes sorted by the
// angle of their normal are pushed on a deque; before each push, half-planes at either end whose
// corner with their neighbour lies outside the new one are redundant and dropped. Four box
// half-planes around the first polygon keep every intermediate region bounded, so that consecutive
// normals on the deque always turn by less than pi unless the region is empty: a turn of pi or
// more (across the deque's ends too) reports it empty. Writes the region's vertices,
// counterclockwise, and returns their number (0: empty).
Eigen::Index intersect(SmallBuffer<HalfPlane, kInlinePlanes>& planes,
                       SmallBuffer<Eigen::Vector2d, kInlinePlanes>& out) {
  std::sort(planes.data(), planes.data() + planes.size(),
            [](const HalfPlane& a, const HalfPlane& b) { return angle_less(a.normal, b.normal); });
  SmallBuffer<HalfPlane, kInlinePlanes> deque(planes.size());
  Eigen::Index head = 0, tail = 0;  // the deque is deque[head, tail)
  for (Eigen::Index i = 0; i < planes.size(); ++i) {
    const HalfPlane& h = planes[i];
    if (tail > head && parallel(deque[tail - 1], h) && deque[tail - 1].normal.dot(h.normal) > 0.0) {
      if (h.offset >= deque[tail - 1].offset) continue;  // the tighter of two parallel rows binds
      --tail;
    }
    while (tail - head >= 2 && outside(h, meet(deque[tail - 2], deque[tail - 1]))) --tail;
    while (tail - head >= 2 && outside(h, meet(deque[head], deque[head + 1]))) ++head;
    // Opposite rows met, or the normal turned by pi or more: empty.
    if (tail > head &&
        (parallel(deque[tail - 1], h) || cross(deque[tail - 1].normal, h.normal) < 0.0)) {
      return 0;
    }
    deque[tail++] = h;
  }
  // Closing the loop: rows within 1e-12 of one direction can sit at both ends of the deque, one
  // just below the angle 2 pi and one at 0 (two polygons' rows of one direction, one of them
  // turned by -1e-158: found by fuzz_proximity, which got an empty overlap of parallel polygons in
  // one order of the shapes only); the tighter binds, as above. Then the ends' corners outside the
  // other end's row are dropped.
  while (tail - head >= 2) {
    const HalfPlane& last = deque[tail - 1];
    const HalfPlane& first = deque[head];
    if (parallel(last, first) && last.normal.dot(first.normal) > 0.0) {
      if (last.offset >= first.offset) {
        --tail;
      } else {
        ++head;
      }
    } else if (tail - head >= 3 && outside(first, meet(deque[tail - 2], last))) {
      --tail;
    } else if (tail - head >= 3 && outside(last, meet(first, deque[head + 1]))) {
      ++head;
    } else {
      break;
    }
  }
  if (tail - head < 3) return 0;
  Eigen::Index count = 0;
  for (Eigen::Index i = head; i < tail; ++i) {
    const HalfPlane& following = i + 1 < tail ? deque[i + 1] : deque[head];
    if (parallel(deque[i], following) || cross(deque[i].normal, following.normal) < 0.0) return 0;
    out[count++] = meet(deque[i], following);
  }
  return count;
}

// Area centroid by a fan from the first vertex (sum of triangle area times triangle centroid). A
// region whose width area / diameter is within 8 slack is a sliver along a touching edge (or a
// point): its longest extent's middle is returned instead, since the centroid of a sliver depends
// on the rounding that shaped it.
Eigen::Vector2d region_centre(const SmallBuffer<Eigen::Vector2d, kInlinePlanes>& vertices,
                              Eigen::Index count, double slack) {
  const Eigen::Vector2d& origin = vertices[0];
  Eigen::Index farthest = 0;
  double area = 0.0;
  Eigen::Vector2d weighted = Eigen::Vector2d::Zero();
  for (Eigen::Index i = 1; i < count; ++i) {
    const Eigen::Vector2d u = vertices[i] - origin;
    if (u.squaredNorm() > (vertices[farthest] - origin).squaredNorm()) farthest = i;
    if (i + 1 < count) {
      const Eigen::Vector2d v = vertices[i + 1] - origin;
      const double triangle = 0.5 * cross(u, v);
      area += triangle;
      weighted += triangle * (u + v) / 3.0;
    }
  }
  const Eigen::Vector2d axis = vertices[farthest] - origin;
  const double diameter = axis.norm();
  if (area > 8.0 * slack * diameter) return origin + weighted / area;
  if (diameter == 0.0) return origin;
  double low = 0.0, high = 0.0;  // extent along the axis, from the origin vertex
  for (Eigen::Index i = 1; i < count; ++i) {
    const double along = axis.dot(vertices[i] - origin);
    low = std::min(low, along), high = std::max(high, along);
  }
  return origin + (0.5 * (low + high) / (diameter * diameter)) * axis;
}

}  // namespace

bool overlap_centre(const HalfPlane* first, Eigen::Index first_count, double first_extent,
                    const HalfPlane* second, Eigen::Index second_count, double slack,
                    Eigen::Vector2d& centre) {
  SmallBuffer<HalfPlane, kInlinePlanes> planes(first_count + second_count + 4);
  Eigen::Index n = 0;
  for (Eigen::Index i = 0; i < first_count; ++i) {
    planes[n++] = {first[i].normal, first[i].offset + slack};
  }
  for (Eigen::Index i = 0; i < second_count; ++i) {
    planes[n++] = {second[i].normal, second[i].offset + slack};
  }
  // The box |x|, |y| <= 2 extent holds the first polygon grown by slack.
  const double box = 2.0 * (first_extent + slack);
  for (const Eigen::Vector2d& normal : {Eigen::Vector2d(1, 0), Eigen::Vector2d(0, 1),
                                        Eigen::Vector2d(-1, 0), Eigen::Vector2d(0, -1)}) {
    planes[n++] = {normal, box};
  }
  SmallBuffer<Eigen::Vector2d, kInlinePlanes> vertices(planes.size());
  const Eigen::Index count = intersect(planes, vertices);
  if (count == 0) return false;
  centre = region_centre(vertices, count, slack);
  // The sweep decides by the sides of corners, which rounding can flip where many lines pass near
  // one point (a polygon far smaller than the scene is a bundle of lines through its origin, found
  // by fuzz_proximity): the centre must satisfy every half-plane, already grown by slack, to
  // within slack more, or the polygons are taken not to overlap. O(n), like the sort.
  for (Eigen::Index j = 0; j < n; ++j) {
    if (planes[j].normal.dot(centre) > planes[j].offset + slack) return false;
  }
  return true;
}

}  // namespace diffpills::detail
