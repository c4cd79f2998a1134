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
// Bounded <=> consecutive kept normals turn by less than pi. The vertices are computed from the
// rows as given, not from the unit normals: each row scaled by a power of two (exactly) so that
// its largest entry is in [1, 2), the 2 x 2 system of two rows solved by Cramer's rule with each
// determinant a b - c d computed to about one rounding (Kahan's fused multiply-add algorithm).
// So a vertex is as accurate as the rows fix it, however nearly parallel or opposite they are: a
// sliver's apex of rows x <= 1e-28 and -x + 1e-16 y <= 1e-28 lies at y = 2e-12, to the last digits
// (from the unit normals, rounded by 1e-16, it would be off by as much as itself). Vertices more
// than 1e12 times the largest offset from the origin are reported as unbounded: rows meeting
// there are almost surely not what was meant, and a polygon's tolerances are relative to its
// size.
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
  int row = 0;  // its index in C
  // The row as given, scaled by a power of two: largest |entry| in [1, 2), for the vertices.
  Eigen::Vector2d scaled_row;
  double scaled_offset = 0.0;
};

// The smallest normalized offset d_i / |C_i| accepted.
constexpr double kMinOffset = 1e-300;

// a b - c d to about one rounding (Kahan's algorithm): c d's rounding error, recovered exactly by
// a fused multiply-add, is added back, so nearly equal products keep their digits.
double difference_of_products(double a, double b, double c, double d) {
  const double cd = c * d;
  const double error = std::fma(-c, d, cd);  // cd - c d, exactly
  return std::fma(a, b, -cd) + error;
}

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
  int exponent = 0;
  std::frexp(largest, &exponent);  // largest = f 2^exponent, f in [1/2, 1)
  const double scale = std::ldexp(1.0, 1 - exponent);
  row.scaled_row = Eigen::Vector2d(c0 * scale, c1 * scale);
  row.scaled_offset = d * scale;
  return std::isfinite(row.offset) && std::isfinite(row.scaled_offset);
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
    unit.row = static_cast<int>(i);
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
    if (a.angle != b.angle) return a.angle < b.angle;
    return a.offset < b.offset || (a.offset == b.offset && a.row < b.row);
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
  edge_rows_.resize(k);
  vertices_.resize(k, 2);
  for (Eigen::Index i = 0; i < k; ++i) {
    normals_.row(i) = kept[static_cast<std::size_t>(i)].normal.transpose();
    offsets_(i) = kept[static_cast<std::size_t>(i)].offset;
    edge_rows_(i) = kept[static_cast<std::size_t>(i)].row;
  }
  // Vertex i joins edges i and i + 1: p . y = s for row i and q . y = t for row i + 1 (scaled
  // rows as given), so y = (s q_y - t p_y, t p_x - s q_x) / (p x q).
  for (Eigen::Index i = 0; i < k; ++i) {
    const UnitRow& a = kept[static_cast<std::size_t>(i)];
    const UnitRow& c = kept[static_cast<std::size_t>((i + 1) % k)];
    const Eigen::Vector2d& p = a.scaled_row;
    const Eigen::Vector2d& q = c.scaled_row;
    const double s = a.scaled_offset, t = c.scaled_offset;
    const double determinant = difference_of_products(p.x(), q.y(), p.y(), q.x());
    if (!(determinant > 0.0)) unbounded();  // the rows turn by pi or more: open
    // The offsets scaled by the larger one's power of two, exactly (unless the smaller underflows,
    // when it is negligible beside it), so that an offset of 1e-300 times an entry of 1e-16 is
    // not a subnormal number that has lost its digits.
    int exponent = 0;
    std::frexp(std::max(s, t), &exponent);
    const double s1 = std::ldexp(s, -exponent), t1 = std::ldexp(t, -exponent);
    const Eigen::Vector2d vertex(
        std::ldexp(difference_of_products(s1, q.y(), t1, p.y()) / determinant, exponent),
        std::ldexp(difference_of_products(t1, p.x(), s1, q.x()) / determinant, exponent));
    vertices_.row(i) = vertex.transpose();
    extent_ = std::max(extent_, std::hypot(vertex.x(), vertex.y()));  // no underflow of squares
  }
  if (!(extent_ <= 1e12 * largest_offset)) unbounded();
  if (!(extent_ <= kMaxMagnitude)) {
    detail::fail("polygon.C", "a vertex lies farther than 1e100 from the origin");
  }
}

}  // namespace diffpills
