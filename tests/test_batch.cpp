// proximity_batch: every entry equals the single call (to rounding where two capsules take the
// vector kernel), for every pair type and thread count (any count, however large, and also when
// the system refuses threads); bad rows are reported by index.
// The threads are the process's worker pool: reused across calls, shared by callers on several
// threads, and started anew in a forked child.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "diffpills/diffpills.hpp"
#include "support/address_space.hpp"
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

// True if a row of the batch (value, gradient) agrees with the single call on its poses. Rows of
// two capsules by the default method come from the vector kernel (src/capsule_rows.hpp) and agree
// to rounding: 1e-12 of the scene's size to the power of the value's lengths (2 for phi, 1 for the
// distance), one length less for the position parts of the gradient, and per unit of q (1 / |q|)
// for its quaternion parts. Every other row is the single call's, bit for bit.
bool row_agrees(const Shape& a, const Shape& b, Method method, const Pose& pose_a,
                const Pose& pose_b, double value, const Eigen::Matrix<double, 1, 14>& gradient,
                double single_value, const Eigen::Matrix<double, 14, 1>& single_gradient,
                int lengths) {
  const auto* capsule_a = std::get_if<Capsule>(&a);
  const auto* capsule_b = std::get_if<Capsule>(&b);
  if (capsule_a == nullptr || capsule_b == nullptr || method != Method::kDefault) {
    return value == single_value && gradient == single_gradient.transpose();
  }
  const double size =
      std::max({capsule_a->length(), capsule_b->length(), capsule_a->radius() + capsule_b->radius(),
                (pose_a.r() - pose_b.r()).norm()});
  const double unit = lengths == 2 ? size : 1.0;
  if (!(std::abs(value - single_value) <= 1e-12 * size * unit)) return false;
  for (int j = 0; j < 14; ++j) {
    const bool quaternion = (j >= 3 && j < 7) || j >= 10;
    const double q_norm = (j < 7 ? pose_a : pose_b).q().norm();
    const double tolerance = 1e-12 * unit * (quaternion ? size / q_norm : 1.0);
    if (!(std::abs(gradient(j) - single_gradient(j)) <= tolerance)) return false;
  }
  return true;
}

