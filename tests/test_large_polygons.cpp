// Polygons with many vertices: the window path (polygon_windows.hpp), which makes a pair cost about
// linear in the vertex counts, must give the answer of the full enumeration it replaces above
// 32 x 32 vertices, and of the brute-force reference. Both paths are called directly on the same
// pairs; the public queries use the windows for these sizes. The same for the signed distance in
// penetration, whose search of the edge chains' hierarchies (edge_chain_tree.hpp) replaces the
// visit of every edge pair there, against that visit and a separating-axis brute force.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "diffpills/diffpills.hpp"
#include "proximity/core_outline.hpp"
#include "proximity/pair_frame.hpp"
#include "proximity/penetration.hpp"
#include "proximity/polygon_windows.hpp"
#include "proximity/separated_polygons.hpp"
#include "proximity/sub_polygon.hpp"
#include "support/random_shapes.hpp"
#include "support/reference.hpp"
#include "support/scene_helpers.hpp"

namespace diffpills::testing {
namespace {

// A convex polygon of `count` vertices on a random ellipse (or a half-ellipse closed by one long
// straight edge), with the body origin at a random interior point; its vertices in the body frame.
TestShape many_sided(Rng& rng, int count, bool half) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double a = 0.5 + uniform(rng), b = 0.5 + uniform(rng), turn = M_PI * uniform(rng);
  const Eigen::Matrix2d rotation = Eigen::Rotation2Dd(turn).toRotationMatrix();
  std::vector<Eigen::Vector2d> points;
  const double span = half ? M_PI : 2.0 * M_PI;
  for (int i = 0; i < count; ++i) {
    const double angle = span * (i + 0.3 * uniform(rng)) / (half ? count - 1 : count);
    points.emplace_back(rotation * Eigen::Vector2d(a * std::cos(angle), b * std::sin(angle)));
  }
  if (half) points.back() = rotation * Eigen::Vector2d(-a, 0.0);
  const Eigen::Vector2d centre = 0.3 * (points[0] + points[count / 3] + points[2 * count / 3]);
  Eigen::MatrixX2d C(count, 2);
  Eigen::VectorXd d(count);
  TestShape out{Capsule(0, 0), {}, 0.0};
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector2d p = points[i] - centre, q = points[(i + 1) % count] - centre;
    const Eigen::Vector2d normal = Eigen::Vector2d(q.y() - p.y(), p.x() - q.x()).normalized();
    C.row(i) = normal.transpose();
    d(i) = normal.dot(p);
    out.body_vertices.emplace_back(p.x(), p.y(), 0.0);
    out.size = std::max(out.size, p.norm());
  }
  out.shape = PaddedPolygon(C, d, 0.05);
  return out;
}

using Sides = std::array<detail::ClosestFeature, 2>;

struct BothPaths {
  Sides windows, enumeration;
  detail::PosedCore a, b;
};

// Both separated-pair solvers on one pair, in a frame of scale 1 (the inputs are of order one).
BothPaths both_paths(const PaddedPolygon& a, const Pose& pa, const PaddedPolygon& b,
                     const Pose& pb) {
  const detail::PolygonView view_a(a, 1.0), view_b(b, 1.0);
  BothPaths out{{},
                {},
                {pa.r(), detail::UnitQuaternion(pa.q()), 0.0, a.extent()},
                {pb.r(), detail::UnitQuaternion(pb.q()), 0.0, b.extent()}};
  const detail::PairFrame scales =
      detail::make_pair_frame(a.extent(), 0.0, b.extent(), 0.0, pa.r(), pb.r());
  const double tolerance = scales.tolerance * scales.scale;
  const double tie_tolerance = scales.tie_tolerance * scales.scale;
  const detail::PolygonPairFrame frame(out.a, out.b);
  const detail::CarriedPolygon<detail::PolygonView> W(view_b, frame.b_in_a, frame.b_origin_in_a);
  const detail::CarriedPolygon<detail::PolygonView> X(view_a, frame.b_in_a.transpose(),
                                                      frame.a_origin_in_b);
  out.windows =
      detail::closest_separated_by_windows(view_a, view_b, frame, W, tolerance, tie_tolerance);
  out.enumeration =
      detail::closest_separated(view_a, view_b, frame, W, X, tolerance, tie_tolerance);
  return out;
}

// A window holding every vertex of the polygon.
detail::SubPolygon every_vertex(const detail::PolygonView& view) {
  std::vector<Eigen::Index> indices(static_cast<std::size_t>(view.size()));
  std::iota(indices.begin(), indices.end(), Eigen::Index{0});
  return detail::SubPolygon(view, indices);
}

// The separated pair's enumeration of `first` against `second` on windows holding every vertex
// (above 32 x 32 vertex pairs, the large windows' search), with both posed cores for world().
struct WholeWindows {
  detail::PosedCore core_1, core_2;
  Sides sides;
};

WholeWindows search_whole_windows(const PaddedPolygon& first, const Pose& p1,
                                  const PaddedPolygon& second, const Pose& p2, double tolerance,
                                  double tie_tolerance) {
  const detail::PolygonView view_1(first, 1.0), view_2(second, 1.0);
  WholeWindows out{{p1.r(), detail::UnitQuaternion(p1.q()), 0.0, first.extent()},
                   {p2.r(), detail::UnitQuaternion(p2.q()), 0.0, second.extent()},
                   {}};
  const detail::PolygonPairFrame frame(out.core_1, out.core_2);
  const detail::SubPolygon all_1 = every_vertex(view_1), all_2 = every_vertex(view_2);
  const detail::CarriedPolygon<detail::SubPolygon> all_W(all_2, frame.b_in_a, frame.b_origin_in_a);
  const detail::CarriedPolygon<detail::SubPolygon> all_X(all_1, frame.b_in_a.transpose(),
                                                         frame.a_origin_in_b);
  out.sides =
      detail::closest_separated(all_1, all_2, frame, all_W, all_X, tolerance, tie_tolerance);
  return out;
}

Eigen::Vector3d world(const detail::PosedCore& core, const detail::ClosestFeature& side) {
  return core.r + core.attitude.matrix() * side.body_point;
}

TEST(LargePolygons, WindowsAgreeWithEnumerationAndBruteForce) {
  Rng rng(17);
  int separated = 0;
  for (int i = 0; i < 300; ++i) {
    const int ka = std::uniform_int_distribution<int>(33, 160)(rng);
    const int kb = std::uniform_int_distribution<int>(33, 160)(rng);
    const TestShape a = many_sided(rng, ka, i % 5 == 0), b = many_sided(rng, kb, i % 7 == 0);
    const Pose pa = random_pose(rng, 1.0), pb = random_pose(rng, 2.5);
    const auto& polygon_a = std::get<PaddedPolygon>(a.shape);
    const auto& polygon_b = std::get<PaddedPolygon>(b.shape);
    const ClosestPair reference = brute_force_closest(to_world(a, pa), to_world(b, pb));
    if (reference.distance < 1e-6) continue;  // the windows are for separated pairs
    ++separated;
    const BothPaths paths = both_paths(polygon_a, pa, polygon_b, pb);
    const Eigen::Vector3d w1 = world(paths.a, paths.windows[0]);
    const Eigen::Vector3d w2 = world(paths.b, paths.windows[1]);
    const Eigen::Vector3d e1 = world(paths.a, paths.enumeration[0]);
    const Eigen::Vector3d e2 = world(paths.b, paths.enumeration[1]);
    ASSERT_NEAR((w1 - w2).norm(), static_cast<double>(reference.distance), 1e-12) << i;
    ASSERT_LE((w1 - e1).norm(), 1e-9) << i;
    ASSERT_LE((w2 - e2).norm(), 1e-9) << i;
    ASSERT_EQ(paths.windows[0].free_dimensions, paths.enumeration[0].free_dimensions) << i;
    ASSERT_EQ(paths.windows[1].free_dimensions, paths.enumeration[1].free_dimensions) << i;
    // The public query (windows at these sizes) against the reference, with its gradient.
    const Proximity result = proximity(polygon_a, pa, polygon_b, pb);
    ASSERT_LE((result.core_points[0] - w1).norm(), 1e-9) << i;
  }
  EXPECT_GT(separated, 200);
}

