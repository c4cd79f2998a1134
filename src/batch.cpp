#include "diffpills/batch.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <exception>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <variant>

#include "capsule_rows.hpp"
#include "diffpills/signed_distance.hpp"
#include "worker_pool.hpp"

namespace diffpills {
namespace {

// "pose.q: ..." from the Pose constructor becomes "q_b[17]: ..." for row 17 of q_b.
[[noreturn]] void rethrow_for_row(const std::invalid_argument& error, char side, Eigen::Index row) {
  std::string message = error.what();
  const std::string field = message.rfind("pose.r", 0) == 0 ? "r_" : "q_";
  const std::size_t colon = message.find(": ");
  throw std::invalid_argument(field + side + "[" + std::to_string(row) + "]" +
                              (colon == std::string::npos ? message : message.substr(colon)));
}

Pose pose_at(const Eigen::Ref<const PositionArray>& r, const Eigen::Ref<const QuaternionArray>& q,
             Eigen::Index row, char side) {
  try {
    return Pose(r.row(row).transpose(), q.row(row).transpose());
  } catch (const std::invalid_argument& error) {
    rethrow_for_row(error, side, row);
  }
}

// A solver failure of row i says which row: "row 17: the interior-point method stopped ...".
// (An invalid pose already names its row, pose_at.)
std::exception_ptr with_row(std::exception_ptr error, Eigen::Index row) {
  try {
    std::rethrow_exception(error);
  } catch (const SolverError& failure) {
    return std::make_exception_ptr(
        SolverError("row " + std::to_string(row) + ": " + std::string(failure.what())));
  } catch (...) {
    return error;
  }
}

// Rows [0, rows) in `blocks` blocks of block_rows (at most kMaxBlockRows), shared by `threads`
// threads. fast_rows(begin, end, left) answers what it can of a block (the capsule pairs' vector
// kernel, capsule_rows.hpp) and sets left[i - begin] for each row it leaves; row_work(i) computes
// and writes row i by the scalar path.
//
// Who takes which block: the blocks are cut into shares of consecutive blocks, one per thread's
// slot (worker_pool.hpp: 0 the calling thread, 1.. the workers), and each share has a counter its
// blocks are taken from in order. A thread takes the blocks of its own share, then helps with the
// others' (the next share's counter first), so a thread that joined late or whose rows cost more
// is helped (pair costs vary: a crossing pair of polygons stops early, a distant one prunes most
// edge pairs; a fixed split with no help measured 1.79x on two threads against 1.8-1.9x). Taking
// every block from one counter instead (before this) balanced as well but sent each block to
// either thread at random, so a loop calling the batch again found half its rows in the other
// core's cache, and two threads' writes interleaved block by block. In paired runs, two threads
// ran 10^4 capsule pairs 1.42-1.67x faster than one with the single counter and 1.61-1.91x with
// the shares, 10^6 pairs 1.64-1.78x and 1.87-2.2x (BENCHMARKS.md, 2026-11-28).
//
// The shares live in the job, on the calling thread's stack (the batch into caller-owned outputs
// allocates nothing, batch.hpp): at most kMaxShares of them. Beyond that many threads, slots
// share a share's counter (slot % kMaxShares), which only makes them take its blocks in turn.
constexpr Eigen::Index kMaxBlockRows = 512;
constexpr Eigen::Index kMaxShares = 64;
static_assert(kMaxBlockRows <= detail::kCapsuleRowsBlock);

template <class FastRows, class RowWork>
struct RowsJob final : detail::Job {
  RowsJob(const FastRows& fast, const RowWork& work, Eigen::Index rows, Eigen::Index block_rows,
          Eigen::Index blocks, Eigen::Index threads)
      : fast_rows(fast),
        row_work(work),
        rows(rows),
        block_rows(block_rows),
        share_count(std::min(threads, kMaxShares)),
        first_error_row(rows) {
    for (Eigen::Index k = 0; k < share_count; ++k) {
      Share& share = shares[static_cast<std::size_t>(k)];
      share.next_block = k * blocks / share_count;
      share.end_block = (k + 1) * blocks / share_count;
    }
  }

  // Every exception of a row is caught here and carried to the caller: one escaping a worker
  // would end the process with std::terminate.
  void run(int slot) noexcept override {
    const auto count = static_cast<std::size_t>(share_count);
    for (std::size_t turn = 0; turn < count; ++turn) {
      Share& share = shares[(static_cast<std::size_t>(slot) + turn) % count];
      for (Eigen::Index block = share.next_block++; block < share.end_block;
           block = share.next_block++) {
        const Eigen::Index begin = block * block_rows;
        // A lower row already failed: the rest of this share is moot (its blocks only rise), but
        // the next share may hold blocks below the failing row, which must still be processed.
        if (begin > first_error_row) break;
        run_block(begin, std::min(rows, begin + block_rows));
      }
    }
  }

