// The polygon's reduction: from the rows C y <= d as given to the non-redundant rows, their
// vertices and the polygon's extent.
//
// Each nonzero row is normalized to n_i . y <= b_i with |n_i| = 1 and b_i = d_i / |C_i| > 0.
// Because every b_i > 0, the origin lies strictly inside every half-plane, so the polygon is
// star-shaped about it: walking the rows by the angle of their normal, each row either bounds the
// polygon (it has an edge) or is cut away by its neighbours. The walk is a Graham scan around the
// origin; it starts at the row nearest the origin, which always has an edge (the point b n of
// that row satisfies every other row: n_j . b n <= b <= b_j).
//
// The redundancy test. For rows a, b, c in angular order with 0 < angle(a, c) < pi, the lines of a
// and c meet at the vertex (Cramer's rule)
//   v_ac = (b_a [n_c,y, -n_c,x] + b_c [-n_a,y, n_a,x]) / k,   k = n_a x n_c = sin angle(a, c),
// and row b cuts that vertex off by n_b . v_ac - b_b = E / k with
//   E = b_a (n_b x n_c) + b_c (n_a x n_b) - b_b (n_a x n_c).
// E is linear in the offsets: no product of two lengths is ever formed, so the test means the same
// for offsets of 1e-95 and of 1e100 (a dual formulation, through the points n_i / b_i, squares
// 1 / b and underflows or overflows at either end). Row b is kept when it cuts more than 1e-12 of
// the polygon's size off: E > 1e-12 k max_i b_i. That drops exact and rounded duplicates (a row
// given twice at different scales), rows through an existing vertex, and loose rows, and keeps the
// rows of a 10^5-gon (whose neighbours cut ~2e-9 of its size). If angle(a, c) >= pi (k <= 0), b is
// needed to close the polygon and always kept.
//
// Bounded <=> consecutive kept normals turn by less than pi. The vertex of a turn within 1e-12 of
// 0 is not fixed by the rows, and is reported as unbounded. The vertex v of a turn within 1e-12
// of pi, k = sin(turn) <= 1e-12, is fixed only if the rounding of k (a few 1e-16 absolute in
// n_a x n_c, so |v| 4.4e-16 / k in v) stays below 1e-12 of the polygon's size: a spike of rows
// whose offsets are far below the largest (x <= 1e-300 and -x + 1e-16 y <= 1e-300 meet at y =
// 2e-284 in a polygon of size 1; the row y <= 1e-300 between them is dropped as cutting nothing
// of that size) is a vertex, the same turn between offsets of the polygon's size is not. Vertices
// more than 1e12 times the largest offset from the origin are reported as unbounded too, since
// their position is then fixed only to ~1e-4.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include "diffpills/shapes.hpp"
#include "validation.hpp"

namespace diffpills {
namespace {

struct UnitRow {
  Eigen::Vector2d normal;
  double offset = 0.0;
  double angle = 0.0;
};

// The smallest normalized offset d_i / |C_i| accepted.
constexpr double kMinOffset = 1e-300;

// Turns (sines, n_a x n_c) at or below this are checked for the vertex they fix (see above), and
// the rounding of a sine of unit normals: 2 products of rounded unit vectors, 2^-52 each.
constexpr double kSmallestTurn = 1e-12;
constexpr double kTurnRounding = 4.4e-16;

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Row b's cut E (see above) of the vertex of rows a and c, times 1 / (k max_b).
bool cuts_vertex(const UnitRow& a, const UnitRow& b, const UnitRow& c, double largest_offset) {
  const double k = cross(a.normal, c.normal);
  if (k <= 0.0) return true;  // a and c alone leave the polygon open: b closes it
  const double cut =
      a.offset * cross(b.normal, c.normal) + c.offset * cross(a.normal, b.normal) - b.offset * k;
  return cut > 1e-12 * k * largest_offset;
}

// The row C y <= d as n . y <= b with |n| = 1; false for a row that constrains nothing (C = 0, or
// an offset beyond the largest double, a half-plane that holds every representable point).
bool normalize_row(double c0, double c1, double d, UnitRow& row) {
  const double largest = std::max(std::abs(c0), std::abs(c1));
  if (largest == 0.0) return false;
  const double norm = std::hypot(c0, c1);  // no overflow or underflow, unlike sqrt(c0^2 + c1^2)
  row.normal = Eigen::Vector2d(c0 / norm, c1 / norm);
  row.offset = d / norm;
  row.angle = std::atan2(row.normal.y(), row.normal.x());
  return std::isfinite(row.offset);
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
  std::vector<UnitRow> rows;
  rows.reserve(static_cast<std::size_t>(m));
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto row = [i] { return "[" + std::to_string(i) + "]"; };
    detail::require_finite(C(i, 0), [&] { return "polygon.C" + row() + "[0]"; });
    detail::require_finite(C(i, 1), [&] { return "polygon.C" + row() + "[1]"; });
    detail::require_finite(d(i), [&] { return "polygon.d" + row(); });
    if (!(d(i) > 0.0)) {
      detail::fail("polygon.d" + row(),
                   "must be > 0 so that the body origin lies strictly inside the polygon (got " +
                       detail::format_number(d(i)) + ")");
    }
    UnitRow unit;
    if (!normalize_row(C(i, 0), C(i, 1), d(i), unit)) continue;
    // Below this the offset is subnormal or zero: the origin would sit on the row's line, and the
    // vertices would lose their digits (a hostile review found 2 C, d = 5e-324 accepted with
    // every vertex at 0).
    if (!(unit.offset >= kMinOffset)) {
      detail::fail("polygon.d" + row(),
                   "must be at least 1e-300 times |C" + row() +
                       "| (got d = " + detail::format_number(d(i)) + ", |C" + row() +
                       "| = " + detail::format_number(std::hypot(C(i, 0), C(i, 1))) + ")");
    }
    rows.push_back(unit);
  }
  const auto unbounded = [] {
    detail::fail("polygon.C", "the rows C y <= d do not bound a polygon (it is unbounded)");
  };
  if (rows.size() < 3) unbounded();