// Nearly parallel faces facing each other put thousands of vertices into both windows (a hostile
// review: two 10^5-gons 1e-11 rad from parallel took 2.3 s, quadratic in the vertices); the
// windows' search must still give the full enumeration's answer and the brute force's distance,
// with B's vertices over A's and turned by a third of an edge, at the tilts just above the 1e-12
// that counts as parallel too, where every vertex of B is within a few 1e-12 of the lowest.
TEST(LargePolygons, NearlyParallelFacesAgreeWithEnumerationAndBruteForce) {
  Eigen::MatrixX2d C(600, 2);
  for (int k = 0; k < 600; ++k)
    C.row(k) << std::cos(2 * M_PI * k / 600), std::sin(2 * M_PI * k / 600);
  const PaddedPolygon disc(C, Eigen::VectorXd::Ones(600), 0.0);
  std::vector<Eigen::Vector3d> body;
  for (const auto& v : disc.vertices().rowwise()) body.emplace_back(v.x(), v.y(), 0.0);
  const TestShape shape{disc, body, 1.0};
  int compared = 0;
  for (const double tilt : {2e-12, -5e-12, 1e-11, -1e-10, 1e-9, 1e-7}) {
    for (const int axis : {0, 1, 2}) {  // 2: about x, B turned by a third of an edge
      for (const Eigen::Vector3d& offset :
           {Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d(1.5, 0, 0.5),
            Eigen::Vector3d(1.999, 0, 1e-6), Eigen::Vector3d(0, 0, 1e-9),
            Eigen::Vector3d(0.3, -0.2, 1e-9)}) {
        Eigen::Vector4d q(std::cos(tilt / 2), 0, 0, 0);
        q(1 + axis % 2) = std::sin(tilt / 2);
        if (axis == 2) {
          const double turn = 2 * M_PI / 600 / 3;
          const Eigen::Quaterniond turned =
              Eigen::Quaterniond(q(0), q(1), q(2), q(3)) *
              Eigen::Quaterniond(std::cos(turn / 2), 0, 0, std::sin(turn / 2));
          q << turned.w(), turned.x(), turned.y(), turned.z();
        }
        const Pose pa(Eigen::Vector3d::Zero(), kIdentity), pb(offset, q);
        const ClosestPair reference = brute_force_closest(to_world(shape, pa), to_world(shape, pb));
        if (reference.distance <= 1e-12) continue;  // touching: not for the separated solvers
        const BothPaths paths = both_paths(disc, pa, disc, pb);
        const Eigen::Vector3d w1 = world(paths.a, paths.windows[0]);
        const Eigen::Vector3d w2 = world(paths.b, paths.windows[1]);
        // The windows' certificates hold to the tie tolerance (2e-12 of the polygons' size):
        // at a tilt of 1e-11 a face is level to within the certificate's slack over the whole
        // window. At (0.3, -0.2, 1e-9), tilted 1e-10, the gap came out 5% too large (9.43e-10
        // for 9.00e-10) until the windows' direction was freed of the points' rounding.
        const double enumerated =
            (world(paths.a, paths.enumeration[0]) - world(paths.b, paths.enumeration[1])).norm();
        ASSERT_NEAR(enumerated, static_cast<double>(reference.distance), 1e-12)
            << tilt << " " << axis << " " << offset.transpose();
        ASSERT_NEAR((w1 - w2).norm(), enumerated, 4e-12)
            << tilt << " " << axis << " " << offset.transpose();
        ++compared;
      }
    }
  }
  EXPECT_GE(compared, 78);  // of 90: the rest touch
}

// Ties at large sizes: the half-ellipse's straight edge parallel to a square's edge, beside it
// and above it, and a vertex or an edge of one over the face of a 2000-gon.
TEST(LargePolygons, TiesAndFacesMatchTheEnumeration) {
  Rng rng(18);
  for (int i = 0; i < 60; ++i) {
    const TestShape half = many_sided(rng, 200, true);
    const auto& polygon = std::get<PaddedPolygon>(half.shape);
    // The straight edge closes the polygon, from the last body vertex to the first.
    const Eigen::Vector3d start = half.body_vertices[199], end = half.body_vertices[0];
    const Eigen::Vector3d along = (end - start).normalized();
    const Eigen::Vector3d outward(along.y(), -along.x(), 0.0);
    // A 64-gon square-ish polygon whose edge faces the straight edge: a regular 64-gon rotated so
    // that one edge is parallel to it, 0.3 away, sideways by a random amount, raised by h.
    const int sides = 64;
    Eigen::MatrixX2d C(sides, 2);
    for (int k = 0; k < sides; ++k) {
      C.row(k) << std::cos(2 * M_PI * k / sides), std::sin(2 * M_PI * k / sides);
    }
    const PaddedPolygon round(C, Eigen::VectorXd::Constant(sides, 0.2), 0.0);
    const double angle = std::atan2(-outward.y(), -outward.x());  // row 0 faces the edge
    const double h = (i % 3) * 0.1;
    const Eigen::Vector3d centre = 0.5 * (start + end) + outward * 0.5 +
                                   along * std::uniform_real_distribution<double>(-0.3, 0.3)(rng) +
                                   Eigen::Vector3d(0, 0, h);
    const Pose pa({0, 0, 0}, kIdentity), pb(centre, about(angle, 0, 0, 1));
    const BothPaths paths = both_paths(polygon, pa, round, pb);
    // The middle of the overlap is the midpoint of the 64-gon's short facing edge.
    const Eigen::Vector3d midpoint = centre - 0.2 * outward;
    ASSERT_LE((world(paths.b, paths.windows[1]) - midpoint).norm(), 1e-9) << i;
    ASSERT_LE(
        (world(paths.a, paths.windows[0]) - (midpoint - 0.3 * outward - Eigen::Vector3d(0, 0, h)))
            .norm(),
        1e-9)
        << i;
    for (int side = 0; side < 2; ++side) {
      const detail::PosedCore& core = side == 0 ? paths.a : paths.b;
      ASSERT_LE((world(core, paths.windows[side]) - world(core, paths.enumeration[side])).norm(),
                1e-9)
          << i;
    }
  }
  // A square hovering over a 2000-gon: a vertex over its face, then an edge parallel to it.
  Eigen::MatrixX2d C(2000, 2);
  for (int k = 0; k < 2000; ++k)
    C.row(k) << std::cos(2 * M_PI * k / 2000), std::sin(2 * M_PI * k / 2000);
  const PaddedPolygon disc(C, Eigen::VectorXd::Constant(2000, 1.0), 0.0);
  const PaddedPolygon small = square(0.25, 0.0);
  const Pose corner_down({0.2, 0.1, 0.6}, about(0.7, 1, 1, 0));
  const Pose edge_down({0.9, 0.1, 0.4}, about(M_PI / 4, 0, 1, 0));
  for (const Pose& pose : {corner_down, edge_down}) {
    for (const bool disc_first : {true, false}) {
      const BothPaths paths = disc_first ? both_paths(disc, Pose(), small, pose)
                                         : both_paths(small, pose, disc, Pose());
      for (int side = 0; side < 2; ++side) {
        const detail::PosedCore& core = side == 0 ? paths.a : paths.b;
        ASSERT_LE((world(core, paths.windows[side]) - world(core, paths.enumeration[side])).norm(),
                  1e-9);
      }
    }
  }
  // The edge x = 0.9 + 0.25/sqrt(2) .. hangs over the disc's rim: the middle of its part over the
  // disc, against the public query in both orders.
  const Proximity over = proximity(small, edge_down, disc, Pose());
  const Proximity under = proximity(disc, Pose(), small, edge_down);
  EXPECT_LE((over.core_points[0] - under.core_points[1]).norm(), 1e-9);
  EXPECT_NEAR(over.core_points[1].z(), 0.0, 1e-12);
}

// Large windows of polygons within 1,000 intersection tolerances of their size ("specks", as two
// polygons 1e12 times their size apart are), searched in hierarchies bounding depth along the
// line between them and offset across it (depth_box_tree.hpp) with a band of 0 and no pass over
// parallel edges: only pairs that can be closer than the best are solved. Exercised where the
// brute force is exact: polygons of size ~1 given a tolerance of 1,000, at distances of 0.5 and
// 100 sizes beyond touching, in both orders, with random poses: the search called on windows
// holding every vertex, and the windows (which take both polygons whole at that tolerance) on the
// same pairs. In the public queries polygons reach the speck regimes where the distance makes the
// scene (PolygonPolygon_FarApart); where radii make it, two polygons are solved at their cores'
// own tolerances (pair_setup.hpp) and are specks only as the bare cores would be. No bound may
// leave out a closer pair: both distances are the brute force's to rounding. (Their cost, about
// linear against ka kb before: BENCHMARKS.md.)
TEST(LargePolygons, SpeckWindowsLeaveNoCloserPairOut) {
  Rng rng(41);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int trial = 0; trial < 40; ++trial) {
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    const TestShape a = many_sided(rng, 100 + 10 * trial, trial % 5 == 0);
    const TestShape b = many_sided(rng, 150 + 7 * trial, trial % 7 == 0);
    const double beyond = trial % 2 == 0 ? 0.5 : 100.0 * (a.size + b.size);
    const Eigen::Vector3d direction =
        Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng)).normalized();
    const Pose pa = random_pose(rng, 1.0);
    const Pose pb(pa.r() + (a.size + b.size + beyond) * direction, random_pose(rng, 1.0).q());
    const long double reference = brute_force_closest(to_world(a, pa), to_world(b, pb)).distance;
    const auto& polygon_a = std::get<PaddedPolygon>(a.shape);
    const auto& polygon_b = std::get<PaddedPolygon>(b.shape);
    for (const bool swapped : {false, true}) {
      const PaddedPolygon& first = swapped ? polygon_b : polygon_a;
      const PaddedPolygon& second = swapped ? polygon_a : polygon_b;
      const Pose& p1 = swapped ? pb : pa;
      const Pose& p2 = swapped ? pa : pb;
      const WholeWindows whole = search_whole_windows(first, p1, second, p2, 1e3, 1e-13);
      const detail::PolygonView view_1(first, 1.0), view_2(second, 1.0);
      const detail::PolygonPairFrame frame(whole.core_1, whole.core_2);
      const detail::CarriedPolygon<detail::PolygonView> W(view_2, frame.b_in_a,
                                                          frame.b_origin_in_a);
      const Sides windows =
          detail::closest_separated_by_windows(view_1, view_2, frame, W, 1e3, 1e-13);
      for (const Sides& sides : {whole.sides, windows}) {
        const double distance =
            (world(whole.core_1, sides[0]) - world(whole.core_2, sides[1])).norm();
        EXPECT_NEAR(distance, static_cast<double>(reference), 1e-12 * (1.0 + distance))
            << (swapped ? "b, a" : "a, b") << (&sides == &windows ? ", windows" : ", searched");
      }
    }
  }
}

