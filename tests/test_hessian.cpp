// The Hessians of phi (proximity_hessian) and of the signed distance (signed_distance_hessian)
// against central differences of the exact gradients, on 1,000 random pairs per ordering each
// (phi apart, the distance apart and penetrating; kinks, where the features change within the
// step, are detected by two step sizes and counted); exact scaling by powers of two; swapping the
// shapes; phi's zero where the cores intersect.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <utility>

#include "diffpills/diffpills.hpp"
#include "support/random_shapes.hpp"

namespace diffpills::testing {
namespace {

using Vector14 = Eigen::Matrix<double, 14, 1>;
using Matrix14 = Eigen::Matrix<double, 14, 14>;

// The exact gradient of phi, or of the signed distance.
Vector14 gradient_at(const Shape& a, const Shape& b, const Vector14& x, bool of_distance) {
  const Pose pa(x.segment<3>(0), x.segment<4>(3)), pb(x.segment<3>(7), x.segment<4>(10));
  return of_distance ? signed_distance(a, pa, b, pb).gradient : proximity(a, pa, b, pb).gradient;
}

// Central differences of the gradient at steps h and h / 4; false where a column disagrees (a
// kink within the step).
bool differences(const Shape& a, const Shape& b, const Vector14& x, double h, Matrix14& out,
                 bool of_distance = false) {
  for (int j = 0; j < 14; ++j) {
    const auto column = [&](double step) {
      Vector14 plus = x, minus = x;
      plus(j) += step;
      minus(j) -= step;
      return Vector14(
          (gradient_at(a, b, plus, of_distance) - gradient_at(a, b, minus, of_distance)) /
          (2 * step));
    };
    const Vector14 coarse = column(h), fine = column(h / 4);
    if ((coarse - fine).cwiseAbs().maxCoeff() > 1e-5 * (1.0 + fine.cwiseAbs().maxCoeff())) {
      return false;
    }
    out.col(j) = fine;
  }
  return true;
}

TestShape random_shape(Rng& rng, bool capsule) {
  return capsule ? random_capsule(rng, 1.0, 0.05) : random_polygon(rng, 1.0);
}

TEST(Hessian, MatchesCentralDifferencesOfTheGradient) {
  Rng rng(31);
  for (const bool capsule_a : {true, false}) {
    for (const bool capsule_b : {true, false}) {
      int checked = 0, kinks = 0, intersecting = 0;
      double worst = 0.0;
      for (int trial = 0; trial < 1000; ++trial) {
        const TestShape ta = random_shape(rng, capsule_a), tb = random_shape(rng, capsule_b);
        const Pose pa = random_pose(rng, 1.5), pb = random_pose(rng, 1.5);
        const ProximityHessian exact = proximity_hessian(ta.shape, pa, tb.shape, pb);
        if (exact.cores_intersect) {
          EXPECT_EQ(exact.hessian, Matrix14::Zero());
          ++intersecting;
          continue;
        }
        Vector14 x;
        x << pa.r(), pa.q(), pb.r(), pb.q();
        Matrix14 numeric;
        if (!differences(ta.shape, tb.shape, x, 1e-5, numeric)) {
          ++kinks;
          continue;
        }
        const double error =
            (exact.hessian - numeric).cwiseAbs().maxCoeff() / (1.0 + numeric.cwiseAbs().maxCoeff());
        worst = std::max(worst, error);
        EXPECT_LE(error, 1e-5) << "capsules " << capsule_a << capsule_b << " trial " << trial
                               << "\nexact\n"
                               << exact.hessian << "\nnumeric\n"
                               << numeric;
        ++checked;
      }
      EXPECT_GE(checked, 700) << "too few smooth cases: the check would prove little";
      std::printf("capsules %d%d: %d checked, %d at kinks, %d intersecting, worst %.2g\n",
                  capsule_a, capsule_b, checked, kinks, intersecting, worst);
    }
  }
}

// The signed distance's Hessian, apart and penetrating (half of the pairs close together).
// In penetration the nearest facet changes more often within a step (kinks, skipped and counted),
// and where D is flat (two capsules crossing) the normal is a fixed rule: those are skipped too.
TEST(Hessian, SignedDistanceMatchesCentralDifferencesOfTheGradient) {
  Rng rng(34);
  for (const bool capsule_a : {true, false}) {
    for (const bool capsule_b : {true, false}) {
      int checked = 0, penetrating = 0, kinks = 0;
      double worst = 0.0;
      for (int trial = 0; trial < 1000; ++trial) {
        const TestShape ta = random_shape(rng, capsule_a), tb = random_shape(rng, capsule_b);
        const double spread = trial % 2 == 0 ? 0.3 : 1.5;
        const Pose pa = random_pose(rng, spread), pb = random_pose(rng, spread);
        const SignedDistanceHessian exact = signed_distance_hessian(ta.shape, pa, tb.shape, pb);
        Vector14 x;
        x << pa.r(), pa.q(), pb.r(), pb.q();
        Matrix14 numeric;
        if (!differences(ta.shape, tb.shape, x, 1e-5, numeric, true)) {
          ++kinks;
          continue;
        }
        const double error =
            (exact.hessian - numeric).cwiseAbs().maxCoeff() / (1.0 + numeric.cwiseAbs().maxCoeff());
        worst = std::max(worst, error);
        EXPECT_LE(error, 1e-5) << "capsules " << capsule_a << capsule_b << " trial " << trial
                               << " penetrating " << exact.penetrating << "\nexact\n"
                               << exact.hessian << "\nnumeric\n"
                               << numeric;
        ++checked;
        penetrating += exact.penetrating;
      }
      EXPECT_GE(checked, 600) << "too few smooth cases: the check would prove little";
      // Two segments' cores cross only on a set of measure zero: no penetration to expect there.
      if (!(capsule_a && capsule_b)) {
        EXPECT_GE(penetrating, 50) << "too few penetrating cases";
      }
      std::printf("distance, capsules %d%d: %d checked (%d penetrating), %d at kinks, worst %.2g\n",
                  capsule_a, capsule_b, checked, penetrating, kinks, worst);
    }
  }
}

// Scaling every length by 2^k: phi scales by 2^2k, so d2phi/dr2 is unchanged, d2phi/drdq scales
// by 2^k and d2phi/dq2 by 2^2k, exactly (the query is solved in a frame scaled by a power of two).
TEST(Hessian, ScalesExactlyWithPowersOfTwo) {
  Rng rng(32);
  for (int trial = 0; trial < 100; ++trial) {
    const bool capsule_a = trial % 2 == 0, capsule_b = trial % 3 == 0;
    const TestShape ta = random_shape(rng, capsule_a), tb = random_shape(rng, capsule_b);
    const Pose pa = random_pose(rng, 1.5), pb = random_pose(rng, 1.5);
    for (const int k : {-30, 12}) {
      const double s = std::ldexp(1.0, k);
      const auto scaled = [&](const Shape& shape) -> Shape {
        if (const auto* capsule = std::get_if<Capsule>(&shape)) {
          return Capsule(s * capsule->length(), s * capsule->radius());
        }
        const auto& polygon = std::get<PaddedPolygon>(shape);
        return PaddedPolygon(polygon.constraint_matrix(), s * polygon.constraint_offsets(),
                             s * polygon.radius());
      };
      const Matrix14 base = proximity_hessian(ta.shape, pa, tb.shape, pb).hessian;
      const Matrix14 big = proximity_hessian(scaled(ta.shape), Pose(s * pa.r(), pa.q()),
                                             scaled(tb.shape), Pose(s * pb.r(), pb.q()))
                               .hessian;
      // The distance scales by 2^k: its Hessian by 2^(k (power - 1)).
      const Matrix14 distance_base = signed_distance_hessian(ta.shape, pa, tb.shape, pb).hessian;
      const Matrix14 distance_big =
          signed_distance_hessian(scaled(ta.shape), Pose(s * pa.r(), pa.q()), scaled(tb.shape),
                                  Pose(s * pb.r(), pb.q()))
              .hessian;
      for (int i = 0; i < 14; ++i) {
        for (int j = 0; j < 14; ++j) {
          const int power = (i % 7 >= 3) + (j % 7 >= 3);  // q rows and columns carry a length
          EXPECT_EQ(big(i, j), std::ldexp(base(i, j), k * power))
              << "trial " << trial << " k " << k << " (" << i << ", " << j << ")";
          EXPECT_EQ(distance_big(i, j), std::ldexp(distance_base(i, j), k * (power - 1)))
              << "distance, trial " << trial << " k " << k << " (" << i << ", " << j << ")";
        }
      }
    }
  }
}

// A quaternion scaled by 2^k is the same attitude: its rows and columns of the Hessians scale
// by 2^-k each (the normalization's 1 / |q|), at the extremes Pose accepts too (norms up to
// ~1e70 and down to ~1e-39; fuzz_proximity found a NaN block at |q| = 1.5e70 in a scene of
// positions 1e100, where q' M q overflowed).
TEST(Hessian, ScalesWithTheQuaternionsNorm) {
  Rng rng(34);
  for (int trial = 0; trial < 100; ++trial) {
    const TestShape ta = random_shape(rng, trial % 2 == 0), tb = random_shape(rng, trial % 3 == 0);
    const Pose pa = random_pose(rng, 1.5), pb = random_pose(rng, 1.5);
    for (const auto& [k1, k2] : {std::pair{232, -120}, std::pair{-120, 232}}) {
      const Pose scaled_a(pa.r(), std::ldexp(1.0, k1) * pa.q());
      const Pose scaled_b(pb.r(), std::ldexp(1.0, k2) * pb.q());
      const std::array<Matrix14, 2> base = {
          proximity_hessian(ta.shape, pa, tb.shape, pb).hessian,
          signed_distance_hessian(ta.shape, pa, tb.shape, pb).hessian};
      const std::array<Matrix14, 2> scaled = {
          proximity_hessian(ta.shape, scaled_a, tb.shape, scaled_b).hessian,
          signed_distance_hessian(ta.shape, scaled_a, tb.shape, scaled_b).hessian};
      for (std::size_t measure = 0; measure < 2; ++measure) {
        ASSERT_TRUE(scaled[measure].allFinite()) << "trial " << trial << " k1 " << k1;
        for (int i = 0; i < 14; ++i) {
          for (int j = 0; j < 14; ++j) {
            const auto power = [k1 = k1, k2 = k2](int index) {
              return index % 7 < 3 ? 0 : (index < 7 ? -k1 : -k2);
            };
            const double expected = std::ldexp(base[measure](i, j), power(i) + power(j));
            EXPECT_LE(std::abs(scaled[measure](i, j) - expected),
                      1e-13 * std::ldexp(base[measure].cwiseAbs().maxCoeff(), power(i) + power(j)))
                << "measure " << measure << ", trial " << trial << " k1 " << k1 << " (" << i << ", "
                << j << ")";
          }
        }
      }
    }
  }
}

// The fuzzer's case: 77- and 51-gons of size ~1e70, the first posed with |q| = 1.5e70, the
// second 1e100 away. Every block is finite, and q1's block is q1's unit block over |q1|^2.
TEST(Hessian, FiniteAtExtremeQuaternionNormsAndDistances) {
  const auto regular = [](int m, double d, double radius) {
    Eigen::MatrixX2d C(m, 2);
    for (int i = 0; i < m; ++i) {
      C.row(i) << std::cos(2 * M_PI * i / m), std::sin(2 * M_PI * i / m);
    }
    return PaddedPolygon(C, Eigen::VectorXd::Constant(m, d), radius);
  };
  const PaddedPolygon a = regular(77, 1.0352619520185846e70, 0.0);
  const PaddedPolygon b = regular(51, 4.1410478080743383e70, 7.9409338805090657e-23);
  const Eigen::Vector4d q(1.0352619520185846e70, -3, 1.0352619520185846e70, -3);
  const Pose pa(Eigen::Vector3d::Constant(1.0352619520185846e70), q);
  const Pose unit_a(pa.r(), q.normalized());
  const Pose pb(Eigen::Vector3d(-1.75, -2.5, -1e100), Eigen::Vector4d(0.5, 0.5, 0.5, 0.5));
  const ProximityHessian h = proximity_hessian(a, pa, b, pb);
  const SignedDistanceHessian s = signed_distance_hessian(a, pa, b, pb);
  ASSERT_TRUE(h.hessian.allFinite());
  ASSERT_TRUE(s.hessian.allFinite());
  const Eigen::Matrix4d unit_block = proximity_hessian(a, unit_a, b, pb).hessian.block<4, 4>(3, 3);
  const double norm_squared = q.squaredNorm();
  EXPECT_LE((h.hessian.block<4, 4>(3, 3) * norm_squared - unit_block).norm(),
            1e-12 * unit_block.norm());
}

// A tiny polygon beside a huge capsule, posed by |q| = 1 and by |q| = 1e100: the q block is the
// unit one over 1e200 to its digits. The rotation's Hessian is ~2 |e| |u| / |q|^2 with u the
// polygon's vertex; in the query's frame (lengths over ~1e99) u is ~1e-114, and the 1 / |q|^2
// applied before the frame's units came back made a subnormal of it (a relative error of 1e-10 at
// a side of 1e-15, everything lost at 1e-25).
TEST(Hessian, RotationBlockOfAHugeQuaternionKeepsItsDigits) {
  const double c = std::sqrt(0.5);
  Eigen::MatrixX2d C(4, 2);
  C << c, c, c, -c, -c, c, -c, -c;  // a square turned 45 degrees: one vertex on +x
  for (const double side : {1e-15, 1e-25, 1e-40}) {
    const PaddedPolygon a(C, Eigen::Vector4d::Constant(side), 0.0);
    const Capsule b(1e99, 0.0);
    const Pose pose_b(Eigen::Vector3d(1e98, 0, 5e98), Eigen::Vector4d(c, 0, 0, c));
    const Pose unit(Eigen::Vector3d::Zero(), Eigen::Vector4d(1, 0, 0, 0));
    const Pose huge(Eigen::Vector3d::Zero(), Eigen::Vector4d(1e100, 0, 0, 0));
    const Matrix14 H1 = proximity_hessian(a, unit, b, pose_b).hessian;
    const Matrix14 H2 = proximity_hessian(a, huge, b, pose_b).hessian;
    const double largest = H1.block<4, 4>(3, 3).cwiseAbs().maxCoeff();
    ASSERT_GT(largest, 0.0);
    for (int i = 3; i < 7; ++i) {
      for (int j = 3; j < 7; ++j) {
        EXPECT_NEAR(H2(i, j), H1(i, j) * 1e-200, 1e-12 * largest * 1e-200)
            << "side " << side << ", entry " << i << ", " << j;
      }
    }
  }
}

// Two points whose gap is subnormal (fuzz_proximity: 5.2e-320): the normal's rate 1 / gap is
// beyond the double range, so it is held fixed as at contact. Everything stays finite, and the
// Hessian is then the fixed-normal one: zero in the positions (the distance is linear along the
// fixed normal) and in the attitudes (the points are the poses' origins).
TEST(Hessian, SubnormalGapHoldsTheNormalFixed) {
  const Capsule point(0.0, 0.0);
  const Eigen::Vector4d identity(1, 0, 0, 0);
  for (const double gap : {5.1857130187497237e-320, 4.9406564584124654e-324, 1e-310}) {
    const SignedDistanceHessian s = signed_distance_hessian(point, Pose({gap, 0.0, 0.0}, identity),
                                                            point, Pose({0.0, 0.0, 0.0}, identity));
    EXPECT_EQ(s.distance, gap);
    EXPECT_TRUE(s.normal_jacobian.allFinite()) << gap;
    EXPECT_TRUE(s.hessian.allFinite()) << gap;
    EXPECT_EQ(s.hessian.cwiseAbs().maxCoeff(), 0.0) << gap;
  }
  // At a gap of 1e-300 the rate is representable and the normal turns: (I - n n') / gap.
  const SignedDistanceHessian s = signed_distance_hessian(point, Pose({1e-300, 0.0, 0.0}, identity),
                                                          point, Pose({0.0, 0.0, 0.0}, identity));
  EXPECT_NEAR(s.hessian(1, 1), 1e300, 1e286);
}

// Swapping the shapes permutes the Hessian's blocks.
TEST(Hessian, SwappingTheShapesPermutesTheBlocks) {
  Rng rng(33);
  for (int trial = 0; trial < 200; ++trial) {
    const TestShape ta = random_shape(rng, trial % 2 == 0), tb = random_shape(rng, trial % 3 == 0);
    const Pose pa = random_pose(rng, 1.5), pb = random_pose(rng, 1.5);
    const Matrix14 forward = proximity_hessian(ta.shape, pa, tb.shape, pb).hessian;
    const Matrix14 backward = proximity_hessian(tb.shape, pb, ta.shape, pa).hessian;
    Eigen::PermutationMatrix<14> swap;
    for (int i = 0; i < 14; ++i) swap.indices()(i) = (i + 7) % 14;
    const Matrix14 permuted = swap.transpose() * backward * swap;
    EXPECT_LE((forward - permuted).cwiseAbs().maxCoeff(),
              1e-9 * (1.0 + forward.cwiseAbs().maxCoeff()))
        << "trial " << trial;
    const Matrix14 distance = signed_distance_hessian(ta.shape, pa, tb.shape, pb).hessian;
    const Matrix14 distance_swapped =
        swap.transpose() * signed_distance_hessian(tb.shape, pb, ta.shape, pa).hessian * swap;
    EXPECT_LE((distance - distance_swapped).cwiseAbs().maxCoeff(),
              1e-9 * (1.0 + distance.cwiseAbs().maxCoeff()))
        << "distance, trial " << trial;
  }
}

// proximity_with_hessian is proximity_hessian without the Jacobians: every field it has is the
// same, bit for bit, for every ordering, both methods, apart and with intersecting cores (half the
// pairs close together).
TEST(Hessian, WithHessianRepeatsProximityHessian) {
  Rng rng(35);
  int intersecting = 0;
  for (int trial = 0; trial < 800; ++trial) {
    const TestShape ta = random_shape(rng, trial % 2 == 0), tb = random_shape(rng, trial % 4 < 2);
    const double spread = trial % 3 == 0 ? 0.2 : 1.5;
    const Pose pa = random_pose(rng, spread), pb = random_pose(rng, spread);
    for (const Method method : {Method::kDefault, Method::kInteriorPoint}) {
      ProximityHessian full;
      try {
        full = proximity_hessian(ta.shape, pa, tb.shape, pb, {method});
      } catch (const SolverError&) {
        EXPECT_THROW(proximity_with_hessian(ta.shape, pa, tb.shape, pb, {method}), SolverError);
        continue;
      }
      const ProximityWithHessian lean =
          proximity_with_hessian(ta.shape, pa, tb.shape, pb, {method});
      SCOPED_TRACE(::testing::Message()
                   << "trial " << trial << " method " << static_cast<int>(method));
      EXPECT_EQ(lean.phi, full.phi);
      EXPECT_EQ(lean.gradient, full.gradient);
      EXPECT_EQ(lean.normal, full.normal);
      EXPECT_EQ(lean.cores_intersect, full.cores_intersect);
      for (int i = 0; i < 2; ++i) {
        EXPECT_EQ(lean.core_points[i], full.core_points[i]);
        EXPECT_EQ(lean.points[i], full.points[i]);
      }
      EXPECT_EQ(lean.hessian, full.hessian);
      intersecting += full.cores_intersect;
    }
  }
  EXPECT_GT(intersecting, 10) << "too few intersecting pairs to test that branch";
}

// An analytic case: two points (capsules of length 0) at distance vector e = r1 - r2: phi =
// |e|^2 - R^2, whose Hessian in (r1, r2) is 2 [I -I; -I I] and 0 in the quaternions.
TEST(Hessian, TwoSpheres) {
  const Capsule sphere(0.0, 0.1);
  const ProximityHessian h =
      proximity_hessian(sphere, Pose({0.3, -0.2, 1.0}, {0.9, 0.1, 0.3, -0.2}), sphere,
                        Pose({-1.0, 0.5, 0.2}, {1, 0, 0, 0}));
  Matrix14 expected = Matrix14::Zero();
  for (int i = 0; i < 3; ++i) {
    expected(i, i) = expected(7 + i, 7 + i) = 2.0;
    expected(i, 7 + i) = expected(7 + i, i) = -2.0;
  }
  EXPECT_LE((h.hessian - expected).cwiseAbs().maxCoeff(), 1e-14);
}

}  // namespace
}  // namespace diffpills::testing
