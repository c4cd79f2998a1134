// Shape-parameter gradients (shape_gradient.hpp) against central differences of phi and of the
// signed distance, the shapes rebuilt with each parameter moved: a capsule's length and radius, a
// polygon's every entry of C and d and its radius, on random pairs of every ordering, apart and
// penetrating. Also: redundant rows get 0, scaling every length by a power of two scales every
// gradient exactly, and swapping the shapes swaps the gradients.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include "diffpills/diffpills.hpp"
#include "diffpills/shape_gradient.hpp"
#include "support/random_shapes.hpp"

namespace diffpills::testing {
namespace {

// A shape's parameters as one vector, and the shape they make: [length, radius] or [C by rows,
// d, radius].
Eigen::VectorXd parameters(const Shape& shape) {
  if (const auto* capsule = std::get_if<Capsule>(&shape)) {
    return Eigen::Vector2d(capsule->length(), capsule->radius());
  }
  const auto& polygon = std::get<PaddedPolygon>(shape);
  const Eigen::Index m = polygon.constraint_offsets().size();
  Eigen::VectorXd out(3 * m + 1);
  for (Eigen::Index i = 0; i < m; ++i) out.segment<2>(2 * i) = polygon.constraint_matrix().row(i);
  out.segment(2 * m, m) = polygon.constraint_offsets();
  out(3 * m) = polygon.radius();
  return out;
}

Shape with_parameters(const Shape& shape, const Eigen::VectorXd& x) {
  if (std::holds_alternative<Capsule>(shape)) return Capsule(x(0), x(1));
  const Eigen::Index m = (x.size() - 1) / 3;
  Eigen::MatrixX2d C(m, 2);
  for (Eigen::Index i = 0; i < m; ++i) C.row(i) = x.segment<2>(2 * i).transpose();
  return PaddedPolygon(C, x.segment(2 * m, m), x(3 * m));
}

Eigen::VectorXd flatten(const ShapeGradient& gradient) {
  if (const auto* capsule = std::get_if<CapsuleShapeGradient>(&gradient)) {
    return Eigen::Vector2d(capsule->length, capsule->radius);
  }
  const auto& polygon = std::get<PolygonShapeGradient>(gradient);
  const Eigen::Index m = polygon.d.size();
  Eigen::VectorXd out(3 * m + 1);
  for (Eigen::Index i = 0; i < m; ++i) out.segment<2>(2 * i) = polygon.C.row(i);
  out.segment(2 * m, m) = polygon.d;
  out(3 * m) = polygon.radius;
  return out;
}

struct Case {
  Shape a, b;
  Pose pa, pb;
};

using Measure = std::function<double(const Shape&, const Shape&, const Pose&, const Pose&)>;

double phi_of(const Shape& a, const Shape& b, const Pose& pa, const Pose& pb) {
  return proximity(a, pa, b, pb).phi;
}
double distance_of(const Shape& a, const Shape& b, const Pose& pa, const Pose& pb) {
  return signed_distance(a, pa, b, pb).distance;
}

// Central differences of the measure along every parameter of shape `side`, at steps h and h / 4;
// false where they disagree (a kink within the step: the active set changes there).
bool differences(const Case& c, int side, const Measure& measure, double h, Eigen::VectorXd& out) {
  const Shape& shape = side == 0 ? c.a : c.b;
  const Eigen::VectorXd x = parameters(shape);
  out.resize(x.size());
  for (Eigen::Index k = 0; k < x.size(); ++k) {
    const auto at = [&](double step) {
      Eigen::VectorXd y = x;
      y(k) += step;
      const Shape moved = with_parameters(shape, y);
      return side == 0 ? measure(moved, c.b, c.pa, c.pb) : measure(c.a, moved, c.pa, c.pb);
    };
    // At a bound (a sphere's length 0, a radius 0) the right derivative, second order.
    const auto difference = [&](double step) {
      if (x(k) - step < 0.0) return (4.0 * at(step) - at(2.0 * step) - 3.0 * at(0.0)) / (2 * step);
      return (at(step) - at(-step)) / (2 * step);
    };
    const double coarse = difference(h), fine = difference(h / 4);
    if (std::abs(coarse - fine) > 1e-6 * (1.0 + std::abs(fine))) return false;
    out(k) = fine;
  }
  return true;
}

// A random shape; a polygon without the scaled duplicate of a row that random_polygon() may add:
// an active row given twice is a kink in its offsets (relaxing either leaves the other binding),
// where central differences see half of each one-sided derivative (AnalyticCases checks it).
TestShape random_shape(Rng& rng, bool capsule) {
  if (capsule) return random_capsule(rng, 1.0, 0.05);
  TestShape shape = random_polygon(rng, 1.0);
  const auto& polygon = std::get<PaddedPolygon>(shape.shape);
  const Eigen::MatrixX2d& C = polygon.constraint_matrix();
  const Eigen::VectorXd& d = polygon.constraint_offsets();
  std::vector<Eigen::Index> kept;
  for (Eigen::Index i = 0; i < C.rows(); ++i) {
    bool duplicate = false;
    for (const Eigen::Index j : kept) {
      const double scale = C.row(i).norm() / C.row(j).norm();
      duplicate = duplicate || ((C.row(i) - scale * C.row(j)).norm() <= 1e-12 * C.row(i).norm() &&
                                std::abs(d(i) - scale * d(j)) <= 1e-12 * d(i));
    }
    if (!duplicate) kept.push_back(i);
  }
  Eigen::MatrixX2d rows(static_cast<Eigen::Index>(kept.size()), 2);
  Eigen::VectorXd offsets(static_cast<Eigen::Index>(kept.size()));
  for (std::size_t k = 0; k < kept.size(); ++k) {
    rows.row(static_cast<Eigen::Index>(k)) = C.row(kept[k]);
    offsets(static_cast<Eigen::Index>(k)) = d(kept[k]);
  }
  shape.shape = PaddedPolygon(rows, offsets, polygon.radius());
  return shape;
}

// Every ordering, phi and the distance, 300 random pairs each (a third of them penetrating).
TEST(ShapeGradient, MatchesCentralDifferences) {
  Rng rng(12);
  for (const bool capsule_a : {true, false}) {
    for (const bool capsule_b : {true, false}) {
      for (const bool of_phi : {true, false}) {
        int checked = 0, kinks = 0;
        double worst = 0.0;
        for (int trial = 0; trial < 300; ++trial) {
          const TestShape ta = random_shape(rng, capsule_a), tb = random_shape(rng, capsule_b);
          const Case c{ta.shape, tb.shape, random_pose(rng, trial % 3 == 0 ? 0.4 : 1.5),
                       random_pose(rng, 1.0)};
          std::array<ShapeGradient, 2> exact;
          if (of_phi) {
            exact = proximity_shape_gradient(c.a, c.pa, c.b, c.pb).shape_gradient;
          } else {
            exact = signed_distance_shape_gradient(c.a, c.pa, c.b, c.pb).shape_gradient;
          }
          for (int side = 0; side < 2; ++side) {
            Eigen::VectorXd numeric;
            if (!differences(c, side, of_phi ? Measure(phi_of) : Measure(distance_of), 1e-5,
                             numeric)) {
              ++kinks;
              continue;
            }
            const Eigen::VectorXd analytic = flatten(exact[static_cast<std::size_t>(side)]);
            ASSERT_EQ(analytic.size(), numeric.size());
            for (Eigen::Index k = 0; k < numeric.size(); ++k) {
              const double error =
                  std::abs(analytic(k) - numeric(k)) / (1.0 + std::abs(numeric(k)));
              worst = std::max(worst, error);
              EXPECT_LE(error, 1e-6) << "capsules " << capsule_a << capsule_b << " phi " << of_phi
                                     << " trial " << trial << " side " << side << " parameter " << k
                                     << ": " << analytic(k) << " vs " << numeric(k);
            }
            ++checked;
          }
        }
        EXPECT_LE(kinks, 60) << "too many kinks: the check would prove little";
        std::printf("capsules %d%d %s: %d sides checked, %d at kinks, worst %.2g\n", capsule_a,
                    capsule_b, of_phi ? "phi" : "distance", checked, kinks, worst);
      }
    }
  }
}

// Scaling every length by 2^k scales the gradients exactly: of phi, d/dlength, d/dd and d/dradius
// by 2^k and d/dC by 2^2k (C y <= d: C is unitless, y a length); of the distance, d/dC by 2^k and
// the rest not at all.
TEST(ShapeGradient, ScaleExactlyWithPowersOfTwo) {
  Rng rng(13);
  for (int trial = 0; trial < 60; ++trial) {
    const TestShape ta = random_shape(rng, trial % 2 == 0), tb = random_shape(rng, trial % 3 == 0);
    const Pose pa = random_pose(rng, 1.0), pb = random_pose(rng, 1.0);
    for (const int k : {-40, 17}) {
      const double s = std::ldexp(1.0, k);
      const auto scaled = [&](const Shape& shape) {
        Eigen::VectorXd x = parameters(shape);
        if (std::holds_alternative<Capsule>(shape)) return with_parameters(shape, s * x);
        const Eigen::Index m = (x.size() - 1) / 3;
        x.tail(m + 1) *= s;  // d and the radius; C stays
        return with_parameters(shape, x);
      };
      const Pose spa(s * pa.r(), pa.q()), spb(s * pb.r(), pb.q());
      const auto expect_scaled = [&](const ShapeGradient& base, const ShapeGradient& big,
                                     double length_power, const char* what) {
        const Eigen::VectorXd x = flatten(base), y = flatten(big);
        const bool polygon = std::holds_alternative<PolygonShapeGradient>(base);
        const Eigen::Index m = polygon ? (x.size() - 1) / 3 : 0;
        for (Eigen::Index i = 0; i < x.size(); ++i) {
          const bool is_C = polygon && i < 2 * m;
          const double factor = std::ldexp(1.0, static_cast<int>(k * (length_power + is_C)));
          EXPECT_EQ(y(i), factor * x(i)) << what << " trial " << trial << " k " << k << " " << i;
        }
      };
      const auto p = proximity_shape_gradient(ta.shape, pa, tb.shape, pb);
      const auto sp = proximity_shape_gradient(scaled(ta.shape), spa, scaled(tb.shape), spb);
      const auto d = signed_distance_shape_gradient(ta.shape, pa, tb.shape, pb);
      const auto sd = signed_distance_shape_gradient(scaled(ta.shape), spa, scaled(tb.shape), spb);
      for (int side = 0; side < 2; ++side) {
        expect_scaled(p.shape_gradient[side], sp.shape_gradient[side], 1, "phi");
        expect_scaled(d.shape_gradient[side], sd.shape_gradient[side], 0, "distance");
      }
    }
  }
}

// Swapping the shapes swaps their gradients.
TEST(ShapeGradient, SwappingTheShapesSwapsTheGradients) {
  Rng rng(14);
  for (int trial = 0; trial < 200; ++trial) {
    const TestShape ta = random_shape(rng, trial % 2 == 0), tb = random_shape(rng, trial % 3 == 0);
    const Pose pa = random_pose(rng, 1.0), pb = random_pose(rng, 1.0);
    const auto forward = signed_distance_shape_gradient(ta.shape, pa, tb.shape, pb);
    const auto backward = signed_distance_shape_gradient(tb.shape, pb, ta.shape, pa);
    const auto phi_forward = proximity_shape_gradient(ta.shape, pa, tb.shape, pb);
    const auto phi_backward = proximity_shape_gradient(tb.shape, pb, ta.shape, pa);
    for (int side = 0; side < 2; ++side) {
      const Eigen::VectorXd x = flatten(forward.shape_gradient[side]);
      const Eigen::VectorXd y = flatten(backward.shape_gradient[1 - side]);
      EXPECT_LE((x - y).lpNorm<Eigen::Infinity>(), 1e-9 * (1.0 + x.lpNorm<Eigen::Infinity>()))
          << "distance, trial " << trial;
      const Eigen::VectorXd u = flatten(phi_forward.shape_gradient[side]);
      const Eigen::VectorXd v = flatten(phi_backward.shape_gradient[1 - side]);
      EXPECT_LE((u - v).lpNorm<Eigen::Infinity>(), 1e-9 * (1.0 + u.lpNorm<Eigen::Infinity>()))
          << "phi, trial " << trial;
    }
  }
}

// Analytic cases: a unit square 2 above a sphere, and a capsule reaching past a square's edge.
// A row given scaled by c is the same half-plane, and its multiplier, so its gradient, is 1 / c
// times: exactly so for rows far below 1e-154 too, whose squares underflow (a hostile review:
// |C_i| = 1e-200 gave -inf for d/dd_i, and NaN with the shapes apart), and never NaN where it
// exceeds the largest double.
TEST(ShapeGradient, RowsOfAnyScaleGetTheirGradient) {
  Eigen::MatrixX2d C(4, 2);
  C << 1, 0, 0, 1, -1, 0, 0, -1;
  const Capsule sphere(0.0, 0.2);
  const Pose beside(Eigen::Vector3d(2, 0.3, -0.5), Eigen::Vector4d(1, 0, 0, 0));
  const PaddedPolygon unit(C, Eigen::Vector4d::Constant(1.0), 0.1);
  const auto reference = std::get<PolygonShapeGradient>(
      proximity_shape_gradient(unit, Pose(), sphere, beside).shape_gradient[0]);
  ASSERT_NE(reference.d(0), 0.0);
  for (const double scale : {1e-100, 1e-200, 1e-300, 1e-305}) {
    SCOPED_TRACE(scale);
    const PaddedPolygon tiny(scale * C, Eigen::Vector4d::Constant(scale), 0.1);
    const auto g = std::get<PolygonShapeGradient>(
        proximity_shape_gradient(tiny, Pose(), sphere, beside).shape_gradient[0]);
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(g.d(i) * scale, reference.d(i), 1e-14 * std::abs(reference.d(0))) << i;
      EXPECT_NEAR(g.C(i, 0) * scale, reference.C(i, 0), 1e-14 * std::abs(reference.d(0))) << i;
      EXPECT_NEAR(g.C(i, 1) * scale, reference.C(i, 1), 1e-14 * std::abs(reference.d(0))) << i;
    }
  }
  // Subnormal rows: the exact values exceed the largest double; infinite, not NaN.
  const PaddedPolygon subnormal(1e-320 * C, Eigen::Vector4d::Constant(1e-320), 0.1);
  const auto g = std::get<PolygonShapeGradient>(
      proximity_shape_gradient(subnormal, Pose(), sphere, beside).shape_gradient[0]);
  EXPECT_FALSE(g.d.hasNaN());
  EXPECT_FALSE(g.C.hasNaN());
  EXPECT_EQ(g.d(0), -std::numeric_limits<double>::infinity());
  // Rows of normal length overflow too where the scene is large: rows of 2^-960 with the sphere
  // 2^80 away give multipliers of about 2^81 / 2^-960 (fuzz_proximity's finding: a row of
  // 8e-281 in a scene of 1e70). Rescaled by 2^960 the rows give the finite multipliers.
  const double row = std::ldexp(1.0, -960);
  const double far = std::ldexp(1.0, 80);
  const Pose far_beside(far * beside.r(), beside.q());
  const PaddedPolygon short_rows(row * C, Eigen::Vector4d::Constant(row), 0.1);
  const auto overflowing = std::get<PolygonShapeGradient>(
      proximity_shape_gradient(short_rows, Pose(), sphere, far_beside).shape_gradient[0]);
  const auto finite = std::get<PolygonShapeGradient>(
      proximity_shape_gradient(unit, Pose(), sphere, far_beside).shape_gradient[0]);
  ASSERT_TRUE(finite.d.allFinite() && finite.C.allFinite());
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(overflowing.d(i), std::ldexp(finite.d(i), 960)) << i;
    EXPECT_EQ(overflowing.C(i, 0), std::ldexp(finite.C(i, 0), 960)) << i;
    EXPECT_EQ(overflowing.C(i, 1), std::ldexp(finite.C(i, 1), 960)) << i;
  }
  EXPECT_EQ(overflowing.d(0), -std::numeric_limits<double>::infinity());
}

