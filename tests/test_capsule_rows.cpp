// The capsule pairs' vector kernel (src/capsule_rows.hpp), on every instruction set this machine
// runs: the rows it answers agree with a brute-force reference in long double (phi, the signed
// distance) and with the scalar path (values and gradients, to 1e-12 of the scene), its gradients
// with central differences; swapping the capsules, moving the scene rigidly and scaling it by a
// power of two act on them as they must; and it leaves every degenerate row to the scalar path.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "capsule_rows.hpp"
#include "diffpills/diffpills.hpp"
#include "support/random_shapes.hpp"
#include "support/reference.hpp"

namespace diffpills::testing {
namespace {

using detail::CapsuleMeasure;
using detail::CapsulePair;

struct Rows {
  PositionArray r_a, r_b;
  QuaternionArray q_a, q_b;
  Eigen::Index size() const { return r_a.rows(); }
  Pose pose_a(Eigen::Index i) const { return Pose(r_a.row(i).transpose(), q_a.row(i).transpose()); }
  Pose pose_b(Eigen::Index i) const { return Pose(r_b.row(i).transpose(), q_b.row(i).transpose()); }
};

Rows random_rows(Rng& rng, Eigen::Index n, double spread) {
  Rows rows{PositionArray(n, 3), PositionArray(n, 3), QuaternionArray(n, 4), QuaternionArray(n, 4)};
  for (Eigen::Index i = 0; i < n; ++i) {
    const Pose a = random_pose(rng, spread), b = random_pose(rng, spread);
    rows.r_a.row(i) = a.r().transpose();
    rows.q_a.row(i) = a.q().transpose();
    rows.r_b.row(i) = b.r().transpose();
    rows.q_b.row(i) = b.q().transpose();
  }
  return rows;
}

struct Answers {
  Eigen::VectorXd value;
  GradientArray gradient;
  std::vector<std::uint8_t> left;
};

// The kernel over every row, in blocks as the batch hands them.
Answers kernel(const CapsulePair& pair, const Rows& rows) {
  const Eigen::Index n = rows.size();
  Answers answers{Eigen::VectorXd::Constant(n, std::nan("")), GradientArray::Constant(n, 14, 0.0),
                  std::vector<std::uint8_t>(static_cast<std::size_t>(n), 2)};
  for (Eigen::Index begin = 0; begin < n; begin += detail::kCapsuleRowsBlock) {
    const Eigen::Index end = std::min(n, begin + detail::kCapsuleRowsBlock);
    detail::capsule_rows(pair, rows.r_a, rows.q_a, rows.r_b, rows.q_b, begin, end, answers.value,
                         answers.gradient, answers.left.data() + begin);
  }
  return answers;
}

// The kernel's description of two test capsules.
CapsulePair capsule_pair(const TestShape& a, const TestShape& b, CapsuleMeasure measure) {
  const auto& capsule_a = std::get<Capsule>(a.shape);
  const auto& capsule_b = std::get<Capsule>(b.shape);
  return {capsule_a.length(), capsule_a.radius(), capsule_b.length(), capsule_b.radius(), measure};
}

// The scene's size of row i: the largest of the lengths, the radii's sum and the distance between
// the capsules' middles (the scale of the tolerances).
double scene_size(const CapsulePair& pair, const Rows& rows, Eigen::Index i) {
  return std::max({pair.length_a, pair.length_b, pair.radius_a + pair.radius_b,
                   (rows.r_a.row(i) - rows.r_b.row(i)).norm()});
}

// The names of the instruction sets Highway compiled the kernel for that this CPU runs; each test
// below runs on every one of them (hwy::SetSupportedTargetsForTest), then on the default again.
template <class Check>
void on_every_target(const Check& check) {
  for (const std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    SCOPED_TRACE(std::string("target ") + hwy::TargetName(target));
    ASSERT_STREQ(detail::capsule_rows_target(), hwy::TargetName(target));
    check();
  }
  hwy::SetSupportedTargetsForTest(0);
}

TEST(CapsuleRows, RunsOnSeveralInstructionSets) {
  // The build is portable (x86-64 baseline code plus the wider sets, chosen at run time): this
  // machine runs at least the baseline and one more.
  EXPECT_GE(hwy::SupportedAndGeneratedTargets().size(), 2u);
}

TEST(CapsuleRows, AnsweredRowsMatchBruteForceAndTheScalarPath) {
  on_every_target([] {
    Rng rng(401);
    for (const double scale : {0x1p-20, 1.0, 0x1p20}) {
      const TestShape a = random_capsule(rng, scale), b = random_capsule(rng, scale);
      for (const CapsuleMeasure measure : {CapsuleMeasure::kPhi, CapsuleMeasure::kSignedDistance}) {
        const CapsulePair pair = capsule_pair(a, b, measure);
        ASSERT_TRUE(detail::capsule_rows_apply(pair));
        const Rows rows = random_rows(rng, 1'500, 1.5 * scale);
        const Answers answers = kernel(pair, rows);
        const double radii = pair.radius_a + pair.radius_b;
        int answered = 0;
        for (Eigen::Index i = 0; i < rows.size(); ++i) {
          const auto left = answers.left[static_cast<std::size_t>(i)];
          ASSERT_LE(left, 1) << "row " << i << " not marked";
          if (left == 1) continue;
          ++answered;
          const Pose pose_a = rows.pose_a(i), pose_b = rows.pose_b(i);
          const double size = scene_size(pair, rows, i);
          const long double distance =
              brute_force_closest(to_world(a, pose_a), to_world(b, pose_b)).distance;
          const double q_norm_a = pose_a.q().norm(), q_norm_b = pose_b.q().norm();
          Eigen::Matrix<double, 14, 1> scalar_gradient;
          double scalar_value = 0.0, reference = 0.0, unit = 0.0;
          if (measure == CapsuleMeasure::kPhi) {
            const Proximity single = proximity(a.shape, pose_a, b.shape, pose_b);
            scalar_value = single.phi;
            scalar_gradient = single.gradient;
            reference =
                static_cast<double>(distance * distance - static_cast<long double>(radii) *
                                                              static_cast<long double>(radii));
            unit = size;  // phi and its derivatives carry one more length
          } else {
            const SignedDistance single = signed_distance(a.shape, pose_a, b.shape, pose_b);
            scalar_value = single.distance;
            scalar_gradient = single.gradient;
            reference = static_cast<double>(distance) - radii;
            unit = 1.0;
          }
          const double value = answers.value(i);
          ASSERT_NEAR(value, reference, 1e-12 * size * unit) << "row " << i;
          ASSERT_NEAR(value, scalar_value, 1e-12 * size * unit) << "row " << i;
          for (int j = 0; j < 14; ++j) {
            // Position parts in value per length; quaternion parts in value per unit of q, which
            // carry a length (the point's offset along the axis) and 1 / |q|.
            const bool quaternion = (j >= 3 && j < 7) || j >= 10;
            const double q_norm = j < 7 ? q_norm_a : q_norm_b;
            const double tolerance = 1e-12 * unit * (quaternion ? size / q_norm : 1.0);
            ASSERT_NEAR(answers.gradient(i, j), scalar_gradient(j), tolerance)
                << "row " << i << ", entry " << j;
          }
        }
        // Random poses are almost all generic: the kernel answers them, not the scalar path.
        EXPECT_GE(answered, 1'400) << "scale " << scale;
      }
    }
  });
}

// Properties of the kernel's rows, on every instruction set: swapping the capsules gives the same
// value and the gradient with its halves exchanged, moving the whole scene rigidly leaves the value
// unchanged, and scaling every length by a power of two scales the value and gradient exactly
// (the kernel's arithmetic is then the same up to exponents).
TEST(CapsuleRows, SwapRigidMotionAndPowerOfTwoScaling) {
  on_every_target([] {
    Rng rng(404);
    const TestShape a = random_capsule(rng, 1.0), b = random_capsule(rng, 1.0);
    for (const CapsuleMeasure measure : {CapsuleMeasure::kPhi, CapsuleMeasure::kSignedDistance}) {
      const CapsulePair pair = capsule_pair(a, b, measure);
      const CapsulePair swapped{pair.length_b, pair.radius_b, pair.length_a, pair.radius_a,
                                measure};
      const int lengths = measure == CapsuleMeasure::kPhi ? 2 : 1;
      const Rows rows = random_rows(rng, 300, 1.5);
      const Answers answers = kernel(pair, rows);
      const Answers swap = kernel(swapped, Rows{rows.r_b, rows.r_a, rows.q_b, rows.q_a});
      // The whole scene turned by q_turn about the origin and moved by r_turn.
      const Pose turn = random_pose(rng, 2.0);
      const Eigen::Quaterniond q_turn(turn.q()(0), turn.q()(1), turn.q()(2), turn.q()(3));
      Rows moved = rows;
      for (Eigen::Index i = 0; i < rows.size(); ++i) {
        for (auto [r, q] : {std::pair{&moved.r_a, &moved.q_a}, std::pair{&moved.r_b, &moved.q_b}}) {
          r->row(i) =
              (q_turn.normalized() * Eigen::Vector3d(r->row(i).transpose()) + turn.r()).transpose();
          const Eigen::Quaterniond q_row((*q)(i, 0), (*q)(i, 1), (*q)(i, 2), (*q)(i, 3));
          const Eigen::Quaterniond composed = q_turn.normalized() * q_row;
          q->row(i) << composed.w(), composed.x(), composed.y(), composed.z();
        }
      }
      const Answers motion = kernel(pair, moved);
      constexpr int kExponent = 13;
      Rows scaled = rows;
      scaled.r_a *= std::ldexp(1.0, kExponent);
      scaled.r_b *= std::ldexp(1.0, kExponent);
      const CapsulePair big{
          std::ldexp(pair.length_a, kExponent), std::ldexp(pair.radius_a, kExponent),
          std::ldexp(pair.length_b, kExponent), std::ldexp(pair.radius_b, kExponent), measure};
      const Answers large = kernel(big, scaled);
      for (Eigen::Index i = 0; i < rows.size(); ++i) {
        const auto k = static_cast<std::size_t>(i);
        ASSERT_EQ(swap.left[k], answers.left[k]) << "row " << i;
        ASSERT_EQ(large.left[k], answers.left[k]) << "row " << i;
        if (answers.left[k] != 0) continue;
        const double size = scene_size(pair, rows, i);
        const double unit = lengths == 2 ? size : 1.0;
        EXPECT_NEAR(swap.value(i), answers.value(i), 1e-12 * size * unit) << "row " << i;
        for (int j = 0; j < 14; ++j) {
          const bool quaternion = (j >= 3 && j < 7) || j >= 10;
          const double tolerance = 1e-12 * unit * (quaternion ? 2 * size : 1.0);  // |q| >= 0.5
          EXPECT_NEAR(swap.gradient(i, (j + 7) % 14), answers.gradient(i, j), tolerance)
              << "row " << i << ", entry " << j;
        }
        if (motion.left[k] == 0) {
          EXPECT_NEAR(motion.value(i), answers.value(i), 1e-12 * size * unit) << "row " << i;
        }
        // Exact: every length carries 2^13, the quaternions are unchanged.
        EXPECT_EQ(large.value(i), std::ldexp(answers.value(i), lengths * kExponent)) << "row " << i;
        for (int j = 0; j < 14; ++j) {
          const bool quaternion = (j >= 3 && j < 7) || j >= 10;
          const int power = (lengths - 1) + (quaternion ? 1 : 0);
          EXPECT_EQ(large.gradient(i, j), std::ldexp(answers.gradient(i, j), power * kExponent))
              << "row " << i << ", entry " << j;
        }
      }
    }
  });
}

TEST(CapsuleRows, GradientsMatchCentralDifferences) {
  on_every_target([] {
    Rng rng(402);
    const TestShape a = random_capsule(rng, 1.0), b = random_capsule(rng, 1.0);
    for (const CapsuleMeasure measure : {CapsuleMeasure::kPhi, CapsuleMeasure::kSignedDistance}) {
      const CapsulePair pair = capsule_pair(a, b, measure);
      const Rows rows = random_rows(rng, 200, 1.5);
      const Answers answers = kernel(pair, rows);
      for (Eigen::Index i = 0; i < rows.size(); ++i) {
        if (answers.left[static_cast<std::size_t>(i)] != 0) continue;
        for (int j = 0; j < 14; ++j) {
          constexpr double kStep = 1e-6;
          Rows plus = rows, minus = rows;
          const auto entry = [j, i](Rows& r) -> double& {
            if (j < 3) return r.r_a(i, j);
            if (j < 7) return r.q_a(i, j - 3);
            if (j < 10) return r.r_b(i, j - 7);
            return r.q_b(i, j - 10);
          };
          entry(plus) += kStep;
          entry(minus) -= kStep;
          const Answers up = kernel(pair, plus), down = kernel(pair, minus);
          // A step that moves the row out of the generic case (or across a clamp's kink) tells
          // nothing about the derivative at the row.
          if (up.left[static_cast<std::size_t>(i)] != 0 ||
              down.left[static_cast<std::size_t>(i)] != 0) {
            continue;
          }
          const double difference = (up.value(i) - down.value(i)) / (2 * kStep);
          EXPECT_NEAR(answers.gradient(i, j), difference, 1e-6 * (1.0 + std::abs(difference)))
              << "row " << i << ", entry " << j;
        }
      }
    }
  });
}

// Cores close together: D = w + s u - t v cancels to a few eps S, so D / |D|, the signed
// distance's gradient direction, is only accurate to ~eps S / |D| (phi's gradient 2 D needs eps S
// absolutely). A hostile review found 4e-8 errors at a gap of 1e-8 S. Crossing segments at gaps
// 1e-9 .. 1e-1 of the scene, in random orientations of the whole scene, and the review's row:
// every batch row agrees with the single call within the promise, whichever path answered it.
TEST(CapsuleRows, CloseCoresAgreeWithTheSingleCall) {
  on_every_target([] {
    Rng rng(403);
    const Capsule capsule_a(1.0, 0.1), capsule_b(1.0, 0.0);
    Rows rows{PositionArray(0, 3), PositionArray(0, 3), QuaternionArray(0, 4),
              QuaternionArray(0, 4)};
    std::vector<Pose> poses_a, poses_b;
    double gap = 1e-9;
    for (int step = 0; step < 18; ++step, gap *= 3.1) {  // gaps 1e-9 3.1^step, up to 0.23
      for (int trial = 0; trial < 20; ++trial) {
        // b crosses a's axis at 70 degrees, `gap` above it, with its crossing point at s_b along
        // b (an end when |s_b| = 0.5) over a's point at s_a; then the whole scene is turned.
        const Pose turn = random_pose(rng, 1.0);
        const Eigen::Matrix3d R = rotation_matrix(turn.q());
        const double s_a = std::uniform_real_distribution<double>(-0.5, 0.5)(rng);
        const double s_b =
            trial % 4 == 0 ? 0.5 : std::uniform_real_distribution<double>(-0.4, 0.4)(rng);
        const Eigen::Vector3d axis_b(std::cos(1.22), std::sin(1.22), 0.0);
        const Eigen::Vector3d middle_b = Eigen::Vector3d(s_a, 0, gap) - s_b * axis_b;
        const Eigen::Vector4d q_b(std::cos(0.61), 0, 0, std::sin(0.61));  // 1.22 rad about z
        const Eigen::Vector4d q_turn = turn.q() / turn.q().norm();
        const auto compose = [&](const Eigen::Vector4d& q) {  // turn then q: q_turn * q
          Eigen::Vector4d out;
          out << q_turn(0) * q(0) - q_turn.tail<3>().dot(q.tail<3>()),
              q_turn(0) * q.tail<3>() + q(0) * q_turn.tail<3>() +
                  q_turn.tail<3>().cross(q.tail<3>());
          return out;
        };
        poses_a.emplace_back(turn.r(), q_turn);
        poses_b.emplace_back(turn.r() + R * middle_b, compose(q_b));
      }
    }
    poses_a.emplace_back(
        Eigen::Vector3d(-0.7366259628102443, -0.9010619057334996, 0.5469427694517313),
        Eigen::Vector4d(-0.6990587457554023, -0.20410891716030366, -0.6416845250404185,
                        0.24061876535753524));
    poses_b.emplace_back(
        Eigen::Vector3d(-1.1055420327063281, -0.8028751232304318, 0.7218144361980663),
        Eigen::Vector4d(0.11876200870253072, -0.05515193197242101, -0.7547025595300207,
                        0.642866935164257));
    const auto n = static_cast<Eigen::Index>(poses_a.size());
    rows = Rows{PositionArray(n, 3), PositionArray(n, 3), QuaternionArray(n, 4),
                QuaternionArray(n, 4)};
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      rows.r_a.row(i) = poses_a[k].r().transpose();
      rows.q_a.row(i) = poses_a[k].q().transpose();
      rows.r_b.row(i) = poses_b[k].r().transpose();
      rows.q_b.row(i) = poses_b[k].q().transpose();
    }
    const SignedDistanceBatchResult distances =
        signed_distance_batch(capsule_a, rows.r_a, rows.q_a, capsule_b, rows.r_b, rows.q_b, {1});
    const BatchResult phis =
        proximity_batch(capsule_a, rows.r_a, rows.q_a, capsule_b, rows.r_b, rows.q_b, {1});
    for (Eigen::Index i = 0; i < n; ++i) {
      const Pose pose_a = rows.pose_a(i), pose_b = rows.pose_b(i);
      const SignedDistance distance = signed_distance(capsule_a, pose_a, capsule_b, pose_b);
      const Proximity phi = proximity(capsule_a, pose_a, capsule_b, pose_b);
      const double size = std::max(1.0, (pose_a.r() - pose_b.r()).norm());
      ASSERT_NEAR(distances.distance(i), distance.distance, 1e-12 * size) << "row " << i;
      ASSERT_NEAR(phis.phi(i), phi.phi, 1e-12 * size * size) << "row " << i;
      for (int j = 0; j < 14; ++j) {
        const bool quaternion = (j >= 3 && j < 7) || j >= 10;
        const double per_q = quaternion ? size : 1.0;  // |q| = 1 here
        ASSERT_NEAR(distances.gradient(i, j), distance.gradient(j), 1e-12 * per_q)
            << "signed distance, row " << i << ", entry " << j;
        ASSERT_NEAR(phis.gradient(i, j), phi.gradient(j), 1e-12 * size * per_q)
            << "phi, row " << i << ", entry " << j;
      }
    }
  });
}

TEST(CapsuleRows, LeavesEveryDegenerateRowToTheScalarPath) {
  on_every_target([] {
    const CapsulePair pair{1.0, 0.1, 0.8, 0.2, CapsuleMeasure::kPhi};
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    const double twist = 0.09;  // sin^2 = 0.0081 <= 1e-2
    Rows rows{PositionArray(12, 3), PositionArray(12, 3), QuaternionArray(12, 4),
              QuaternionArray(12, 4)};
    // Defaults: a generic pair (b 0.5 above a, turned by 60 degrees about z).
    for (Eigen::Index i = 0; i < 12; ++i) {
      rows.r_a.row(i) << 0.1, 0.2, 0.3;
      rows.q_a.row(i) << 1, 0, 0, 0;
      rows.r_b.row(i) << 0.1, 0.2, 0.8;
      rows.q_b.row(i) << std::cos(M_PI / 6), 0, 0, std::sin(M_PI / 6);
    }
    rows.q_b.row(1) << 1, 0, 0, 0;                                      // parallel
    rows.q_b.row(2) << std::cos(twist / 2), 0, 0, std::sin(twist / 2);  // nearly parallel
    rows.r_b.row(3) = rows.r_a.row(3);                                  // cores crossing
    rows.r_b.row(4) << 0.1, 0.2, 0.3 + 1e-10;                           // within 1e-9
    rows.r_a(5, 1) = nan;                                               // not a number
    rows.q_b(6, 2) = inf;                                               // infinite
    rows.q_a.row(7).setZero();                                          // no quaternion
    rows.r_b(8, 0) = 1e13;                                              // beyond 2^40
    rows.q_a.row(9) << 1e-10, 0, 0, 0;                                  // |q|^2 < 2^-60
    rows.q_b.row(10) << 1e10, 0, 0, 1e10;                               // |q|^2 > 2^60
    const Answers answers = kernel(pair, rows);
    const std::vector<std::uint8_t> expected = {0, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 0};
    EXPECT_EQ(answers.left, expected);
    EXPECT_TRUE(std::isnan(answers.value(1))) << "a row left is not written";
    // The signed distance also leaves cores within 1e-2 of the scene (row 4 at 5e-3 of it).
    rows.r_b.row(4) << 0.1, 0.2, 0.3 + 5e-3 * std::sqrt(1.73);
    CapsulePair distance_pair = pair;
    distance_pair.measure = CapsuleMeasure::kSignedDistance;
    EXPECT_EQ(kernel(distance_pair, rows).left, expected);
    EXPECT_EQ(kernel(pair, rows).left[4], 0) << "phi answers the same row";
    for (CapsulePair other : {CapsulePair{0.0, 0.1, 1.0, 0.1, CapsuleMeasure::kPhi},
                              CapsulePair{1.0, 0.1, 0x1p41, 0.1, CapsuleMeasure::kPhi},
                              CapsulePair{1.0, 0x1p41, 1.0, 0.1, CapsuleMeasure::kPhi},
                              CapsulePair{0x1p-41, 0.1, 1.0, 0.1, CapsuleMeasure::kPhi}}) {
      EXPECT_FALSE(detail::capsule_rows_apply(other)) << other.length_a << " " << other.length_b;
    }
  });
}

}  // namespace
}  // namespace diffpills::testing
