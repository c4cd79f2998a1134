// Shape and pose validation, and the polygon's precomputed vertices and reduced rows.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "diffpills/diffpills.hpp"

namespace diffpills {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Expects std::invalid_argument whose message starts with `field`.
template <class Function>
void expect_invalid(const Function& make, const std::string& field) {
  try {
    make();
    ADD_FAILURE() << "no exception; expected one naming " << field;
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(std::string(error.what()).rfind(field, 0), 0u)
        << "message '" << error.what() << "' does not start with " << field;
  }
}

Eigen::MatrixX2d square_rows() {
  return (Eigen::MatrixX2d(4, 2) << 1, 0, 0, 1, -1, 0, 0, -1).finished();
}

PaddedPolygon regular_polygon(int sides, double apothem, double radius) {
  Eigen::MatrixX2d C(sides, 2);
  for (int i = 0; i < sides; ++i)
    C.row(i) << std::cos(2 * M_PI * i / sides), std::sin(2 * M_PI * i / sides);
  return PaddedPolygon(C, Eigen::VectorXd::Constant(sides, apothem), radius);
}

TEST(Shapes, SquareVerticesCounterclockwise) {
  const PaddedPolygon square(square_rows(), Eigen::Vector4d(1, 2, 1, 2), 0.1);
  ASSERT_EQ(square.vertices().rows(), 4);
  double area = 0.0;  // shoelace: positive for counterclockwise
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d a = square.vertices().row(i), b = square.vertices().row((i + 1) % 4);
    area += 0.5 * (a.x() * b.y() - a.y() * b.x());
    EXPECT_NEAR(std::abs(a.x()), 1.0, 1e-15);
    EXPECT_NEAR(std::abs(a.y()), 2.0, 1e-15);
  }
  EXPECT_NEAR(area, 8.0, 1e-14);
  EXPECT_NEAR(square.extent(), std::sqrt(5.0), 1e-15);
}

TEST(Shapes, HexagonVerticesLieOnCircumcircle) {
  const PaddedPolygon hexagon = regular_polygon(6, 0.6, 0.05);
  ASSERT_EQ(hexagon.vertices().rows(), 6);
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(hexagon.vertices().row(i).norm(), 0.6 / std::cos(M_PI / 6), 1e-14);
  }
}

TEST(Shapes, RedundantRowsAreDropped) {
  Eigen::MatrixX2d C(8, 2);
  C << 1, 0, 0, 1, -1, 0, 0, -1,  // the unit square's rows
      3, 0,                       // a duplicate at another scale
      0, 0,                       // a zero row
      1, 1,                       // a row through the corner (1, 1): touches, never binds alone
      -1, -1;                     // a loose row
  Eigen::VectorXd d(8);
  d << 1, 1, 1, 1, 3, 5, 2, 7;
  const PaddedPolygon polygon(C, d, 0.0);
  EXPECT_EQ(polygon.edge_normals().rows(), 4);
  EXPECT_EQ(polygon.vertices().rows(), 4);
  EXPECT_EQ(polygon.constraint_matrix().rows(), 8);  // the original rows are kept for round trips
  for (Eigen::Index i = 0; i < 4; ++i) {
    EXPECT_NEAR(polygon.edge_normals().row(i).norm(), 1.0, 1e-15);
    EXPECT_NEAR(polygon.edge_offsets()(i), 1.0, 1e-15);
  }
}

TEST(Shapes, ClockwiseInputStillYieldsCounterclockwiseVertices) {
  Eigen::MatrixX2d C(3, 2);
  C << 0, -1, -1, 1, 1, 1;  // a triangle, rows given clockwise
  const PaddedPolygon triangle(C, Eigen::Vector3d(1, 1, 1), 0.0);
  const auto& v = triangle.vertices();
  ASSERT_EQ(v.rows(), 3);
  double area = 0.0;
  for (int i = 0; i < 3; ++i) {
    area += 0.5 * (v(i, 0) * v((i + 1) % 3, 1) - v(i, 1) * v((i + 1) % 3, 0));
  }
  EXPECT_GT(area, 0.0);
}