// The lower half of the ellipse x^2 + 4 y^2 <= 1 as a polygon of `count` vertices, its straight
// edge on top along y = 0 from x = -1 to 1, given in a body frame turned by `turn` about z with
// the origin at (0, -0.2).
PaddedPolygon half_ellipse(int count, double turn) {
  const Eigen::Vector2d origin(0.0, -0.2);
  const Eigen::Matrix2d rotation = Eigen::Rotation2Dd(turn).toRotationMatrix();
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < count; ++i) {
    const double angle = M_PI + M_PI * i / (count - 1);
    points.emplace_back(rotation *
                        (Eigen::Vector2d(std::cos(angle), 0.5 * std::sin(angle)) - origin));
  }
  Eigen::MatrixX2d C(count, 2);
  Eigen::VectorXd d(count);
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector2d p = points[i], q = points[(i + 1) % count];
    const Eigen::Vector2d normal = Eigen::Vector2d(q.y() - p.y(), p.x() - q.x()).normalized();
    C.row(i) = normal.transpose();
    d(i) = normal.dot(p);
  }
  return PaddedPolygon(C, d, 0.0);
}

// Large windows' intervals: two half-ellipses of 400 vertices with their straight edges facing,
// parallel, 0.3 apart and shifted by `shift` along them: in one plane, B raised out of A's plane,
// or B turned about its straight edge. The closest set is the overlap of the two straight edges,
// and its middle must be returned in both orders, after a rigid motion of the whole scene, with the
// straight edge at any place in the polygons' edge order (the body frames turned), by the search
// of large windows (windows holding every vertex) as by the full enumeration of small ones. B is
// also turned about the normal by up to 6e-15 rad, parallel within the tie band. The search for
// closer points leaves out chain pairs that can only tie, so it meets the straight edges' pair
// only when its chains happen to be visited first; without the pass over parallel edge pairs
// (offer_parallel_edge_pairs) an end of the overlap came back where B is raised and 6e-15 rad
// off, with the edges along the frames' axes (trials 250 and 310 as first written, 310 now).
TEST(LargePolygons, LargeWindowsReturnTheMiddleOfParallelEdges) {
  Rng rng(43);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const double gap = 0.3;
  for (int trial = 0; trial < 480; ++trial) {
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    // Even trials: the straight edges along the body frames' axes, where the chains' boxes in
    // the frame of A's normal are tight. Odd ones: turned by 48ths of a turn.
    const bool quarter = trial % 2 == 0;
    const int quarters_a = trial % 8 / 2, quarters_b = trial % 16 / 4;  // whole quarter turns
    const double turn_a = quarter ? M_PI / 2 * quarters_a : 2 * M_PI * trial / 48;
    const double turn_b = quarter ? M_PI / 2 * quarters_b : 2 * M_PI * (trial * 7 % 48) / 48;
    const PaddedPolygon a = half_ellipse(400, turn_a), b = half_ellipse(400, turn_b);
    // No shift puts the straight edges right across the line between the polygons' boxes, where
    // the chains' bounds are exact and every chain pair holding a point of the overlap ties.
    const double shift = trial % 4 == 0 ? 0.0 : 0.2 + 0.5 * (uniform(rng) + 1.0);
    const double raise = trial % 3 == 1 ? 0.4 : 0.0, tilt = trial % 3 == 2 ? 0.7 : 0.0;
    // A's straight edge along the world x axis from -1 to 1, B's flipped over it (its dome on the
    // far side), gap away, then raised or turned by `tilt` about its own straight edge.
    const Eigen::Quaterniond flip(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
    // Turned about the normal by a few 1e-15 rad as well: within the tie band of parallel.
    const double skew = 3e-15 * (trial % 5 - 2);
    const Eigen::Quaterniond lean =
        Eigen::Quaterniond(Eigen::AngleAxisd(skew, Eigen::Vector3d::UnitZ())) *
        Eigen::Quaterniond(Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX()));
    const Eigen::Quaterniond body_a(Eigen::AngleAxisd(-turn_a, Eigen::Vector3d::UnitZ()));
    const Eigen::Quaterniond body_b(Eigen::AngleAxisd(-turn_b, Eigen::Vector3d::UnitZ()));
    const Eigen::Vector3d edge_b(shift, gap, raise);  // the middle of B's straight edge
    const auto wxyz = [](const Eigen::Quaterniond& q) {
      return Eigen::Vector4d(q.w(), q.x(), q.y(), q.z());
    };
    const Pose pa(Eigen::Vector3d(0.0, -0.2, 0.0), wxyz(body_a));
    const Pose pb(edge_b + lean * (flip * Eigen::Vector3d(0.0, -0.2, 0.0)),
                  wxyz(lean * flip * body_b));
    const Eigen::Vector3d middle_a(0.5 * shift, 0.0, 0.0), middle_b(0.5 * shift, gap, raise);
    const Eigen::Quaterniond motion =
        Eigen::Quaterniond(Eigen::Vector4d(uniform(rng), uniform(rng), uniform(rng), 1.0))
            .normalized();
    const Eigen::Vector3d moved(uniform(rng), uniform(rng), uniform(rng));
    const Pose moved_a = rigidly_moved(pa, motion, moved),
               moved_b = rigidly_moved(pb, motion, moved);
    const std::array<Eigen::Vector3d, 2> expected = {motion * middle_a + moved,
                                                     motion * middle_b + moved};
    for (const bool swapped : {false, true}) {
      SCOPED_TRACE(swapped ? "b, a" : "a, b");
      const PaddedPolygon& first = swapped ? b : a;
      const PaddedPolygon& second = swapped ? a : b;
      const Pose& p1 = swapped ? moved_b : moved_a;
      const Pose& p2 = swapped ? moved_a : moved_b;
      const detail::PairFrame scales =
          detail::make_pair_frame(first.extent(), 0.0, second.extent(), 0.0, p1.r(), p2.r());
      const WholeWindows whole =
          search_whole_windows(first, p1, second, p2, scales.tolerance * scales.scale,
                               scales.tie_tolerance * scales.scale);
      EXPECT_LE((world(whole.core_1, whole.sides[0]) - expected[swapped ? 1 : 0]).norm(), 1e-9);
      EXPECT_LE((world(whole.core_2, whole.sides[1]) - expected[swapped ? 0 : 1]).norm(), 1e-9);
    }
  }
}

// A 1000:1 ellipse of `count` vertices (from angle `phase`), 2 kNeedleLength long, padded by
// `radius`; with its body vertices.
constexpr double kNeedleLength = 2e-11;
TestShape needle(int count, double phase, double radius) {
  Eigen::MatrixX2d C(count, 2);
  Eigen::VectorXd d(count);
  TestShape out{Capsule(0, 0), {}, kNeedleLength};
  const auto at = [&](int k) {
    const double angle = phase + 2 * M_PI * k / count;
    return Eigen::Vector2d(1e-3 * kNeedleLength * std::cos(angle), kNeedleLength * std::sin(angle));
  };
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector2d p = at(i), q = at(i + 1);
    const Eigen::Vector2d n = Eigen::Vector2d(q.y() - p.y(), p.x() - q.x()).normalized();
    C.row(i) = n.transpose();
    d(i) = n.dot(p);
    out.body_vertices.emplace_back(p.x(), p.y(), 0.0);
  }
  out.shape = PaddedPolygon(C, d, radius);
  return out;
}