  void run_block(Eigen::Index begin, Eigen::Index end) {
    std::array<std::uint8_t, kMaxBlockRows> left;
    fast_rows(begin, end, left.data());
    for (Eigen::Index i = begin; i < end; ++i) {
      if (left[static_cast<std::size_t>(i - begin)] == 0) continue;
      try {
        row_work(i);
      } catch (...) {
        // Every block below a failing row is still processed, so the lowest row recorded is the
        // first bad row whatever the thread timing.
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (i < first_error_row) {
          first_error_row = i;
          first_error = with_row(std::current_exception(), i);
        }
        return;
      }
    }
  }

  // A slot's consecutive blocks [next_block, end_block); a cache line each, so that the threads'
  // counters do not share one.
  struct alignas(64) Share {
    std::atomic<Eigen::Index> next_block{0};
    Eigen::Index end_block = 0;
  };

  const FastRows& fast_rows;
  const RowWork& row_work;
  const Eigen::Index rows, block_rows, share_count;
  std::array<Share, kMaxShares> shares;
  std::atomic<Eigen::Index> first_error_row;
  std::exception_ptr first_error;  // of first_error_row, written under error_mutex
  std::mutex error_mutex;
};

// The vector kernel's pair if both shapes are capsules it covers (capsule_rows_apply).
std::optional<detail::CapsulePair> capsule_pair(const Shape& a, const Shape& b,
                                                detail::CapsuleMeasure measure) {
  const auto* capsule_a = std::get_if<Capsule>(&a);
  const auto* capsule_b = std::get_if<Capsule>(&b);
  if (capsule_a == nullptr || capsule_b == nullptr) return std::nullopt;
  const detail::CapsulePair pair{capsule_a->length(), capsule_a->radius(), capsule_b->length(),
                                 capsule_b->radius(), measure};
  if (!detail::capsule_rows_apply(pair)) return std::nullopt;
  return pair;
}

// std::thread::hardware_concurrency(), at least 1, read once per process: glibc answers it by
// reading /sys/devices/system/cpu/online at every call, ~2.4 us here, which was 5-6 times the work
// of a 16-row batch (2.97 -> 0.53 us a call with it read once). glibc counts the online CPUs, not
// the process's affinity mask, so the count is the same at every call unless a CPU is brought
// online or taken offline: one brought online later is not used, one taken offline only makes
// its thread take turns.
Eigen::Index hardware_threads() {
  static const Eigen::Index count = std::max(1u, std::thread::hardware_concurrency());
  return count;
}

// The batch of either query: the vector kernel answers what it can of each block if `capsules`
// holds its pair, and `query(pose_a[i], pose_b[i], i)` writes row i of value and gradient for
// every other row. `name` and `value_name` are the function's and its output's names, for
// messages. value and gradient are views taken by const reference; the rows are written through
// copies of them, which view the same numbers.
template <class Query>
void run_batch(const char* name, const char* value_name, const Eigen::Ref<const PositionArray>& r_a,
               const Eigen::Ref<const QuaternionArray>& q_a,
               const Eigen::Ref<const PositionArray>& r_b,
               const Eigen::Ref<const QuaternionArray>& q_b,
               const Eigen::Ref<Eigen::VectorXd>& value, const Eigen::Ref<GradientArray>& gradient,
               const BatchOptions& options, const std::optional<detail::CapsulePair>& capsules,
               const Query& query) {
  const Eigen::Index n = r_a.rows();
  if (q_a.rows() != n || r_b.rows() != n || q_b.rows() != n) {
    throw std::invalid_argument(
        std::string(name) + ": r_a, q_a, r_b and q_b must have the same number of rows (got " +
        std::to_string(n) + ", " + std::to_string(q_a.rows()) + ", " + std::to_string(r_b.rows()) +
        ", " + std::to_string(q_b.rows()) + ")");
  }
  if (options.threads < 0) {
    throw std::invalid_argument("threads: must be >= 0 (0 = every hardware thread)");
  }
  if (value.size() != n || gradient.rows() != n) {
    throw std::invalid_argument(std::string(name) + ": " + value_name +
                                " and gradient must have one row per pose (" + std::to_string(n) +
                                ")");
  }

  // Blocks of 512 rows keep the counters cold; a small batch is cut into at least 16 blocks per
  // thread (of at least 16 rows), so that the threads end within a small block of each other.
  // Each row is written by exactly one thread; nothing else is shared.
  const Eigen::Index hardware = hardware_threads();
  const Eigen::Index requested = options.threads == 0 ? hardware : options.threads;
  const auto fast_rows = [&](Eigen::Index begin, Eigen::Index end, std::uint8_t* left) noexcept {
    if (capsules) {
      detail::capsule_rows(*capsules, r_a, q_a, r_b, q_b, begin, end, value, gradient, left);
    } else {
      std::fill(left, left + (end - begin), std::uint8_t{1});  // every row to the scalar path
    }
  };
  const auto row_work = [&](Eigen::Index i) {
    query(pose_at(r_a, q_a, i, 'a'), pose_at(r_b, q_b, i, 'b'), i);
  };
  const Eigen::Index block_rows = std::clamp<Eigen::Index>(n / (16 * hardware), 16, kMaxBlockRows);
  const Eigen::Index blocks = (n + block_rows - 1) / block_rows;
  // Threads beyond the hardware's only take turns, and threads beyond the blocks find no work, so
  // a request above either is capped: threads = 10^6 uses no more threads than threads = 0.
  const Eigen::Index threads = std::max<Eigen::Index>(1, std::min({requested, hardware, blocks}));
  RowsJob<decltype(fast_rows), decltype(row_work)> job(fast_rows, row_work, n, block_rows, blocks,
                                                       threads);
  // The calling thread works beside threads - 1 of the process's workers (worker_pool.hpp: started
  // once, reused by every call; a worker the system refuses is one fewer, never an error).
  detail::WorkerPool::instance().run(job, static_cast<int>(threads - 1));
  if (job.first_error) std::rethrow_exception(job.first_error);
}

}  // namespace

void proximity_batch(const Shape& a, const Eigen::Ref<const PositionArray>& r_a,
                     const Eigen::Ref<const QuaternionArray>& q_a, const Shape& b,
                     const Eigen::Ref<const PositionArray>& r_b,
                     const Eigen::Ref<const QuaternionArray>& q_b, Eigen::Ref<Eigen::VectorXd> phi,
                     Eigen::Ref<GradientArray> gradient, const BatchOptions& options) {
  const ProximityOptions single{options.method};
  // Two capsules by the default method: the vector kernel first, the scalar path for the rest.
  const auto capsules = options.method == Method::kDefault
                            ? capsule_pair(a, b, detail::CapsuleMeasure::kPhi)
                            : std::nullopt;
  run_batch("proximity_batch", "phi", r_a, q_a, r_b, q_b, phi, gradient, options, capsules,
            [&](const Pose& pose_a, const Pose& pose_b, Eigen::Index i) {
              const Proximity result = proximity(a, pose_a, b, pose_b, single);
              phi(i) = result.phi;
              gradient.row(i) = result.gradient.transpose();
            });
}

void signed_distance_batch(const Shape& a, const Eigen::Ref<const PositionArray>& r_a,
                           const Eigen::Ref<const QuaternionArray>& q_a, const Shape& b,
                           const Eigen::Ref<const PositionArray>& r_b,
                           const Eigen::Ref<const QuaternionArray>& q_b,
                           Eigen::Ref<Eigen::VectorXd> distance, Eigen::Ref<GradientArray> gradient,
                           const BatchOptions& options) {
  run_batch("signed_distance_batch", "distance", r_a, q_a, r_b, q_b, distance, gradient, options,
            capsule_pair(a, b, detail::CapsuleMeasure::kSignedDistance),
            [&](const Pose& pose_a, const Pose& pose_b, Eigen::Index i) {
              const SignedDistance result = signed_distance(a, pose_a, b, pose_b);
              distance(i) = result.distance;
              gradient.row(i) = result.gradient.transpose();
            });
}

BatchResult proximity_batch(const Shape& a, const Eigen::Ref<const PositionArray>& r_a,
                            const Eigen::Ref<const QuaternionArray>& q_a, const Shape& b,
                            const Eigen::Ref<const PositionArray>& r_b,
                            const Eigen::Ref<const QuaternionArray>& q_b,
                            const BatchOptions& options) {
  BatchResult result;
  result.phi.resize(r_a.rows());
  result.gradient.resize(r_a.rows(), 14);
  proximity_batch(a, r_a, q_a, b, r_b, q_b, result.phi, result.gradient, options);
  return result;
}

SignedDistanceBatchResult signed_distance_batch(const Shape& a,
                                                const Eigen::Ref<const PositionArray>& r_a,
                                                const Eigen::Ref<const QuaternionArray>& q_a,
                                                const Shape& b,
                                                const Eigen::Ref<const PositionArray>& r_b,
                                                const Eigen::Ref<const QuaternionArray>& q_b,
                                                const BatchOptions& options) {
  SignedDistanceBatchResult result;
  result.distance.resize(r_a.rows());
  result.gradient.resize(r_a.rows(), 14);
  signed_distance_batch(a, r_a, q_a, b, r_b, q_b, result.distance, result.gradient, options);
  return result;
}

}  // namespace diffpills