TEST(Shapes, TwoThousandRowPolygonIsReducedAndQueried) {
  const PaddedPolygon big = regular_polygon(2000, 1.0, 0.0);
  EXPECT_EQ(big.vertices().rows(), 2000);
  // A sphere 3 above the centre and one beside the rim, against the analytic answers.
  const Capsule sphere(0.0, 0.0);
  const Proximity above = proximity(sphere, Pose({0, 0, 3}, {1, 0, 0, 0}), big, Pose());
  EXPECT_NEAR(above.phi, 9.0, 1e-9);
  const Proximity beside = proximity(sphere, Pose({3, 0, 0}, {1, 0, 0, 0}), big, Pose());
  EXPECT_NEAR(std::sqrt(beside.phi), 2.0, 1e-9);  // (1, 0) is a vertex-free edge midpoint
}

TEST(Shapes, CapsuleRejectsBadSizes) {
  expect_invalid([] { Capsule(-1.0, 0.1); }, "capsule.length");
  expect_invalid([] { Capsule(1.0, -0.1); }, "capsule.radius");
  expect_invalid([] { Capsule(kNan, 0.1); }, "capsule.length");
  expect_invalid([] { Capsule(1.0, kInf); }, "capsule.radius");
  expect_invalid([] { Capsule(1e200, 0.1); }, "capsule.length");
  EXPECT_NO_THROW(Capsule(0.0, 0.0));  // a point is a valid (degenerate) capsule
}

TEST(Shapes, PoseRejectsBadNumbers) {
  expect_invalid([] { Pose({0, kNan, 0}, {1, 0, 0, 0}); }, "pose.r[1]");
  expect_invalid([] { Pose({0, 0, 0}, {1, kInf, 0, 0}); }, "pose.q[1]");
  expect_invalid([] { Pose({0, 0, 0}, {0, 0, 0, 0}); }, "pose.q");
  expect_invalid([] { Pose({0, 0, 0}, {1e-170, 0, 0, 0}); }, "pose.q");
  expect_invalid([] { Pose({0, 0, 0}, {-1.1e-146, -1.1e-146, -1.1e-146, -1.1e-146}); }, "pose.q");
  expect_invalid([] { Pose({0, 0, 0}, {0, 0, 9e-41, 0}); }, "pose.q");
  EXPECT_NO_THROW(Pose({0, 0, 0}, {1e-40, 0, 0, 0}));
}

// Offsets whose normalized value d_i / |C_i| underflows are refused, naming the row (a hostile
// review found them accepted with every vertex at 0); 1e-300 itself is accepted.
TEST(Shapes, PolygonRejectsOffsetsThatUnderflow) {
  Eigen::MatrixX2d C(4, 2);
  C << 1, 0, 0, 1, -1, 0, 0, -1;
  expect_invalid([&] { PaddedPolygon(2 * C, Eigen::Vector4d::Constant(5e-324), 0.0); },
                 "polygon.d[0]: must be at least 1e-300");
  expect_invalid([&] { PaddedPolygon(1e100 * C, Eigen::Vector4d::Constant(1e-300), 0.0); },
                 "polygon.d[0]");
  const PaddedPolygon tiny(C, Eigen::Vector4d::Constant(1e-300), 0.0);
  EXPECT_GT(tiny.extent(), 0.0);
}