// Rows with subnormal entries of many bits: the same polygon given with such a row rescaled to
// unit length by 2^k has the same closest points, and the row's gradient is 2^-k times the
// rescaled row's, exactly, or infinite where that exceeds the largest double. fuzz_proximity's
// scene: a 4-row polygon (rows down to 6e-317 and 8e-321) 1e70 from a 51-gon. In the fuzzer's
// build (clang) the multiplier of the row [-6.2e-317, -7.6e-321] was a rounding residue, 5e-66,
// and its d-gradient, -7.6e250, was 1e-7 off 2^-k times the rescaled row's: |C_i| by hypot of the
// row as given kept only the bits of a subnormal above 2^-1074. The residue depends on the
// compiler's rounding (here the gradient overflows, as the rescaled row's scaled back does), so
// that input is kept in fuzz_proximity's corpus, which make test replays under clang.
TEST(ShapeGradient, SubnormalRowsScaleExactlyLikeTheirRowsRescaled) {
  Eigen::MatrixX2d C(4, 2);
  C << 0, 2.25, -6.2167845438435712e-317, -7.5888483201215469e-321, 5.5593629330205671e-83,
      2.4677579418653533e-178, 3.3051431974266301e+40, -3.1280323686774314e-230;
  const Eigen::Vector4d d(2.625, 4.7974170233113611e-299, 1e+100, 1.6525713069001583e+40);
  const int sides = 51;
  Eigen::MatrixX2d round(sides, 2);
  for (int i = 0; i < sides; ++i) {
    round.row(i) << std::cos(2 * M_PI * i / sides), std::sin(2 * M_PI * i / sides);
  }
  const PaddedPolygon b(round, Eigen::VectorXd::Constant(sides, 4.1410478080743383e+70),
                        1.8807128734703512e-119);
  const double big = 1.0352619520185846e+70;
  const Pose pose_a(Eigen::Vector3d(4.1410478080743383e+70, big, big),
                    Eigen::Vector4d(big, 3, big, -3));
  const Pose pose_b(Eigen::Vector3d(-2.875, -2.5, 0.5), Eigen::Vector4d(0.5, 0.5, 0.5, 0.5));
  Eigen::MatrixX2d unit_rows = C;
  Eigen::Vector4d unit_offsets = d;
  // Only the subnormal row is rescaled: the loose row's offset, 1e100, scaled alike would exceed
  // the accepted magnitudes.
  Eigen::Vector4i exponents = Eigen::Vector4i::Zero();
  std::frexp(std::hypot(C(1, 0), C(1, 1)), &exponents(1));
  unit_rows.row(1) << std::ldexp(C(1, 0), -exponents(1)), std::ldexp(C(1, 1), -exponents(1));
  unit_offsets(1) = std::ldexp(d(1), -exponents(1));
  const PaddedPolygon given(C, d, 0.0), rescaled(unit_rows, unit_offsets, 0.0);
  const ProximityShapeGradient g = proximity_shape_gradient(given, pose_a, b, pose_b);
  const ProximityShapeGradient u = proximity_shape_gradient(rescaled, pose_a, b, pose_b);
  EXPECT_EQ(g.core_points, u.core_points);
  const auto& given_rows = std::get<PolygonShapeGradient>(g.shape_gradient[0]);
  const auto& unit = std::get<PolygonShapeGradient>(u.shape_gradient[0]);
  ASSERT_TRUE(unit.d.allFinite() && unit.C.allFinite());
  for (int i = 0; i < 4; ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(given_rows.d(i), std::ldexp(unit.d(i), -exponents(i)));
    EXPECT_EQ(given_rows.C(i, 0), std::ldexp(unit.C(i, 0), -exponents(i)));
    EXPECT_EQ(given_rows.C(i, 1), std::ldexp(unit.C(i, 1), -exponents(i)));
  }
}

