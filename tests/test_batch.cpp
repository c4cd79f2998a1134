// proximity_batch: every entry equals the single call, for every pair type and thread count;
// bad rows are reported by index.
#include <gtest/gtest.h>

#include <thread>

#include "diffpills/diffpills.hpp"
#include "support/random_shapes.hpp"

namespace diffpills::testing {
namespace {

struct Arrays {
  PositionArray r_a, r_b;
  QuaternionArray q_a, q_b;
};

Arrays random_arrays(Rng& rng, Eigen::Index n) {
  Arrays arrays{PositionArray(n, 3), PositionArray(n, 3), QuaternionArray(n, 4),
                QuaternionArray(n, 4)};
  for (Eigen::Index i = 0; i < n; ++i) {
    const Pose a = random_pose(rng, 1.5), b = random_pose(rng, 1.5);
    arrays.r_a.row(i) = a.r().transpose();
    arrays.q_a.row(i) = a.q().transpose();
    arrays.r_b.row(i) = b.r().transpose();
    arrays.q_b.row(i) = b.q().transpose();
  }
  return arrays;
}

TEST(Batch, EveryEntryEqualsTheSingleCall) {
  Rng rng(61);
  const Shape capsule = random_capsule(rng, 1.0).shape;
  const Shape polygon = random_polygon(rng, 1.0).shape;
  const Arrays arrays = random_arrays(rng, 1001);  // not a multiple of the thread counts
  for (const auto& [a, b] : {std::pair{capsule, capsule}, std::pair{capsule, polygon},
                             std::pair{polygon, capsule}, std::pair{polygon, polygon}}) {
    for (int threads : {1, 2, 3, 0}) {
      for (Method method : {Method::kDefault, Method::kInteriorPoint}) {
        const BatchResult batch = proximity_batch(a, arrays.r_a, arrays.q_a, b, arrays.r_b,
                                                  arrays.q_b, {threads, method});
        ASSERT_EQ(batch.phi.size(), 1001);
        for (Eigen::Index i = 0; i < 1001; ++i) {
          const Proximity single = proximity(
              a, Pose(arrays.r_a.row(i).transpose(), arrays.q_a.row(i).transpose()), b,
              Pose(arrays.r_b.row(i).transpose(), arrays.q_b.row(i).transpose()), {method});
          ASSERT_EQ(batch.phi(i), single.phi) << "row " << i << ", threads " << threads;
          ASSERT_EQ(batch.gradient.row(i), single.gradient.transpose());
        }
      }
    }
  }
}

TEST(Batch, ReportsTheFirstBadRow) {
  Rng rng(62);
  const Shape capsule = Capsule(1.0, 0.1);
  Arrays arrays = random_arrays(rng, 500);
  arrays.q_b.row(317).setZero();
  arrays.r_a(401, 2) = std::nan("");
  for (int threads : {1, 2, 4}) {
    try {
      proximity_batch(capsule, arrays.r_a, arrays.q_a, capsule, arrays.r_b, arrays.q_b, {threads});
      ADD_FAILURE() << "no exception";
    } catch (const std::invalid_argument& error) {
      EXPECT_EQ(std::string(error.what()).rfind("q_b[317]: quaternion must be nonzero", 0), 0u)
          << error.what();
    }
  }
  arrays.q_b.row(317) << 1, 0, 0, 0;
  try {
    proximity_batch(capsule, arrays.r_a, arrays.q_a, capsule, arrays.r_b, arrays.q_b);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(std::string(error.what()).rfind("r_a[401]: must be finite", 0), 0u) << error.what();
  }
}

TEST(Batch, RejectsMismatchedArraysAndBadThreadCounts) {
  Rng rng(63);
  const Shape capsule = Capsule(1.0, 0.1);
  const Arrays arrays = random_arrays(rng, 10);
  const PositionArray short_r = arrays.r_b.topRows(9);
  EXPECT_THROW(proximity_batch(capsule, arrays.r_a, arrays.q_a, capsule, short_r, arrays.q_b),
               std::invalid_argument);
  EXPECT_THROW(
      proximity_batch(capsule, arrays.r_a, arrays.q_a, capsule, arrays.r_b, arrays.q_b, {-1}),
      std::invalid_argument);
  Eigen::VectorXd phi(10);
  GradientArray gradient(9, 14);  // one row short
  EXPECT_THROW(proximity_batch(capsule, arrays.r_a, arrays.q_a, capsule, arrays.r_b, arrays.q_b,
                               phi, gradient),
               std::invalid_argument);
  const BatchResult empty = proximity_batch(capsule, PositionArray(0, 3), QuaternionArray(0, 4),
                                            capsule, PositionArray(0, 3), QuaternionArray(0, 4));
  EXPECT_EQ(empty.phi.size(), 0);
  EXPECT_EQ(empty.gradient.rows(), 0);
}

}  // namespace
}  // namespace diffpills::testing