// Rows given at any scale are the same half-planes, down to subnormal entries (a hostile review:
// the row [1e-308, 0] y <= 5e-309, x <= 0.5, was dropped as constraining nothing, and a point at
// x = 0.9 reported touching; a polygon of subnormal rows only, unbounded).
TEST(Shapes, SubnormalRowsAreTheirHalfPlanes) {
  Eigen::MatrixX2d C(5, 2);
  C << 1, 0, 0, 1, -1, 0, 0, -1, 1e-308, 0;
  const PaddedPolygon cut(C, (Eigen::VectorXd(5) << 1, 1, 1, 1, 5e-309).finished(), 0.0);
  const Capsule point(0.0, 0.0);
  const Proximity p = proximity(point, Pose({0.9, 0, 0}, {1, 0, 0, 0}), cut, Pose());
  EXPECT_NEAR(p.phi, 0.4 * 0.4, 1e-15);
  EXPECT_FALSE(p.cores_intersect);
  for (const double scale : {0x1p-1030, 0x1p-1060, 1e-310}) {
    SCOPED_TRACE(scale);
    Eigen::MatrixX2d square(4, 2);
    square << 1, 0, 0, 1, -1, 0, 0, -1;
    const PaddedPolygon tiny_rows(scale * square, Eigen::Vector4d::Constant(scale), 0.0);
    const PaddedPolygon unit_rows(square, Eigen::Vector4d::Constant(1.0), 0.0);
    EXPECT_EQ(tiny_rows.vertices(), unit_rows.vertices());
    EXPECT_EQ(proximity(point, Pose({2, 0.5, 0}, {1, 0, 0, 0}), tiny_rows, Pose()).phi, 1.0);
  }
}

// Rows with subnormal entries are normalized as exactly as any other: a row and the same row
// times 2^k are the same half-plane and give the same unit normal and offset to the bit. Rows of
// entries near 2^-1060 keep ~14 bits (the spacing there is 2^-1074), and their norm taken as
// given kept as few, so that normals were ~1e-4 from unit and the polygon ~1e-4 of its size off
// (found by fuzz_proximity as other closest points for the rows rescaled to unit length).
TEST(Shapes, SubnormalRowsGiveTheSamePolygonAsTheirRowsRescaled) {
  const int k = 6;
  Eigen::MatrixX2d subnormal(k, 2), rescaled(k, 2);
  Eigen::VectorXd offsets(k), rescaled_offsets(k);
  for (int i = 0; i < k; ++i) {
    const double angle = 0.3 + 2.0 * std::acos(-1.0) * i / k + 0.05 * i * i;
    const int exponent = -1060 + 3 * i;  // entries 2^-1060 .. 2^-1045, all subnormal
    subnormal.row(i) << std::ldexp(std::cos(angle), exponent),
        std::ldexp(std::sin(angle), exponent);
    offsets(i) = 1e-300 * (1.0 + 0.1 * i);
    // Scaling up by 2^-exponent is exact for both.
    rescaled.row(i) << std::ldexp(subnormal(i, 0), -exponent),
        std::ldexp(subnormal(i, 1), -exponent);
    rescaled_offsets(i) = std::ldexp(offsets(i), -exponent);
  }
  const PaddedPolygon given(subnormal, offsets, 0.5);
  const PaddedPolygon unit_rows(rescaled, rescaled_offsets, 0.5);
  EXPECT_EQ(given.edge_normals(), unit_rows.edge_normals());
  EXPECT_EQ(given.edge_offsets(), unit_rows.edge_offsets());
  EXPECT_EQ(given.vertices(), unit_rows.vertices());
  for (Eigen::Index j = 0; j < given.edge_normals().rows(); ++j) {
    EXPECT_NEAR(given.edge_normals().row(j).norm(), 1.0, 1e-15);
  }
  const Capsule capsule(3e18, 1e17);
  const Pose pose({1e19, 2e18, 3e18}, {0.9, 0.1, -0.3, 0.2});
  const Proximity a = proximity(given, Pose(), capsule, pose);
  const Proximity b = proximity(unit_rows, Pose(), capsule, pose);
  EXPECT_EQ(a.phi, b.phi);
  EXPECT_EQ(a.core_points, b.core_points);
  EXPECT_EQ(a.gradient, b.gradient);
}