TEST(ShapeGradient, AnalyticCases) {
  Eigen::MatrixX2d C(5, 2);
  C << 1, 0, 0, 1, -1, 0, 0, -1, 2, 0;  // the last row is x <= 4: redundant, twice loose
  const PaddedPolygon square(C, (Eigen::VectorXd(5) << 1, 1, 1, 1, 8).finished(), 0.1);
  const Capsule sphere(0.0, 0.2);
  // The sphere's centre at (2, 2, -2): the corner (1, 1, 0) is closest, 6^(1/2) away along
  // n = (1, 1, -2) / 6^(1/2); rows 0 and 1 are active there, each with multiplier 1 / 6^(1/2).
  const Pose below(Eigen::Vector3d(2, 2, -2), Eigen::Vector4d(1, 0, 0, 0));
  const auto g = signed_distance_shape_gradient(square, Pose(), sphere, below);
  const double length = std::sqrt(6.0);
  EXPECT_NEAR(g.distance, length - 0.3, 1e-14);
  const auto& sg = std::get<PolygonShapeGradient>(g.shape_gradient[0]);
  // Moving the corner by +e along x (d_0 += e) brings it closer: d distance / d d_0 = -1 / sqrt 6.
  EXPECT_NEAR(sg.d(0), -1.0 / length, 1e-14);
  EXPECT_NEAR(sg.d(1), -1.0 / length, 1e-14);
  EXPECT_EQ(sg.d(2), 0.0);
  EXPECT_EQ(sg.d(3), 0.0);
  EXPECT_EQ(sg.d(4), 0.0);  // redundant
  // Row 0 given again, scaled by 3: the first of the two gets the whole multiplier.
  Eigen::MatrixX2d twice(5, 2);
  twice << 1, 0, 0, 1, -1, 0, 0, -1, 3, 0;
  const PaddedPolygon square_twice(twice, (Eigen::VectorXd(5) << 1, 1, 1, 1, 3).finished(), 0.1);
  const SignedDistanceShapeGradient twice_gradient =
      signed_distance_shape_gradient(square_twice, Pose(), sphere, below);
  const auto& tg = std::get<PolygonShapeGradient>(twice_gradient.shape_gradient[0]);
  EXPECT_NEAR(tg.d(0), -1.0 / length, 1e-14);
  EXPECT_EQ(tg.d(4), 0.0);
  EXPECT_EQ(sg.radius, -1.0);
  // d/dC_00: the row C_0 . y <= d_0 at the corner y = (1, 1): lambda_0 y = (1/sqrt 6) (1, 1).
  EXPECT_NEAR(sg.C(0, 0), 1.0 / length, 1e-14);
  EXPECT_NEAR(sg.C(0, 1), 1.0 / length, 1e-14);
  const auto& cg = std::get<CapsuleShapeGradient>(g.shape_gradient[1]);
  // The sphere as a segment of length 0 along x: growing it brings an end 1/2 closer along x.
  EXPECT_NEAR(cg.length, -0.5 / length, 1e-14);
  EXPECT_EQ(cg.radius, -1.0);
}

}  // namespace
}  // namespace diffpills::testing