// `shape` scaled by `factor` (the rows keep their normals, the offsets scale), padded by `radius`.
TestShape shrunk(const TestShape& shape, double factor, double radius) {
  const auto& polygon = std::get<PaddedPolygon>(shape.shape);
  TestShape out{
      PaddedPolygon(polygon.constraint_matrix(), factor * polygon.constraint_offsets(), radius),
      shape.body_vertices, factor * shape.size};
  for (Eigen::Vector3d& vertex : out.body_vertices) vertex *= factor;
  return out;
}

// Two needles (radius 1, shrunk by `factor`) crossing or within a few widths at a random pose,
// and their cores' signed gap by the brute force: the distance when apart, else minus the
// separating-axis depth.
struct NeedlePair {
  TestShape a, b;
  Pose pa, pb;
  long double apart = 0.0;
  double gap = 0.0;
};
NeedlePair random_needle_pair(Rng& rng, std::normal_distribution<double>& normal, int trial,
                              double factor) {
  NeedlePair out{shrunk(needle(36 + trial, 0.0, 1.0), factor, 1.0),
                 shrunk(needle(40 + 2 * trial, 0.3, 1.0), factor, 1.0),
                 Pose(),
                 Pose(),
                 0.0,
                 0.0};
  const Eigen::Vector4d q(normal(rng), normal(rng), normal(rng), normal(rng));
  out.pb = Pose(
      1e-3 * factor * kNeedleLength * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)), q);
  const WorldCore wa = to_world(out.a, out.pa), wb = to_world(out.b, out.pb);
  out.apart = brute_force_closest(wa, wb).distance;
  out.gap = static_cast<double>(out.apart > 0 ? out.apart : -brute_force_penetration_depth(wa, wb));
  return out;
}

// Needles far thinner than the tolerance their radii set (the radii make the scene): 1000:1
// ellipses 4e-11 long, radius 1 or 0, at random poses within a few needle lengths. Before two
// polygons were solved at their cores' own tolerances (pair_setup.hpp, search_tolerances), every
// vertex of each tied with its support at the scene's, and a pair crossing each other's planes
// swept nearly all edge pairs (4x10^4 vertices: 1.6-1.9 s, PolygonPolygon_Needles); the answer
// must be unchanged: the cores' distance the brute force's to rounding, with radius 1 as with
// radius 0, in both orders.
TEST(LargePolygons, NeedlesThinnerThanTheTolerance) {
  Rng rng(59);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double length = kNeedleLength;
  const auto ellipse = needle;
  int apart = 0;
  for (int trial = 0; trial < 20; ++trial) {
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    const TestShape a = ellipse(200 + 17 * trial, 0.0, 1.0),
                    b = ellipse(260 + 13 * trial, 0.3, 1.0);
    const TestShape bare_a = ellipse(200 + 17 * trial, 0.0, 0.0);
    const TestShape bare_b = ellipse(260 + 13 * trial, 0.3, 0.0);
    const Eigen::Vector4d q(normal(rng), normal(rng), normal(rng), normal(rng));
    const Pose pa(Eigen::Vector3d::Zero(), kIdentity);
    const Pose pb(1.5 * length * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)), q);
    const long double reference = brute_force_closest(to_world(a, pa), to_world(b, pb)).distance;
    if (reference < 1e-3 * length) continue;  // the cores meet: not the windows' case
    ++apart;
    const auto core_distance = [](const Proximity& p) {
      return (p.core_points[0] - p.core_points[1]).norm();
    };
    const auto& padded_a = std::get<PaddedPolygon>(a.shape);
    const auto& padded_b = std::get<PaddedPolygon>(b.shape);
    const Proximity ab = proximity(padded_a, pa, padded_b, pb);
    const Proximity ba = proximity(padded_b, pb, padded_a, pa);
    const Proximity bare = proximity(std::get<PaddedPolygon>(bare_a.shape), pa,
                                     std::get<PaddedPolygon>(bare_b.shape), pb);
    // The closest points of two ellipses are unique: both orders find them to the cores' rounding.
    const double within = 1e-12 * length;
    EXPECT_NEAR(core_distance(ab), static_cast<double>(reference), within);
    EXPECT_NEAR(core_distance(ba), static_cast<double>(reference), within);
    EXPECT_NEAR(core_distance(bare), static_cast<double>(reference), within);
    EXPECT_LE((ab.core_points[0] - ba.core_points[1]).norm(), 1e-6 * length);
    EXPECT_LE((ab.core_points[1] - ba.core_points[0]).norm(), 1e-6 * length);
  }
  EXPECT_GE(apart, 10);
}

// The same needles' signed distances, crossing or within a few widths (the penetration search of
// penetration.hpp, which the radii's scale also left ruling no edge pair out: two crossing
// 64,000-gons took 11 s): the cores' signed gap equals the separating-axis brute force's depth,
// or the closest distance when apart, to the rounding of the scene (radius 1), in both orders,
// with opposite normals.
TEST(LargePolygons, NeedleSignedDistancesThinnerThanTheTolerance) {
  Rng rng(61);
  std::normal_distribution<double> normal(0.0, 1.0);
  int penetrating = 0;
  for (int trial = 0; trial < 30; ++trial) {
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    const NeedlePair pair = random_needle_pair(rng, normal, trial, 1.0);
    penetrating += pair.apart > 0 ? 0 : 1;
    const auto& padded_a = std::get<PaddedPolygon>(pair.a.shape);
    const auto& padded_b = std::get<PaddedPolygon>(pair.b.shape);
    const SignedDistance ab = signed_distance(padded_a, pair.pa, padded_b, pair.pb);
    const SignedDistance ba = signed_distance(padded_b, pair.pb, padded_a, pair.pa);
    // distance = gap - 2 in a frame of scene 2: a few ulps of 2.
    EXPECT_NEAR(ab.distance + 2.0, pair.gap, 2e-15);
    EXPECT_EQ(ab.distance, ba.distance);
    EXPECT_LE((ab.normal + ba.normal).norm(), 1e-12);
  }
  EXPECT_GE(penetrating, 12);
}

// The same needles shrunk by 1e-95, 2e-106 long beside radii of 1: cores below 1e-100 of the
// frame's units keep the frame's tolerances (pair_frame.hpp), 1e94 times their size, so the
// penetration search took every depth as touching and returned the closest points, a gap of 0,
// for cores 1e-109 deep, and met every facet (1.8 s at 8,000 vertices). The signed distance now
// solves such cores in a frame of their own: the witnesses' gap along the normal is the brute
// force's signed gap to 1e-12 of the needles' length, in both orders, with opposite normals.
TEST(LargePolygons, NeedleSignedDistancesBelow1e100OfTheirRadii) {
  Rng rng(62);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double shrink = 1e-95, length = shrink * kNeedleLength;
  int penetrating = 0;
  for (int trial = 0; trial < 30; ++trial) {
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    const NeedlePair pair = random_needle_pair(rng, normal, trial, shrink);
    penetrating += pair.apart > 0 ? 0 : 1;
    const auto& padded_a = std::get<PaddedPolygon>(pair.a.shape);
    const auto& padded_b = std::get<PaddedPolygon>(pair.b.shape);
    const SignedDistance ab = signed_distance(padded_a, pair.pa, padded_b, pair.pb);
    const SignedDistance ba = signed_distance(padded_b, pair.pb, padded_a, pair.pa);
    const auto core_gap = [](const SignedDistance& s) {
      return (s.core_points[1] - s.core_points[0]).dot(s.normal);
    };
    EXPECT_NEAR(core_gap(ab), pair.gap, 1e-12 * length);
    EXPECT_NEAR(core_gap(ba), pair.gap, 1e-12 * length);
    EXPECT_EQ(ab.penetrating, pair.apart <= 0);
    EXPECT_LE((ab.normal + ba.normal).norm(), 1e-12);
    EXPECT_LE((ab.core_points[0] - ba.core_points[1]).norm(), 1e-12 * length);
  }
  EXPECT_GE(penetrating, 12);
}

// Shrunk by 1e-135 to 1e-185 (cores 2e-146 to 2e-196 long beside radii of 1): below 1e-140 of
// the frame, cores keep its tolerances, which then exceed the whole pair, and touch at any gap
// (signed_distance.hpp). The penetration search met every facet as a tie there (crossing needles
// 1e-145 long: 1.5 s at 8,000 vertices, growing as k^2); they are answered without it. In both
// orders: distance -2 exactly, touching (penetrating), opposite normals, finite derivatives, each
// core point within its needle's length of its origin.
TEST(LargePolygons, NeedleSignedDistancesBelow1e140OfTheirRadiiTouch) {
  Rng rng(63);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int trial = 0; trial < 11; ++trial) {
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    const double shrink = std::pow(10.0, -135.0 - 5.0 * trial);
    const NeedlePair pair = random_needle_pair(rng, normal, trial, shrink);
    const SignedDistanceHessian ab =
        signed_distance_hessian(pair.a.shape, pair.pa, pair.b.shape, pair.pb);
    const SignedDistanceHessian ba =
        signed_distance_hessian(pair.b.shape, pair.pb, pair.a.shape, pair.pa);
    for (const SignedDistanceHessian* s : {&ab, &ba}) {
      EXPECT_EQ(s->distance, -2.0);
      EXPECT_TRUE(s->penetrating);
      EXPECT_TRUE(s->gradient.allFinite());
      EXPECT_TRUE(s->points_jacobian.allFinite() && s->core_points_jacobian.allFinite());
      EXPECT_TRUE(s->hessian.allFinite());
    }
    EXPECT_LE((ab.normal + ba.normal).norm(), 1e-12);
    const double length = shrink * kNeedleLength;
    EXPECT_LE((ab.core_points[0] - pair.pa.r()).norm(), length);
    EXPECT_LE((ab.core_points[1] - pair.pb.r()).norm(), length);
  }
}