// True if every row of the batch agrees with the single call on its poses (row_agrees).
bool equals_single_calls(const Shape& a, const Shape& b, const Arrays& arrays,
                         const Eigen::VectorXd& phi, const GradientArray& gradient) {
  for (Eigen::Index i = 0; i < phi.size(); ++i) {
    const Pose pose_a(arrays.r_a.row(i).transpose(), arrays.q_a.row(i).transpose());
    const Pose pose_b(arrays.r_b.row(i).transpose(), arrays.q_b.row(i).transpose());
    const Proximity single = proximity(a, pose_a, b, pose_b);
    if (!row_agrees(a, b, Method::kDefault, pose_a, pose_b, phi(i), gradient.row(i), single.phi,
                    single.gradient, 2)) {
      return false;
    }
  }
  return true;
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
          const Pose pose_a(arrays.r_a.row(i).transpose(), arrays.q_a.row(i).transpose());
          const Pose pose_b(arrays.r_b.row(i).transpose(), arrays.q_b.row(i).transpose());
          const Proximity single = proximity(a, pose_a, b, pose_b, {method});
          ASSERT_TRUE(row_agrees(a, b, method, pose_a, pose_b, batch.phi(i), batch.gradient.row(i),
                                 single.phi, single.gradient, 2))
              << "row " << i << ", threads " << threads;
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
  for (int threads : {1, 2, 4, 1'000'000}) {
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

// Each thread starts on a share of consecutive rows of its own (src/batch.cpp), so the thread of
// a later share may meet its bad row first; the lower bad row is still the one reported, wherever
// the two fall: the first and the last share, either side of a share's end, both in one share.
TEST(Batch, ReportsTheFirstBadRowWhicheverThreadMeetsItFirst) {
  Rng rng(63);
  const Shape capsule = Capsule(1.0, 0.1);
  const Arrays clean = random_arrays(rng, 1000);
  for (const auto& [low, high] : {std::pair{3, 990}, std::pair{499, 500}, std::pair{249, 750},
                                  std::pair{700, 710}, std::pair{0, 999}}) {
    Arrays arrays = clean;
    arrays.q_b.row(low).setZero();
    arrays.r_a(high, 0) = std::nan("");
    for (int threads : {2, 3, 4, 0}) {
      for (int repeat = 0; repeat < 20; ++repeat) {
        try {
          proximity_batch(capsule, arrays.r_a, arrays.q_a, capsule, arrays.r_b, arrays.q_b,
                          {threads});
          ADD_FAILURE() << "no exception";
        } catch (const std::invalid_argument& error) {
          const std::string expected = "q_b[" + std::to_string(low) + "]";
          ASSERT_EQ(std::string(error.what()).rfind(expected, 0), 0u)
              << error.what() << " (threads " << threads << ")";
        }
      }
    }
  }
}

TEST(Batch, SignedDistanceEntriesEqualTheSingleCall) {
  Rng rng(63);
  const Shape capsule = random_capsule(rng, 1.0).shape;
  const Shape polygon = random_polygon(rng, 1.0).shape;
  const Arrays arrays = random_arrays(rng, 1001);
  for (const auto& [a, b] : {std::pair{capsule, capsule}, std::pair{capsule, polygon},
                             std::pair{polygon, capsule}, std::pair{polygon, polygon}}) {
    for (int threads : {1, 2, 0}) {
      const SignedDistanceBatchResult batch =
          signed_distance_batch(a, arrays.r_a, arrays.q_a, b, arrays.r_b, arrays.q_b, {threads});
      ASSERT_EQ(batch.distance.size(), 1001);
      for (Eigen::Index i = 0; i < 1001; ++i) {
        const Pose pose_a(arrays.r_a.row(i).transpose(), arrays.q_a.row(i).transpose());
        const Pose pose_b(arrays.r_b.row(i).transpose(), arrays.q_b.row(i).transpose());
        const SignedDistance single = signed_distance(a, pose_a, b, pose_b);
        ASSERT_TRUE(row_agrees(a, b, Method::kDefault, pose_a, pose_b, batch.distance(i),
                               batch.gradient.row(i), single.distance, single.gradient, 1))
            << "row " << i << ", threads " << threads;
      }
    }
  }
  Arrays bad = arrays;
  bad.q_a.row(77).setZero();
  try {
    signed_distance_batch(capsule, bad.r_a, bad.q_a, polygon, bad.r_b, bad.q_b);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(std::string(error.what()).rfind("q_a[77]: quaternion must be nonzero", 0), 0u)
        << error.what();
  }
}

// A solver failure names its row: the interior-point method's iteration cap, met on a pair 1e11
// apart whose capsule is 1e-11 of that (a QP too badly scaled for it; the default path answers).
TEST(Batch, ASolverFailureNamesItsRow) {
  PositionArray r_a = PositionArray::Zero(3, 3), r_b(3, 3);
  QuaternionArray q_a(3, 4), q_b(3, 4);
  q_a.rowwise() = Eigen::RowVector4d(1, 0, 0, 0);
  q_b.rowwise() = Eigen::RowVector4d(0.9, 0.1, 0.3, 0.2);
  r_b << 1, 2, 3, 3e10, 1e11, 2e10, 4, 5, 6;
  try {
    proximity_batch(Capsule(0, 0), r_a, q_a, Capsule(1, 0), r_b, q_b, {1, Method::kInteriorPoint});
    ADD_FAILURE() << "no exception";
  } catch (const SolverError& error) {
    EXPECT_EQ(std::string(error.what()).rfind("row 1: ", 0), 0u) << error.what();
  }
  EXPECT_NO_THROW(proximity_batch(Capsule(0, 0), r_a, q_a, Capsule(1, 0), r_b, q_b));
}

TEST(Batch, AMillionThreadsAreCappedAndGiveTheSingleCalls) {
  // 10^6 rows asked of 10^6 threads once started one thread per 512-row block (1954), and the
  // process ended when the system refused one.
  Rng rng(64);
  const Shape capsule = random_capsule(rng, 1.0).shape;
  const Arrays arrays = random_arrays(rng, 1'000'000);
  const BatchResult batch = proximity_batch(capsule, arrays.r_a, arrays.q_a, capsule, arrays.r_b,
                                            arrays.q_b, {1'000'000});
  EXPECT_TRUE(equals_single_calls(capsule, capsule, arrays, batch.phi, batch.gradient));
  const BatchResult most =
      proximity_batch(capsule, arrays.r_a.topRows(1000), arrays.q_a.topRows(1000), capsule,
                      arrays.r_b.topRows(1000), arrays.q_b.topRows(1000), {INT_MAX});
  EXPECT_TRUE(equals_single_calls(capsule, capsule, arrays, most.phi, most.gradient));
}

// Runs a 20,000-row batch (40 blocks) in a child process whose address space may grow by only
// `headroom` bytes past its inputs and outputs, so that the system refuses threads once their
// stacks (8 MB each by default) no longer fit; the child exits with 0 if every row equals the
// single call. A fresh process ("threadsafe" death tests re-run the binary) has no cached thread
// stacks to reuse.
void expect_batch_within_address_space(rlim_t headroom, int threads) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  Rng rng(65);
  const Shape capsule = random_capsule(rng, 1.0).shape;
  const Arrays arrays = random_arrays(rng, 20'000);
  Eigen::VectorXd phi(20'000);
  GradientArray gradient(20'000, 14);
  EXPECT_EXIT(
      {
        limit_address_space(headroom);
        proximity_batch(capsule, arrays.r_a, arrays.q_a, capsule, arrays.r_b, arrays.q_b, phi,
                        gradient, {threads});
        std::exit(equals_single_calls(capsule, capsule, arrays, phi, gradient) ? 0 : 1);
      },
      ::testing::ExitedWithCode(0), "");
}

TEST(Batch, StartsNoMoreThreadsThanHelp) {
  if (kSanitized) GTEST_SKIP() << "address-space limit under a sanitizer";
  // Room for a few thread stacks, not for one per block.
  expect_batch_within_address_space(64 << 20, 1'000'000);
}

TEST(Batch, GoesOnWithTheCallingThreadWhenNoThreadStarts) {
  if (kSanitized) GTEST_SKIP() << "address-space limit under a sanitizer";
  // No room for any thread's stack: the calling thread computes every row.
  for (int threads : {0, 2, 1'000'000}) expect_batch_within_address_space(1 << 20, threads);
}

// The ids of the process's threads (the entries of /proc/self/task).
std::set<std::string> thread_ids() {
  std::set<std::string> ids;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task")) {
    ids.insert(entry.path().filename().string());
  }
  return ids;
}

TEST(Batch, ReusesItsThreadsAcrossCalls) {
  // Issue 13: no thread is created per call. A two-thread batch starts the process's worker (if
  // an earlier test has not), which outlives the call; a hundred more batches of every size run on
  // the same threads (the same thread ids before and after: a thread started and joined per call,
  // as before this pool, would leave no worker behind after the first call).
  if (std::thread::hardware_concurrency() < 2) GTEST_SKIP() << "one hardware thread: no workers";
  Rng rng(66);
  const Shape capsule = random_capsule(rng, 1.0).shape;
  const Arrays arrays = random_arrays(rng, 4'000);
  Eigen::VectorXd phi(4'000);
  GradientArray gradient(4'000, 14);
  proximity_batch(capsule, arrays.r_a, arrays.q_a, capsule, arrays.r_b, arrays.q_b, phi, gradient,
                  {2});
  const std::set<std::string> after_first = thread_ids();
  EXPECT_GE(after_first.size(), 2u) << "no worker outlived the first batch";
  for (int call = 0; call < 100; ++call) {
    const Eigen::Index rows = 1 + (call * 397) % 4'000;
    proximity_batch(capsule, arrays.r_a.topRows(rows), arrays.q_a.topRows(rows), capsule,
                    arrays.r_b.topRows(rows), arrays.q_b.topRows(rows), phi.head(rows),
                    gradient.topRows(rows), {call % 2 == 0 ? 2 : 0});
    ASSERT_TRUE(
        equals_single_calls(capsule, capsule, arrays, phi.head(rows), gradient.topRows(rows)))
        << "call " << call << ", " << rows << " rows";
  }
  EXPECT_EQ(thread_ids(), after_first);
}

TEST(Batch, CallersOnSeveralThreadsAtOnceGetTheSingleCalls) {
  // The pool serves one batch at a time; a batch started while another runs computes on its own
  // thread. Four threads each run forty batches at once, with two threads asked each time.
  Rng rng(67);
  const Shape a = random_capsule(rng, 1.0).shape;
  const Shape b = random_polygon(rng, 1.0).shape;
  const Arrays arrays = random_arrays(rng, 3'000);
  std::vector<int> all_equal(4, 0);
  std::vector<std::thread> callers;
  callers.reserve(4);
  for (int t = 0; t < 4; ++t) {
    callers.emplace_back([&, t] {
      Eigen::VectorXd phi(3'000);
      GradientArray gradient(3'000, 14);
      int equal = 0;
      for (int call = 0; call < 40; ++call) {
        proximity_batch(a, arrays.r_a, arrays.q_a, b, arrays.r_b, arrays.q_b, phi, gradient, {2});
        equal += equals_single_calls(a, b, arrays, phi, gradient) ? 1 : 0;
      }
      all_equal[static_cast<std::size_t>(t)] = equal;
    });
  }
  for (std::thread& caller : callers) caller.join();
  for (int t = 0; t < 4; ++t)
    EXPECT_EQ(all_equal[static_cast<std::size_t>(t)], 40) << "caller " << t;
}

TEST(Batch, AForkedChildStartsItsOwnWorkers) {
  // fork copies only the calling thread: the parent's worker does not exist in the child. A pool
  // that waited for it would hang (what an OpenMP region does in the forked child of a process
  // that used libgomp's threads, measured with g++ 12); one that only counted on it would run on
  // one thread. The child must answer, in time, and start a worker of its own (exit status 2 if
  // it did not).
  Rng rng(68);
  const Shape capsule = random_capsule(rng, 1.0).shape;
  const Arrays arrays = random_arrays(rng, 20'000);
  Eigen::VectorXd phi(20'000);
  GradientArray gradient(20'000, 14);
  proximity_batch(capsule, arrays.r_a, arrays.q_a, capsule, arrays.r_b, arrays.q_b, phi, gradient,
                  {2});
  std::fflush(nullptr);
  const pid_t child = fork();
  ASSERT_NE(child, -1);
  if (child == 0) {
    alarm(60);  // a hang ends the child with SIGALRM
    phi.setZero();
    proximity_batch(capsule, arrays.r_a, arrays.q_a, capsule, arrays.r_b, arrays.q_b, phi, gradient,
                    {2});
    if (!equals_single_calls(capsule, capsule, arrays, phi, gradient)) _exit(1);
    // The child's own worker (the parent's copy lists one that is not there).
    const bool parallel = std::thread::hardware_concurrency() < 2 || thread_ids().size() > 1;
    _exit(parallel ? 0 : 2);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "the child was killed by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 0);
  // And the parent's pool still works.
  proximity_batch(capsule, arrays.r_a, arrays.q_a, capsule, arrays.r_b, arrays.q_b, phi, gradient,
                  {2});
  EXPECT_TRUE(equals_single_calls(capsule, capsule, arrays, phi, gradient));
}

TEST(Batch, RejectsMismatchedArraysAndBadThreadCounts) {
  Rng rng(63);
  const Shape capsule = Capsule(1.0, 0.1);
  const Arrays arrays = random_arrays(rng, 10);
  const PositionArray short_r = arrays.r_b.topRows(9);
  EXPECT_THROW(proximity_batch(capsule, arrays.r_a, arrays.q_a, capsule, short_r, arrays.q_b),
               std::invalid_argument);
  for (int threads : {-1, INT_MIN}) {
    EXPECT_THROW(proximity_batch(capsule, arrays.r_a, arrays.q_a, capsule, arrays.r_b, arrays.q_b,
                                 {threads}),
                 std::invalid_argument);
  }
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
