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
// The redundancy test. For rows a, b, c in angular order with 0 < angle(a, c) < pi, row b cuts
// the vertex of a and c off by E / (k |C_b|) (row_predicates.hpp: k = C_a x C_c, E linear in
// the offsets, so no product of two lengths is formed and offsets of 1e-300 and 1e100 mean the
// same). Both are computed on the rows as given (scaled by powers of two, exactly), with their
// signs exact: the unit normals, rounded, decided nearly parallel and nearly opposite rows by
// noise. If k <= 0, b is needed to close the polygon and kept. The walk runs twice: first keeping
// every row that cuts anything (E > 0), which gives the polygon exactly up to the rounding of its
// vertices and so its size; then dropping the rows that cut less than 1e-12 of that size off
// (exact and rounded duplicates, rows through a vertex), and keeping the rows of a 10^5-gon
// (whose neighbours cut ~2e-9 of its size). What b cuts off is the triangle of the vertices
// v_ab, v_ac, v_bc, measured by v_ac's distance from the edge v_ab v_bc (not from b's line: for b
// nearly parallel to a side of a needle, the tip beyond b's line by 1e-15 can be 4.5e-5 from the
// rest). Drops add up: a vertex may end a few 1e-12 of the size beyond a dropped row. A loose row
// far away (offset 1e13 beside a unit square) sets nothing: the tolerance is the polygon's size,
// not the largest offset's.
//
// Bounded <=> consecutive kept normals turn by less than pi. The vertices are computed from the
// rows as given, not from the unit normals: each row scaled by a power of two (exactly) so that
// its largest entry is in [1, 2), the 2 x 2 system of two rows solved by Cramer's rule with each
// determinant a b - c d computed to about one rounding (Kahan's fused multiply-add algorithm).
// So a vertex is as accurate as the rows fix it, however nearly parallel or opposite they are: a
// sliver's apex of rows x <= 1e-28 and -x + 1e-16 y <= 1e-28 lies at y = 2e-12, to the last digits
// (from the unit normals, rounded by 1e-16, it would be off by as much as itself). Vertices more
// than 1e12 times the largest offset of any row given from the origin are reported as unbounded:
// rows meeting there are almost surely not what was meant, and a polygon's tolerances are relative
// to its size.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include "diffpills/shapes.hpp"
#include "nearest_on_segment.hpp"
#include "row_predicates.hpp"
#include "row_scale.hpp"
#include "validation.hpp"