// Cores from 5e-10 to 1e-6 of the radii that make the scene (a hostile review: discs just above
// the 1e-9 below which a pair counted as specks took 0.8-1.3 s at 10^5 vertices, 1,000x the same
// cores with radius 0, with ~1,400 vertices of each within the scene's tolerance of a support), and
// needles apart by about that tolerance, whose signed distance came out -7e-14 and penetrating for
// a gap of 1.04e-12: two polygons are solved at their cores' own tolerances. The cores' distance
// and signed gap must be the brute force's, with radius 1 as with radius 0 and in both orders.
TEST(LargePolygons, CoresFarSmallerThanTheirRadii) {
  Rng rng(67);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int trial = 0; trial < 24; ++trial) {
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    const double size = std::pow(10.0, -9.3 + 0.15 * trial);
    const TestShape a = shrunk(many_sided(rng, 40 + trial, trial % 4 == 0), size, 1.0);
    const TestShape b = shrunk(many_sided(rng, 45 + trial, trial % 5 == 0), size, 1.0);
    const Pose pa(size * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)),
                  Eigen::Vector4d(normal(rng), normal(rng), normal(rng), normal(rng)));
    const Pose pb(pa.r() + 2.5 * size * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)),
                  Eigen::Vector4d(normal(rng), normal(rng), normal(rng), normal(rng)));
    const WorldCore wa = to_world(a, pa), wb = to_world(b, pb);
    const long double apart = brute_force_closest(wa, wb).distance;
    const double gap =
        static_cast<double>(apart > 0 ? apart : -brute_force_penetration_depth(wa, wb));
    const auto& padded_a = std::get<PaddedPolygon>(a.shape);
    const auto& padded_b = std::get<PaddedPolygon>(b.shape);
    const PaddedPolygon bare_a(padded_a.constraint_matrix(), padded_a.constraint_offsets(), 0.0);
    const PaddedPolygon bare_b(padded_b.constraint_matrix(), padded_b.constraint_offsets(), 0.0);
    const Proximity ab = proximity(padded_a, pa, padded_b, pb);
    const Proximity ba = proximity(padded_b, pb, padded_a, pa);
    const Proximity bare = proximity(bare_a, pa, bare_b, pb);
    const SignedDistance sd_ab = signed_distance(padded_a, pa, padded_b, pb);
    const SignedDistance sd_ba = signed_distance(padded_b, pb, padded_a, pa);
    // Rounding: the cores' coordinates reach ~10 sizes; the signed distance adds the radii, 2.
    const double within = 1e-12 * size;
    if (apart > 0) {
      const auto core_distance = [](const Proximity& p) {
        return (p.core_points[0] - p.core_points[1]).norm();
      };
      EXPECT_NEAR(core_distance(ab), static_cast<double>(apart), within);
      EXPECT_NEAR(core_distance(ba), static_cast<double>(apart), within);
      EXPECT_LE((ab.core_points[0] - bare.core_points[0]).norm(), 1e-9 * size);
      EXPECT_LE((ab.core_points[0] - ba.core_points[1]).norm(), 1e-9 * size);
    }
    EXPECT_NEAR(sd_ab.distance + 2.0, gap, 4e-16 + within);
    EXPECT_EQ(sd_ab.distance, sd_ba.distance);
    EXPECT_EQ(sd_ab.penetrating, apart == 0);  // the cores' penetration, not the padded shapes'
  }
  // The review's needles, 1.04e-12 apart: a gap, found as for radius 0.
  const Eigen::Vector4d q(0.4560115303701098, -0.5485457321125106, 0.5936640938504344,
                          0.3724432945072346);
  const Pose pb(
      Eigen::Vector3d(5.88264993311052e-13, 5.684448263159357e-14, 1.0934259732248938e-12), q);
  for (const int count : {200, 1200}) {
    const TestShape a = needle(count, 0.0, 1.0), b = needle(count + 13, 0.3, 1.0);
    const long double apart = brute_force_closest(to_world(a, Pose()), to_world(b, pb)).distance;
    ASSERT_GT(apart, 1e-12);
    for (const bool swapped : {false, true}) {
      const SignedDistance sd = swapped ? signed_distance(std::get<PaddedPolygon>(b.shape), pb,
                                                          std::get<PaddedPolygon>(a.shape), Pose())
                                        : signed_distance(std::get<PaddedPolygon>(a.shape), Pose(),
                                                          std::get<PaddedPolygon>(b.shape), pb);
      EXPECT_NEAR(sd.distance + 2.0, static_cast<double>(apart), 4e-16) << count << swapped;
      EXPECT_NEAR((sd.core_points[1] - sd.core_points[0]).norm(), static_cast<double>(apart),
                  1e-12 * kNeedleLength)
          << count << swapped;
    }
  }
}

// 10^5-gons: analytic answers. Two coplanar regular polygons side by side (apothem 1, centres
// 2.5 apart: edge midpoints 0.5 apart), a sphere above the face and beside the rim.
TEST(LargePolygons, HundredThousandGons) {
  const int count = 100000;
  Eigen::MatrixX2d C(count, 2);
  for (int k = 0; k < count; ++k)
    C.row(k) << std::cos(2 * M_PI * k / count), std::sin(2 * M_PI * k / count);
  const PaddedPolygon disc(C, Eigen::VectorXd::Constant(count, 1.0), 0.1);
  ASSERT_EQ(disc.vertices().rows(), count);
  const Proximity side = proximity(disc, Pose(), disc, Pose({2.5, 0, 0}, kIdentity));
  EXPECT_NEAR(side.phi, 0.25 - 0.04, 1e-12);
  const Proximity tilted =
      proximity(disc, Pose(), disc, Pose({2.5, 0, 0}, about(0.3, 1, 0, 0)));  // rim to rim
  EXPECT_NEAR(tilted.phi, 0.25 - 0.04, 1e-9);
  const Proximity above = proximity(Capsule(0, 0), Pose({0.2, 0.3, 2}, kIdentity), disc, Pose());
  EXPECT_NEAR(above.phi, 4.0 - 0.01, 1e-12);
}

// Polygons far smaller than the distance between them (found by fuzz_proximity): in the pair's
// frame their vertices are of order 1e-200, whose squares underflow, and a window's chords must
// still bound it. The closest points lie on the two polygons, whichever comes first.
TEST(LargePolygons, PolygonsFarSmallerThanTheirDistance) {
  const auto regular = [](int count, double apothem, double radius) {
    Eigen::MatrixX2d C(count, 2);
    for (int k = 0; k < count; ++k)
      C.row(k) << std::cos(2 * M_PI * k / count), std::sin(2 * M_PI * k / count);
    return PaddedPolygon(C, Eigen::VectorXd::Constant(count, apothem), radius);
  };
  const PaddedPolygon large = regular(293, 4e4, 0.0), speck = regular(293, 5e-115, 0.0);
  const Pose at_origin(Eigen::Vector3d::Zero(), Eigen::Vector4d(0.3, 0.3, 0.3, 0.3001));
  const Pose far(Eigen::Vector3d(2, -6e87, 3e-115), kIdentity);
  const Proximity ab = proximity(large, at_origin, speck, far);
  const Proximity ba = proximity(speck, far, large, at_origin);
  EXPECT_LE((ab.core_points[0]).norm(), 1.01 * large.extent());
  EXPECT_LE((ab.core_points[1] - far.r()).norm(), 1e-100);
  // Every point of the large polygon is as close as any other to 1e-83 of the distance: they all
  // tie, and either order may return any of them; the documented swap symmetry is to 1e-9 of
  // the scene's size (6e87).
  EXPECT_LE((ab.core_points[0] - ba.core_points[1]).norm(), 1e-9 * 6e87);
  EXPECT_LE((ab.core_points[1] - ba.core_points[0]).norm(), 1e-9 * 6e87);
  EXPECT_DOUBLE_EQ(ab.phi, 3.6e175);
  EXPECT_EQ(ab.phi, ba.phi);

  // Two polygons whose vertices all underflow to their origins in the frame, one origin in the
  // other's plane: a window of three coincident vertices would be an unbounded wedge.
  const PaddedPolygon a = regular(461, 1e-300, 0.25), b = regular(293, 2e-300, 0.0);
  const Pose pa(Eigen::Vector3d(-4.2e78, 3.1e-115, 9e-188), about(M_PI / 2, 1, 0, 0));
  const Pose pb(Eigen::Vector3d(1.5, 3.05e-115, 3), about(M_PI, 1, 0, 0));
  for (const Method method : {Method::kDefault, Method::kInteriorPoint}) {
    const Proximity apart = proximity(a, pa, b, pb, {method});
    EXPECT_EQ(apart.core_points[0], pa.r());
    EXPECT_EQ(apart.core_points[1], pb.r());
    EXPECT_DOUBLE_EQ(apart.phi, (pa.r() - pb.r()).squaredNorm() - 0.0625);
    EXPECT_FALSE(apart.cores_intersect);
  }
}