// A sliver far thinner than it is long, its rows at 0, 90, 180 and 270 degrees as cos and sin
// give them (6e-17 off): x <= e, y <= e, -x <= e, -y <= 1 with e = 1e-300 down to 1e-20. The row
// y <= e is dropped (it cuts 1e-284 of a polygon of size 1), leaving the rows x <= e and
// -x + 1.2e-16 y <= e nearly opposite, meeting at a spike within 1e-12 of the size of the apex: a
// polygon, once reported unbounded. Every vertex satisfies every row within 1e-12 of the size,
// and the extent is the farthest corner's, computed here from the rows by hand.
TEST(Shapes, AnOrthogonalSliverWithRoundedRowsIsAPolygon) {
  Eigen::MatrixX2d C(4, 2);
  for (int i = 0; i < 4; ++i) C.row(i) << std::cos(i * M_PI / 2), std::sin(i * M_PI / 2);
  for (const double e : {1e-300, 1e-200, 1e-100, 1e-20}) {
    const Eigen::Vector4d d(e, e, e, 1.0);
    const PaddedPolygon sliver(C, d, 0.1);
    // The far corners (x = e or the third row's line, y on the fourth row's line) are 1 away.
    EXPECT_NEAR(sliver.extent(), 1.0, 1e-12) << e;
    for (Eigen::Index v = 0; v < sliver.vertices().rows(); ++v) {
      const Eigen::Vector4d slack = d - C * sliver.vertices().row(v).transpose();
      EXPECT_GE(slack.minCoeff(), -1e-12) << "e " << e << " vertex " << v;
    }
    // Both corners at y = -1 are vertices, and the apex lies within 1e-12 of the origin.
    double lowest = 0.0, highest = -1.0;
    for (Eigen::Index v = 0; v < sliver.vertices().rows(); ++v) {
      lowest = std::min(lowest, sliver.vertices()(v, 1));
      highest = std::max(highest, sliver.vertices()(v, 1));
    }
    EXPECT_NEAR(lowest, -1.0, 1e-12);
    EXPECT_NEAR(highest, 0.0, 1e-12);
  }
  // A taller sliver: y <= 1 is loose, rows 0 and 2 meet at the apex y = 2e-20 / 1.2246e-16.
  const PaddedPolygon tall(C, Eigen::Vector4d(1e-20, 1, 1e-20, 1e-20), 0.0);
  EXPECT_NEAR(tall.vertices().col(1).maxCoeff(), 2e-20 / C(2, 1), 1e-15 * 2e-20 / C(2, 1));
  // The same nearly opposite rows with offsets of the polygon's size leave it open.
  Eigen::MatrixX2d open(3, 2);
  open << 1, 0, -1, 1e-16, 0, -1;
  expect_invalid([&] { PaddedPolygon(open, Eigen::Vector3d(1, 1, 1), 0.1); }, "polygon.C");
}

// Spikes x <= e, -x + s y <= e, -y <= 1: the vertices, computed from the rows as given, are the
// ones solved here by hand, apex (e, 2e / s) and base (-e - s, -1), (e, -1), to a few ulps for
// every s down to 1e-16 (their unit normals, rounded, would put the apex off by up to itself;
// e = 1e-28 at s = 1e-16 was refused as unbounded). An apex beyond 1e12 times the largest offset
// is refused.
TEST(Shapes, SpikeVerticesAreTheRowsOwn) {
  for (const double s : {1e-16, 1e-14, 1e-11, 1e-6, 0.1}) {
    for (const double e : {2e-300, 1e-100, 1e-30, 1e-28, 1e-25, 1e-20, 1e-10}) {
      if (2 * e / s > 1e12) continue;
      Eigen::MatrixX2d C(3, 2);
      C << 1, 0, -1, s, 0, -1;
      const PaddedPolygon spike(C, Eigen::Vector3d(e, e, 1.0), 0.0);
      ASSERT_EQ(spike.vertices().rows(), 3) << "s " << s << " e " << e;
      const Eigen::Matrix<double, 3, 2> expected =
          (Eigen::Matrix<double, 3, 2>() << e, 2 * e / s, -e - s, -1, e, -1).finished();
      // The same cycle of vertices, from whichever vertex the reduction starts at.
      int start = 0;
      while (start < 3 && spike.vertices()(start, 1) != expected(0, 1)) ++start;
      ASSERT_LT(start, 3) << "s " << s << " e " << e;
      for (int v = 0; v < 3; ++v) {
        for (int k = 0; k < 2; ++k) {
          EXPECT_NEAR(spike.vertices()((start + v) % 3, k), expected(v, k),
                      4e-16 * std::abs(expected(v, k)))
              << "s " << s << " e " << e << " vertex " << v;
        }
      }
    }
  }
  Eigen::MatrixX2d C(3, 2);
  C << 1, 0, -1, 1e-16, 0, -1;
  expect_invalid([&] { PaddedPolygon(C, Eigen::Vector3d(1e-3, 1e-3, 1.0), 0.0); }, "polygon.C");
}