namespace diffpills {
namespace {

struct UnitRow {
  Eigen::Vector2d normal;
  double offset = 0.0;
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

// The vertex of rows a and c (a x c > 0): p . y = s and q . y = t for the scaled rows as given,
// so y = (s q_y - t p_y, t p_x - s q_x) / (p x q), each determinant to about one rounding. The
// offsets are scaled by the larger one's power of two, exactly (unless the smaller underflows,
// when it is negligible beside it), so that an offset of 1e-300 times an entry of 1e-16 is not a
// subnormal number that has lost its digits.
Eigen::Vector2d vertex_of(const UnitRow& a, const UnitRow& c) {
  const Eigen::Vector2d& p = a.scaled_row;
  const Eigen::Vector2d& q = c.scaled_row;
  const double determinant = difference_of_products(p.x(), q.y(), p.y(), q.x());
  int exponent = 0;
  std::frexp(std::max(a.scaled_offset, c.scaled_offset), &exponent);
  const double s = std::ldexp(a.scaled_offset, -exponent);
  const double t = std::ldexp(c.scaled_offset, -exponent);
  return {std::ldexp(difference_of_products(s, q.y(), t, p.y()) / determinant, exponent),
          std::ldexp(difference_of_products(t, p.x(), s, q.x()) / determinant, exponent)};
}

double distance_to_segment(const Eigen::Vector2d& point, const Eigen::Vector2d& start,
                           const Eigen::Vector2d& end) {
  const Eigen::Vector2d gap =
      point - (start + detail::nearest_on_segment(point, start, end) * (end - start));
  return std::hypot(gap.x(), gap.y());
}

// Is row b needed beside its neighbours a and c: does it close the polygon (a and c turn by pi or
// more), or cut anything off (tolerance 0), or cut off more than `tolerance`? What b cuts off is
// the triangle of the vertices v_ab, v_ac, v_bc, as far from the rest as v_ac is from the edge
// v_ab v_bc: more than v_ac's distance beyond b's line where b is nearly parallel to a or c (a
// needle's tip 1e-15 beyond the line of a row 6e-11 rad from its side is 4.5e-5 from the rest).
bool needed(const UnitRow& a, const UnitRow& b, const UnitRow& c, double tolerance) {
  if (detail::turn(a.scaled_row, c.scaled_row).sign <= 0) return true;
  const detail::SignedValue e = detail::cut(a.scaled_row, a.scaled_offset, b.scaled_row,
                                            b.scaled_offset, c.scaled_row, c.scaled_offset);
  if (e.sign <= 0) return false;
  if (tolerance == 0.0) return true;
  return distance_to_segment(vertex_of(a, c), vertex_of(a, b), vertex_of(b, c)) > tolerance;
}

// The rows that bound the polygon, of `rows` in angular order starting at one that does (a Graham
// scan around the origin, closing on the first row again, then checking the first and last rows
// against each other until neither can go).
std::vector<UnitRow> bounding_rows(const std::vector<UnitRow>& rows, double tolerance) {
  std::vector<UnitRow> kept;
  kept.reserve(rows.size());
  for (std::size_t i = 0; i <= rows.size(); ++i) {
    const UnitRow& next = rows[i % rows.size()];
    while (kept.size() >= 2 && !needed(kept[kept.size() - 2], kept.back(), next, tolerance)) {
      kept.pop_back();
    }
    if (i < rows.size()) kept.push_back(next);
  }
  for (bool changed = true; changed && kept.size() >= 3;) {
    changed = false;
    if (!needed(kept[kept.size() - 2], kept.back(), kept.front(), tolerance)) {
      kept.pop_back();
      changed = true;
    } else if (!needed(kept.back(), kept.front(), kept[1], tolerance)) {
      kept.erase(kept.begin());
      changed = true;
    }
  }
  return kept;
}

// The vertices of consecutive rows (vertex i joins rows i and i + 1), and their largest distance
// from the origin; false if two consecutive rows turn by pi or more (the polygon is open).
bool vertices_of(const std::vector<UnitRow>& kept, Eigen::MatrixX2d& vertices, double& extent) {
  const auto k = static_cast<Eigen::Index>(kept.size());
  vertices.resize(k, 2);
  extent = 0.0;
  for (Eigen::Index i = 0; i < k; ++i) {
    const UnitRow& a = kept[static_cast<std::size_t>(i)];
    const UnitRow& c = kept[static_cast<std::size_t>((i + 1) % k)];
    if (detail::turn(a.scaled_row, c.scaled_row).sign <= 0) return false;
    const Eigen::Vector2d vertex = vertex_of(a, c);
    vertices.row(i) = vertex.transpose();
    extent = std::max(extent, std::hypot(vertex.x(), vertex.y()));  // no underflow of squares
  }
  return true;
}

// The row C y <= d as n . y <= b with |n| = 1; false for a row that constrains nothing (C = 0, or
// an offset beyond the largest double, a half-plane that holds every representable point). n and
// b are taken from the row scaled exactly by a power of two (row_scale.hpp): a row and the same
// row times 2^k give the same n and b to the bit (a subnormal row's normal, by hypot of the row as
// given, was ~1e-4 from unit, and the polygon off by as much; fuzz_proximity).
bool normalize_row(double c0, double c1, double d, UnitRow& row) {
  if (c0 == 0.0 && c1 == 0.0) return false;
  const int shift = detail::row_scale_shift(c0, c1);
  row.scaled_row = detail::scaled_row(c0, c1, shift);
  row.scaled_offset = std::ldexp(d, shift);
  const double norm = detail::scaled_row_norm(row.scaled_row);
  row.normal = row.scaled_row / norm;
  row.offset = row.scaled_offset / norm;
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

  // By the angle of the normal, exactly (the half-plane of the direction, then the sign of the
  // turn between two); of rows with one normal only the tightest can bind.
  const auto half = [](const Eigen::Vector2d& p) {
    return p.y() > 0.0 || (p.y() == 0.0 && p.x() > 0.0) ? 0 : 1;
  };
  const auto same_direction = [&](const UnitRow& a, const UnitRow& b) {
    return half(a.scaled_row) == half(b.scaled_row) &&
           detail::turn(a.scaled_row, b.scaled_row).sign == 0;
  };
  std::sort(rows.begin(), rows.end(), [&](const UnitRow& a, const UnitRow& b) {
    if (half(a.scaled_row) != half(b.scaled_row)) return half(a.scaled_row) < half(b.scaled_row);
    const int turn = detail::turn(a.scaled_row, b.scaled_row).sign;
    if (turn != 0) return turn > 0;
    return a.offset < b.offset || (a.offset == b.offset && a.row < b.row);
  });
  rows.erase(std::unique(rows.begin(), rows.end(), same_direction), rows.end());
  // The walk starts at the row nearest the origin, which has an edge (the point b n of that row
  // satisfies every other row: n_j . b n <= b <= b_j); should rounding pick a row that has none,
  // the walk's closing check drops it.
  std::size_t nearest = 0;
  double largest_offset = 0.0;  // of every row given: the scale a far vertex is measured against
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].offset < rows[nearest].offset) nearest = i;
    largest_offset = std::max(largest_offset, rows[i].offset);
  }
  std::rotate(rows.begin(), rows.begin() + static_cast<std::ptrdiff_t>(nearest), rows.end());

  // Every row that cuts anything, for the polygon's size; then those that cut 1e-12 of it.
  std::vector<UnitRow> kept = bounding_rows(rows, 0.0);
  if (kept.size() < 3 || !vertices_of(kept, vertices_, extent_)) unbounded();
  kept = bounding_rows(kept, 1e-12 * extent_);
  if (kept.size() < 3 || !vertices_of(kept, vertices_, extent_)) unbounded();
  const auto k = static_cast<Eigen::Index>(kept.size());
  normals_.resize(k, 2);
  offsets_.resize(k);
  edge_rows_.resize(k);
  for (Eigen::Index i = 0; i < k; ++i) {
    normals_.row(i) = kept[static_cast<std::size_t>(i)].normal.transpose();
    offsets_(i) = kept[static_cast<std::size_t>(i)].offset;
    edge_rows_(i) = kept[static_cast<std::size_t>(i)].row;
  }
  if (!(extent_ <= 1e12 * largest_offset)) unbounded();
  if (!(extent_ <= kMaxMagnitude)) {
    detail::fail("polygon.C", "a vertex lies farther than 1e100 from the origin");
  }
}

}  // namespace diffpills