// A regular polygon whose rows are the unit normals at angles 2 pi k / count and offsets the
// apothem; its vertices computed here, at the angles (2k + 1) pi / count between the rows.
TestShape regular_polygon(int count, double apothem) {
  Eigen::MatrixX2d C(count, 2);
  std::vector<Eigen::Vector3d> body;
  const double circumradius = apothem / std::cos(M_PI / count);
  for (int k = 0; k < count; ++k) {
    C.row(k) << std::cos(2 * M_PI * k / count), std::sin(2 * M_PI * k / count);
    const double between = (2 * k + 1) * M_PI / count;
    body.emplace_back(circumradius * std::cos(between), circumradius * std::sin(between), 0.0);
  }
  return {PaddedPolygon(C, Eigen::VectorXd::Constant(count, apothem), 0.0), body, circumradius};
}

// Shapes far apart compared to their size, parallel, one to the side of the other's shadow: the
// far side of a polygon is farther than the near side by only (H^2 - h^2) / 2V for a distance V
// and horizontal offsets h < H. Ties judged by 1e-12 of the scene's size (which includes V) let an
// edge of the far side, parallel to the other's, win over the near side's vertex: points 1e-6 of
// the scene off, and phi 1e-12 relative, different in the two orders (found by fuzz_proximity at
// V = 2.9e76, polygons of 3 and 1e70). Both orders must give the brute force's points to 1e-9 of
// the scene, for the windows (51-gons) and the enumeration (hexagons), and for a capsule, up to
// V = 1e5 times the shapes' size. (Beyond ~1e6, neighbouring candidates' distances differ by less
// than the tie tolerance's 64 ulps of the scene: the points are then as good as the distances.)
TEST(LargePolygons, FarApartShapesKeepTheirNearSides) {
  const Eigen::Vector4d flipped(0, 0, 1, 0);  // half a turn about y: the other face up
  const auto expect_near_side = [](const TestShape& a, const Pose& pa, const TestShape& b,
                                   const Pose& pb, double scene) {
    const ClosestPair reference = brute_force_closest(to_world(a, pa), to_world(b, pb));
    const Eigen::Vector3d p1 = reference.p1.cast<double>(), p2 = reference.p2.cast<double>();
    const Proximity ab = std::visit(
        [&](const auto& x, const auto& y) { return proximity(x, pa, y, pb); }, a.shape, b.shape);
    const Proximity ba = std::visit(
        [&](const auto& x, const auto& y) { return proximity(x, pb, y, pa); }, b.shape, a.shape);
    EXPECT_LE((ab.core_points[0] - p1).norm(), 1e-9 * scene) << ab.core_points[0].transpose();
    EXPECT_LE((ab.core_points[1] - p2).norm(), 1e-9 * scene) << ab.core_points[1].transpose();
    EXPECT_LE((ba.core_points[1] - p1).norm(), 1e-9 * scene) << ba.core_points[1].transpose();
    EXPECT_LE((ba.core_points[0] - p2).norm(), 1e-9 * scene) << ba.core_points[0].transpose();
    EXPECT_NEAR(ab.phi, ba.phi, 1e-14 * scene * scene);
  };

  // The fuzz input: a 51-gon of apothem 3 far below one of apothem 1e70, beside its shadow.
  const TestShape speck = regular_polygon(51, 3.0),
                  plate = regular_polygon(51, 1.0352619520185846e70);
  expect_near_side(
      speck, Pose(Eigen::Vector3d(2.0705239040371691e70, 0, -2.877773982520949e76), kIdentity),
      plate, Pose(Eigen::Vector3d::Zero(), flipped), 2.877773982520949e76);

  // A polygon and the same polygon face down, far above, beside its shadow on the ray through a
  // vertex of the first, with a vertex pointing back at it: the nearest pair is those two vertices
  // (unique), and every edge has a parallel partner on the far side. A capsule on the same ray,
  // pointing at the vertex.
  for (const int count : {6, 51}) {
    for (const double small : {1e-3, 1.0}) {
      for (const double height : {1e2, 1e3, 1e4, 1e5}) {
        SCOPED_TRACE(::testing::Message() << count << "-gons, " << small << ", V = " << height);
        const TestShape a = regular_polygon(count, 1.0), b = regular_polygon(count, small);
        const Eigen::Vector3d ray(std::cos(M_PI / count), std::sin(M_PI / count), 0.0);
        const Eigen::Vector3d up(0, 0, height);
        const Pose pa(Eigen::Vector3d::Zero(), kIdentity);
        expect_near_side(a, pa, b, Pose((a.size + b.size + 0.5) * ray + up, flipped), height);
        const TestShape capsule{
            Capsule(small, 0.1),
            {Eigen::Vector3d(-0.5 * small, 0, 0), Eigen::Vector3d(0.5 * small, 0, 0)},
            small};
        expect_near_side(a, pa, capsule,
                         Pose((a.size + small + 0.5) * ray + up, about(M_PI / count, 0, 0, 1)),
                         height);
      }
    }
  }
}

// Polygons 1e5 to 1e9 times their size apart, facing and tilted 1e-9 to 1e-3 rad (a hostile
// review: 35-570 ms at 4,000 vertices, 8.3 s at 16,000 1e8 apart tilted 1e-5). The windows and
// the sweep took every feature pair within the intersection tolerance, 1e-12 of the distance, of
// the best; their features tie only within the tie tolerance (64 ulps of the distance), and the
// windows now judge ties by it alone. The cores' distance stays the brute force's, in both orders,
// also with radii 1e3 times the distance (the cores are solved at their own tolerances). Which of
// the tied points is returned is not pinned here: for faces this far apart and this nearly
// parallel the candidates' distances differ by less than the tie tolerance (proximity.hpp), and
// the two orders may pick different ones (up to 1.6e-6 of the scene in random trials, as before
// this change); both lie on the near faces.
TEST(LargePolygons, FarApartTiltedFaces) {
  Rng rng(71);
  for (int trial = 0; trial < 16; ++trial) {
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    const TestShape a = many_sided(rng, 90 + trial, trial % 3 == 0);
    const TestShape b = many_sided(rng, 110 + trial, trial % 4 == 0);
    const double height = std::pow(10.0, 5.0 + 0.25 * trial);
    const double tilt = std::pow(10.0, -9.0 + 0.4 * trial);
    const double radius = trial % 2 == 0 ? 0.0 : 1e3 * height;
    const Pose pa(Eigen::Vector3d::Zero(), kIdentity);
    const Pose pb(Eigen::Vector3d(0.3, -0.2, height), about(M_PI + tilt, 1, 0, 0));
    const ClosestPair reference = brute_force_closest(to_world(a, pa), to_world(b, pb));
    const auto& core_a = std::get<PaddedPolygon>(a.shape);
    const auto& core_b = std::get<PaddedPolygon>(b.shape);
    const PaddedPolygon padded_a(core_a.constraint_matrix(), core_a.constraint_offsets(), radius);
    const PaddedPolygon padded_b(core_b.constraint_matrix(), core_b.constraint_offsets(), radius);
    const Proximity ab = proximity(padded_a, pa, padded_b, pb);
    const Proximity ba = proximity(padded_b, pb, padded_a, pa);
    // The cores' distance to the rounding of the distance between them (64 ulps).
    const double within = 64 * std::numeric_limits<double>::epsilon() * height;
    const auto core_distance = [](const Proximity& p) {
      return (p.core_points[1] - p.core_points[0]).norm();
    };
    EXPECT_NEAR(core_distance(ab), static_cast<double>(reference.distance), within);
    EXPECT_NEAR(core_distance(ba), static_cast<double>(reference.distance), within);
    EXPECT_NEAR(ab.core_points[0].z(), 0.0, 1e-12);
    EXPECT_NEAR(ba.core_points[1].z(), 0.0, 1e-12);
    EXPECT_NEAR(ab.core_points[1].z(), ba.core_points[0].z(), 2.0 * (a.size + b.size) * tilt);
  }
}