  // By angle; of rows with the same normal only the tightest can bind.
  std::sort(rows.begin(), rows.end(), [](const UnitRow& a, const UnitRow& b) {
    return a.angle < b.angle || (a.angle == b.angle && a.offset < b.offset);
  });
  rows.erase(std::unique(rows.begin(), rows.end(),
                         [](const UnitRow& a, const UnitRow& b) { return a.angle == b.angle; }),
             rows.end());
  double largest_offset = 0.0;
  std::size_t nearest = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    largest_offset = std::max(largest_offset, rows[i].offset);
    if (rows[i].offset < rows[nearest].offset) nearest = i;
  }
  std::rotate(rows.begin(), rows.begin() + static_cast<std::ptrdiff_t>(nearest), rows.end());

  std::vector<UnitRow> kept;
  kept.reserve(rows.size());
  for (std::size_t i = 0; i <= rows.size(); ++i) {
    const UnitRow& next = rows[i % rows.size()];  // the walk closes on the first row again
    while (kept.size() >= 2 &&
           !cuts_vertex(kept[kept.size() - 2], kept.back(), next, largest_offset)) {
      kept.pop_back();
    }
    if (i < rows.size()) kept.push_back(next);
  }
  const auto k = static_cast<Eigen::Index>(kept.size());
  if (k < 3) unbounded();

  normals_.resize(k, 2);
  offsets_.resize(k);
  vertices_.resize(k, 2);
  for (Eigen::Index i = 0; i < k; ++i) {
    normals_.row(i) = kept[static_cast<std::size_t>(i)].normal.transpose();
    offsets_(i) = kept[static_cast<std::size_t>(i)].offset;
  }
  // Vertex i joins edges i and i + 1 (v_ac above with a = i, c = i + 1).
  for (Eigen::Index i = 0; i < k; ++i) {
    const UnitRow& a = kept[static_cast<std::size_t>(i)];
    const UnitRow& c = kept[static_cast<std::size_t>((i + 1) % k)];
    const double turn = cross(a.normal, c.normal);
    const bool near_pi = a.normal.dot(c.normal) < 0.0;
    if (!(turn > (near_pi ? 0.0 : kSmallestTurn))) unbounded();
    const Eigen::Vector2d vertex = (a.offset * Eigen::Vector2d(c.normal.y(), -c.normal.x()) +
                                    c.offset * Eigen::Vector2d(-a.normal.y(), a.normal.x())) /
                                   turn;
    const double distance = std::hypot(vertex.x(), vertex.y());  // no underflow of squares
    if (turn <= kSmallestTurn && !(distance * (kTurnRounding / turn) <= 1e-12 * largest_offset)) {
      unbounded();
    }
    vertices_.row(i) = vertex.transpose();
    extent_ = std::max(extent_, distance);
  }
  if (!(extent_ <= 1e12 * largest_offset)) unbounded();
  if (!(extent_ <= kMaxMagnitude)) {
    detail::fail("polygon.C", "a vertex lies farther than 1e100 from the origin");
  }
}

}  // namespace diffpills