// Every reported vertex satisfies every row given, to 1e-12 of the polygon's size, and the
// vertices turn counterclockwise (convex).
void expect_rows_hold_and_convex(const Eigen::MatrixX2d& C, const Eigen::VectorXd& d,
                                 const PaddedPolygon& polygon) {
  const Eigen::MatrixX2d& v = polygon.vertices();
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    for (Eigen::Index j = 0; j < C.rows(); ++j) {
      EXPECT_LE(C.row(j).dot(v.row(i)) - d(j), 1e-12 * polygon.extent() * C.row(j).norm())
          << "vertex " << i << " row " << j;
    }
    const Eigen::Vector2d e = v.row((i + 1) % v.rows()) - v.row(i);
    const Eigen::Vector2d f = v.row((i + 2) % v.rows()) - v.row((i + 1) % v.rows());
    EXPECT_GE(e.x() * f.y() - e.y() * f.x(), -1e-12 * polygon.extent() * polygon.extent())
        << "turn at vertex " << (i + 1) % v.rows();
  }
}

// A hostile review's rows: the reduction's predicates had rounded unit normals decide nearly
// parallel and nearly opposite rows by noise, and its tolerance grew with a loose row's offset.
TEST(Shapes, ReductionIsExactForNearlyParallelAndOppositeRowsAndLooseRows) {
  // A unit square with its corner cut by x + y <= 1.5, and a loose row 1e13 away: the cut stays
  // (it was dropped as cutting less than 1e-12 of 1e13, and the square lost two edges).
  Eigen::MatrixX2d C(6, 2);
  C << 1, 0, 0, 1, -1, 0, 0, -1, 1, 1, -1, 1;
  for (const double far : {1e5, 1e13, 1e100}) {
    Eigen::VectorXd d(6);
    d << 1, 1, 1, 1, 1.5, far;
    const PaddedPolygon cut(C, d, 0.0);
    EXPECT_EQ(cut.vertices().rows(), 5) << far;
    EXPECT_NEAR(cut.extent(), std::sqrt(2.0), 1e-15);  // the corners (-1, -1)
    expect_rows_hold_and_convex(C, d, cut);
  }
  // Three rows within 1e-15 rad of parallel: their vertices are within 1e-12 of the polygon's
  // size of each other (one edge, or two); kept by noise, they put vertices 1,000 away.
  Eigen::MatrixX2d parallel(5, 2);
  parallel << 0.8786979172108029, 0.47737822561297977, 0.8786979172108019, 0.47737822561298154,
      0.8786979172107978, 0.477378225612989, -0.9914774287262685, 0.1302785796911641,
      0.7255462614896907, -0.6881733956193987;
  Eigen::VectorXd ones(5);
  ones << 1.0, 1.0000000000035913, 1.0, 1.0, 1.0;
  const PaddedPolygon fan(parallel, ones, 0.0);
  EXPECT_LT(fan.extent(), 3.3);
  expect_rows_hold_and_convex(parallel, ones, fan);
  // A needle of two nearly opposite rows 2e-20 apart, rotated: bounded (extent 1), it was refused.
  Eigen::MatrixX2d needle(3, 2);
  needle << 0.21887368866980983, 0.9757532005625558, -0.21887368866980986, -0.9757532005625559,
      0.9757532005625558, -0.21887368866980983;
  const Eigen::Vector3d needle_d(1e-20, 1e-20, 1.0);
  const PaddedPolygon thin(needle, needle_d, 0.0);
  EXPECT_NEAR(thin.extent(), 1.0, 1e-12);
  expect_rows_hold_and_convex(needle, needle_d, thin);
  // A needle closed near the origin by two nearly opposite rows, with a back row 7.39 away that
  // does not touch it: it was kept, and the needle stretched to (-6.58, -3.36).
  Eigen::MatrixX2d closed(4, 2);
  closed << 0.45496739475297604, -0.8905080963762708, -0.8905080963762708, -0.45496739475297604,
      -0.008844937136119155, 0.017312203517198813, 0.8905080963762708, 0.45496739475297604;
  const Eigen::Vector4d closed_d(1.6048525430508307e-201, 7.387829803484657, 7.884468112133519e-204,
                                 6.90217553219041);
  const PaddedPolygon spike(closed, closed_d, 0.0);
  EXPECT_EQ(spike.vertices().rows(), 3);
  EXPECT_LT(spike.vertices().col(0).minCoeff(), 0.0);
  EXPECT_GT(spike.vertices().col(0).minCoeff(), -1e-180);  // the apex at the origin's side
  EXPECT_NEAR(spike.extent(), std::hypot(6.146443, 3.140265), 1e-5);
  expect_rows_hold_and_convex(closed, closed_d, spike);
}