// B `height` above A, tilted by `tilt` about a random line of its plane and moved `aside` in a
// random direction. The cores' distance stays the brute force's to 64 ulps of the distance in both
// orders, each point on its core, and the two orders return the same points.
void expect_far_tilted_pair_matches_brute_force(Rng& rng, const TestShape& a, const TestShape& b,
                                                double height, double tilt, double aside) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double heading = 2.0 * M_PI * uniform(rng), axis = 2.0 * M_PI * uniform(rng);
  const Pose pa(Eigen::Vector3d::Zero(), kIdentity);
  const Pose pb(Eigen::Vector3d(aside * std::cos(heading), aside * std::sin(heading), height),
                about(tilt, std::cos(axis), std::sin(axis), 0));
  const double reference =
      static_cast<double>(brute_force_closest(to_world(a, pa), to_world(b, pb)).distance);
  const auto& core_a = std::get<PaddedPolygon>(a.shape);
  const auto& core_b = std::get<PaddedPolygon>(b.shape);
  const Proximity ab = proximity(core_a, pa, core_b, pb);
  const Proximity ba = proximity(core_b, pb, core_a, pa);
  const double within = 64 * std::numeric_limits<double>::epsilon() * height;
  EXPECT_NEAR((ab.core_points[1] - ab.core_points[0]).norm(), reference, within);
  EXPECT_NEAR((ba.core_points[1] - ba.core_points[0]).norm(), reference, within);
  EXPECT_NEAR(ab.core_points[0].z(), 0.0, 1e-12);
  EXPECT_LE((ab.core_points[0] - ba.core_points[1]).norm(), 1e-15 * height);
  EXPECT_LE((ab.core_points[1] - ba.core_points[0]).norm(), 1e-15 * height);
  // B's point on B's plane.
  const Eigen::Vector4d& q = pb.q();
  const Eigen::Vector3d normal_b =
      Eigen::Quaterniond(q(0), q(1), q(2), q(3)).normalized().toRotationMatrix().col(2);
  EXPECT_NEAR(normal_b.dot(ab.core_points[1] - pb.r()), 0.0, 1e-15 * height);
}

// Polygons 1e5 to 1e9 times their size apart, tilted 1e-9 to 1e-3 rad and moved 0 to 1.5 sums of
// their sizes to the side, so that B's lowest vertex is over A's face, over its rim or beside it.
// A tilt carries B the distance times the tilt to the side in A's frame, where the bounds along
// A's plane then ruled nothing out: two unit 4,000-gons 1e8 apart, 2.5 to the side, tilted 1e-5
// rad took 65 ms, growing as k^2 (far windows are searched in depth_box_tree.hpp's hierarchies
// now, separated_polygons.cpp).
TEST(LargePolygons, FarApartTiltedToTheSide) {
  Rng rng(73);
  for (int trial = 0; trial < 24; ++trial) {
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    const TestShape a = many_sided(rng, 100 + trial, trial % 3 == 0);
    const TestShape b = many_sided(rng, 120 + trial, trial % 5 == 0);
    const double height = std::pow(10.0, 5.0 + (trial % 9) * 0.5);
    const double tilt = std::pow(10.0, -9.0 + (trial % 7));
    const double aside = (trial % 4) * 0.5 * (a.size + b.size);  // 0 to 1.5 (sum of sizes)
    expect_far_tilted_pair_matches_brute_force(rng, a, b, height, tilt, aside);
  }
}

// The poses where both of the earlier sweeps (by depth along the line between the polygons, and
// along A's plane) stayed quadratic: many-sided polygons 1e6 to 1e8 times their size apart, tilted
// 1e-8 to 1e-5 rad, 0.5 to 2.5 sums of their sizes to the side. There the distance varies across
// the polygons by a slope (the tilt, and the offset over the distance) and by the offset across
// the line between them squared over twice the distance, both near the distance's rounding; each
// sweep's bound held one of the two (unit 32,000-gons 3e6 apart, 2.5 to the side, tilted 1e-6 rad:
// 0.66 s). The hierarchies' bound holds both; the answers stay the brute force's, with windows of
// hundreds of vertices on each side.
TEST(LargePolygons, FarApartNearlyFacingManySided) {
  Rng rng(79);
  const double heights[] = {1e6, 3e6, 1e7, 1e8};
  const double tilts[] = {1e-8, 1e-6, 1e-5};
  for (int trial = 0; trial < 12; ++trial) {
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    const TestShape a = many_sided(rng, 700 + 37 * trial, trial % 5 == 0);
    const TestShape b = many_sided(rng, 900 + 41 * trial, false);
    const double aside = (0.5 + (trial % 3)) * (a.size + b.size);  // 0.5 to 2.5 sums of sizes
    expect_far_tilted_pair_matches_brute_force(rng, a, b, heights[trial % 4], tilts[trial % 3],
                                               aside);
  }
}

// Two equal 51-gons one above the other, 1.4e-9 rad from parallel, their rims over each other:
// near the lowest pair, vertex pairs differ in distance by 1e-11 of the scene. The windows'
// sub-problem settled on a neighbouring vertex pair whose direction the supports did not certify,
// 6e-12 of the scene too far and different in the two orders (found by fuzz_proximity); the
// certificate is now checked. Both orders against the brute force.
TEST(LargePolygons, RimsOverEachOtherNearlyParallel) {
  const double apothem = 1.0352619520185846e70, h = -1.8325506472120096e-06;
  const TestShape plate = regular_polygon(51, apothem);
  const Pose pa(Eigen::Vector3d(apothem, 0.0, -64175004669402.219),
                Eigen::Vector4d(-1.832550644564944e-06, h, h, h));
  const Pose pb(Eigen::Vector3d(h, h, h), Eigen::Vector4d(h, h, h, h));
  const auto& polygon = std::get<PaddedPolygon>(plate.shape);
  const double reference =
      static_cast<double>(brute_force_closest(to_world(plate, pa), to_world(plate, pb)).distance);
  const Proximity ab = proximity(polygon, pa, polygon, pb);
  const Proximity ba = proximity(polygon, pb, polygon, pa);
  EXPECT_NEAR((ab.core_points[1] - ab.core_points[0]).norm(), reference, 1e-13 * reference);
  EXPECT_NEAR((ba.core_points[1] - ba.core_points[0]).norm(), reference, 1e-13 * reference);
  EXPECT_NEAR(ab.phi, ba.phi, 1e-13 * reference * reference);
}

// A small polygon lying in a large one's plane, 1e-11 rad from parallel (beyond the 1e-12 that
// counts as parallel): the cores intersect in both orders (found by fuzz_proximity, where the
// large polygon's vertices within the tolerance of the small one's plane skewed the section).
TEST(LargePolygons, NearlyCoplanarOverlapIsAnIntersection) {
  const auto regular = [](int count, double apothem) {
    Eigen::MatrixX2d C(count, 2);
    for (int k = 0; k < count; ++k)
      C.row(k) << std::cos(2 * M_PI * k / count), std::sin(2 * M_PI * k / count);
    return PaddedPolygon(C, Eigen::VectorXd::Constant(count, apothem), 0.01);
  };
  for (const auto& [ka, kb] : {std::pair{151, 121}, std::pair{12, 12}}) {
    const PaddedPolygon large = regular(ka, 41402.0), small = regular(kb, 2.75);
    const Pose pose_large({1.75, 0, 1.625}, about(M_PI / 2, 1, 0, 0));
    const Pose pose_small({0.5, 0, 0}, about(M_PI / 2 + 1e-11, 1, 0, 0));
    const Proximity ab = proximity(large, pose_large, small, pose_small);
    const Proximity ba = proximity(small, pose_small, large, pose_large);
    EXPECT_TRUE(ab.cores_intersect) << ka;
    EXPECT_TRUE(ba.cores_intersect) << ka;
    EXPECT_NEAR(ab.phi, -0.0004, 1e-12);
    EXPECT_NEAR(ba.phi, -0.0004, 1e-12);
    // The planes cross along world x through the small polygon's centre; the intersection is
    // that chord of the small polygon, from its edge at +x (apothem 2.75) to, for an odd count,
    // the vertex at -x (circumradius 2.75 / cos(pi / kb)); its middle is returned. Heights
    // rounded to eps * 2.75 place the line of planes 1e-11 from parallel only to
    // 2.75e-16 / 1e-11 ~ 3e-5 across the small polygon, which moves the chord's ends about as much.
    const double far_end = kb % 2 == 1 ? 2.75 / std::cos(M_PI / kb) : 2.75;
    EXPECT_NEAR(ab.core_points[1].x(), 0.5 + 0.5 * (2.75 - far_end), 1e-4);
    EXPECT_LE((ab.core_points[1] - ba.core_points[0]).norm(), 1e-9 * 41402.0);
  }
}

// A triangle's vertex touching another triangle's face, the planes 7e-10 rad from parallel, the
// other two vertices 1e-9 of the scene on either side of the face's plane (found by
// fuzz_proximity): the section of such planes is too ill-conditioned to find the touch, and with
// the vertex's height rounded just below the plane the search of the apart polygons had no
// candidate over the face, answering a gap of 5e-10 of the scene in one order and a touch in the
// other. Both orders against the brute force, in proximity and in the signed distance.
TEST(LargePolygons, VertexTouchingANearlyParallelFaceTouchesInBothOrders) {
  const TestShape core_a = regular_polygon(3, 2.6014606994458081e93),
                  core_b = regular_polygon(3, 2.5194700025415293e93);
  const double radii = 7.3333295109458388e91;  // b's; a has none
  const auto& a = std::get<PaddedPolygon>(core_a.shape);
  const PaddedPolygon b(std::get<PaddedPolygon>(core_b.shape).constraint_matrix(),
                        std::get<PaddedPolygon>(core_b.shape).constraint_offsets(), radii);
  const double w = 2.5194700025415145e93;
  const Pose pa(Eigen::Vector3d(0, w, w), Eigen::Vector4d(w, 2.5194700050708732e93, w, w));
  const Pose pb(
      Eigen::Vector3d(9.6223786342319118e-72, -6.9017463467905638e69, 1.0352619520185846e70),
      Eigen::Vector4d(-0.5, 0.5, -0.5, 0.5));
  const double scene = 2.6e93;
  ASSERT_LE(brute_force_closest(to_world(core_a, pa), to_world(core_b, pb)).distance,
            1e-13 * scene);
  const Proximity ab = proximity(a, pa, b, pb), ba = proximity(b, pb, a, pa);
  EXPECT_TRUE(ab.cores_intersect);
  EXPECT_TRUE(ba.cores_intersect);
  EXPECT_LE((ab.core_points[1] - ab.core_points[0]).norm(), 1e-12 * scene);
  EXPECT_LE((ba.core_points[1] - ba.core_points[0]).norm(), 1e-12 * scene);
  EXPECT_LE((ab.core_points[0] - ba.core_points[1]).norm(), 1e-12 * scene);
  const SignedDistance sab = signed_distance(a, pa, b, pb), sba = signed_distance(b, pb, a, pa);
  EXPECT_NEAR(sab.distance, -radii, 1e-12 * scene);
  EXPECT_NEAR(sba.distance, -radii, 1e-12 * scene);
}

// The penetration search of two polygons in one frame of scale 1 (the inputs are of order one):
// pruned by the edge chains' hierarchies (as the public query above 32 x 32 vertices) or visiting
// every edge pair.
struct PenetrationPaths {
  detail::DeepestFacet pruned, every;
  detail::PosedCore a, b;
};

PenetrationPaths penetration_paths(const PaddedPolygon& a, const Pose& pa, const PaddedPolygon& b,
                                   const Pose& pb) {
  const detail::PolygonView view_a(a, 1.0), view_b(b, 1.0);
  PenetrationPaths out{{},
                       {},
                       {pa.r(), detail::UnitQuaternion(pa.q()), 0.0, a.extent()},
                       {pb.r(), detail::UnitQuaternion(pb.q()), 0.0, b.extent()}};
  const detail::PairFrame scales =
      detail::make_pair_frame(a.extent(), 0.0, b.extent(), 0.0, pa.r(), pb.r());
  const double tolerance = scales.tolerance * scales.scale;
  const detail::CoreOutline outline_a(view_a, out.a), outline_b(view_b, out.b);
  out.pruned = detail::deepest_facet(outline_a, outline_b, tolerance);
  out.every =
      detail::deepest_facet(outline_a, outline_b, tolerance, detail::EdgePairVisits::kEvery);
  return out;
}

// Random pairs of 33 to 120 vertices, crossing at random attitudes, at right angles and nearly
// coplanar (where D is thin and many facets are nearly as deep): the pruned search finds the depth
// of the separating-axis brute force and of the visit of every pair, and its facet's witnesses lie
// on the two cores, x1 - x2 = depth * normal.
TEST(LargePolygons, PenetrationSearchAgreesWithEveryPairAndSeparatingAxes) {
  Rng rng(23);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  int penetrating = 0;
  for (int i = 0; i < 240; ++i) {
    const int ka = std::uniform_int_distribution<int>(33, 120)(rng);
    const int kb = std::uniform_int_distribution<int>(33, 120)(rng);
    const TestShape a = many_sided(rng, ka, i % 5 == 0), b = many_sided(rng, kb, i % 7 == 0);
    const Pose pa = random_pose(rng, 0.3);
    Pose pb = random_pose(rng, 0.3);
    if (i % 3 != 0) {
      // b turned off a's plane by 90 degrees (i % 3 == 1) or by 10^-2 .. 10^-10 rad.
      const Eigen::Quaterniond qa(pa.q()(0), pa.q()(1), pa.q()(2), pa.q()(3));
      const double tilt = i % 3 == 1 ? M_PI / 2 : std::pow(10.0, -2.0 - 8.0 * uniform(rng));
      const Eigen::Quaterniond qb =
          qa.normalized() *
          Eigen::Quaterniond(Eigen::AngleAxisd(
              tilt, Eigen::Vector3d(uniform(rng) - 0.5, uniform(rng) - 0.5, 0).normalized())) *
          Eigen::Quaterniond(Eigen::AngleAxisd(6.3 * uniform(rng), Eigen::Vector3d::UnitZ()));
      pb = Pose(pb.r(), Eigen::Vector4d(qb.w(), qb.x(), qb.y(), qb.z()));
    }
    const WorldCore wa = to_world(a, pa), wb = to_world(b, pb);
    if (brute_force_closest(wa, wb).distance > 0) continue;  // apart: not a penetration
    ++penetrating;
    const PenetrationPaths paths = penetration_paths(std::get<PaddedPolygon>(a.shape), pa,
                                                     std::get<PaddedPolygon>(b.shape), pb);
    const double reference = static_cast<double>(brute_force_penetration_depth(wa, wb));
    ASSERT_NEAR(paths.pruned.depth, reference, 1e-12) << i;
    ASSERT_NEAR(paths.every.depth, reference, 1e-12) << i;
    if (paths.pruned.depth <= 1e-12) continue;  // touching: the closest points serve
    ASSERT_TRUE(paths.pruned.witnesses.has_value()) << i;
    const Eigen::Vector3d x1 = world(paths.a, (*paths.pruned.witnesses)[0]);
    const Eigen::Vector3d x2 = world(paths.b, (*paths.pruned.witnesses)[1]);
    ASSERT_LE(distance_to_core(x1, wa), 1e-12) << i;
    ASSERT_LE(distance_to_core(x2, wb), 1e-12) << i;
    ASSERT_LE((x1 - x2 - paths.pruned.depth * paths.pruned.normal).norm(), 1e-12) << i;
  }
  EXPECT_GT(penetrating, 120);
}

// Two regular 10^5-gons crossing at right angles (a hostile review's stall: every pair of edges is
// a facet of D, and visiting them all took minutes): analytic answers. The disc of circumradius
// 0.7 stands in the plane x = 0 with its centre 0.3 above the unit disc's, its lowest vertex 0.4
// below the unit disc's plane; lifting it by 0.4 is the shortest way out (any tilt of the
// translation costs more: h_D(n) = |n_xy| + 0.7 |n_yz| - 0.3 n_z).
TEST(LargePolygons, HundredThousandGonsCrossing) {
  const auto regular = [](int count, double circumradius) {
    Eigen::MatrixX2d C(count, 2);
    for (int k = 0; k < count; ++k)
      C.row(k) << std::cos(2 * M_PI * (k + 0.5) / count), std::sin(2 * M_PI * (k + 0.5) / count);
    return PaddedPolygon(C, Eigen::VectorXd::Constant(count, circumradius * std::cos(M_PI / count)),
                         0.01);
  };
  const PaddedPolygon large = regular(100000, 1.0), small = regular(100000, 0.7);
  const Pose standing({0, 0, 0.3}, about(M_PI / 2, 0, 1, 0));  // body z along world x
  const SignedDistance sd = signed_distance(large, Pose(), small, standing);
  EXPECT_TRUE(sd.penetrating);
  EXPECT_NEAR(sd.distance, -0.42, 1e-12);
  EXPECT_NEAR((sd.normal - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((sd.core_points[1] - Eigen::Vector3d(0, 0, -0.4)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((sd.core_points[0] - Eigen::Vector3d(0, 0, 0)).norm(), 0.0, 1e-12);
  const SignedDistance swapped = signed_distance(small, standing, large, Pose());
  EXPECT_NEAR(swapped.distance, -0.42, 1e-12);
  EXPECT_NEAR((swapped.normal + Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-12);
}

}  // namespace
}  // namespace diffpills::testing