TEST(Shapes, PolygonRejectsBadRows) {
  expect_invalid([] { PaddedPolygon(Eigen::MatrixX2d(2, 2), Eigen::Vector2d(1, 1), 0.1); },
                 "polygon.C");  // fewer than 3 rows
  expect_invalid([] { PaddedPolygon(square_rows(), Eigen::Vector3d(1, 1, 1), 0.1); },
                 "polygon.d");  // size mismatch
  expect_invalid([] { PaddedPolygon(square_rows(), Eigen::Vector4d(1, 1, 0, 1), 0.1); },
                 "polygon.d[2]");  // origin on the boundary
  expect_invalid([] { PaddedPolygon(square_rows(), Eigen::Vector4d(1, -1, 1, 1), 0.1); },
                 "polygon.d[1]");  // origin outside
  expect_invalid([] { PaddedPolygon(square_rows(), Eigen::Vector4d(1, 1, 1, kNan), 0.1); },
                 "polygon.d[3]");
  Eigen::MatrixX2d with_nan = square_rows();
  with_nan(2, 1) = kNan;
  expect_invalid([&] { PaddedPolygon(with_nan, Eigen::Vector4d(1, 1, 1, 1), 0.1); },
                 "polygon.C[2][1]");
  expect_invalid([] { PaddedPolygon(square_rows(), Eigen::Vector4d(1, 1, 1, 1), -0.1); },
                 "polygon.radius");
  // Unbounded: three rows whose normals lie in a half-plane, and a strip.
  Eigen::MatrixX2d open(3, 2);
  open << 1, 0, 1, 1, 1, -1;
  expect_invalid([&] { PaddedPolygon(open, Eigen::Vector3d(1, 1, 1), 0.1); }, "polygon.C");
  Eigen::MatrixX2d strip(4, 2);
  strip << 0, 1, 0, -1, 0, 2, 0, -2;
  expect_invalid([&] { PaddedPolygon(strip, Eigen::Vector4d(1, 1, 1, 1), 0.1); }, "polygon.C");
}

}  // namespace
}  // namespace diffpills
