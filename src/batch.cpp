#include "diffpills/batch.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include "diffpills/signed_distance.hpp"

namespace diffpills {
namespace {

// "pose.q: ..." from the Pose constructor becomes "q_b[17]: ..." for row 17 of q_b.
[[noreturn]] void rethrow_for_row(const std::invalid_argument& error, const std::string& side,
                                  Eigen::Index row) {
  std::string message = error.what();
  const std::string field = message.rfind("pose.r", 0) == 0 ? "r_" : "q_";
  const std::size_t colon = message.find(": ");
  throw std::invalid_argument(field + side + "[" + std::to_string(row) + "]" +
                              (colon == std::string::npos ? message : message.substr(colon)));
}

Pose pose_at(const Eigen::Ref<const PositionArray>& r, const Eigen::Ref<const QuaternionArray>& q,
             Eigen::Index row, const std::string& side) {
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

// The batch of either query: row i gets `query(pose_a[i], pose_b[i])`'s value and gradient.
// `name` and `value_name` are the function's and its output's names, for messages.
template <class Query>
void run_batch(const char* name, const char* value_name, const Eigen::Ref<const PositionArray>& r_a,
               const Eigen::Ref<const QuaternionArray>& q_a,
               const Eigen::Ref<const PositionArray>& r_b,
               const Eigen::Ref<const QuaternionArray>& q_b, Eigen::Ref<Eigen::VectorXd> value,
               Eigen::Ref<GradientArray> gradient, const BatchOptions& options,
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

  // Threads take blocks of kBlock rows from a shared counter: pair costs vary (a crossing pair
  // of polygons stops early, a distant one prunes most edge pairs), and a fixed split into one
  // chunk per thread left one thread idle while the other finished (1.79x on two threads instead
  // of 1.8-1.9x). Each row is written by exactly one thread; nothing else is shared.
  constexpr Eigen::Index kBlock = 512;
  const Eigen::Index blocks = (n + kBlock - 1) / kBlock;
  // Threads beyond the hardware's only take turns, and threads beyond the blocks find no work, so
  // a request above either is capped: threads = 10^6 starts no more threads than threads = 0.
  const Eigen::Index hardware = std::max(1u, std::thread::hardware_concurrency());
  const Eigen::Index requested = options.threads == 0 ? hardware : options.threads;
  const Eigen::Index threads = std::max<Eigen::Index>(1, std::min({requested, hardware, blocks}));
  std::atomic<Eigen::Index> next_block{0};
  std::exception_ptr first_error;
  std::atomic<Eigen::Index> first_error_row{n};
  std::mutex error_mutex;
  // Every exception of a row is caught here and carried to the caller: one escaping a thread's
  // function would end the process with std::terminate.
  const auto work = [&]() noexcept {
    for (Eigen::Index block = next_block++; block < blocks; block = next_block++) {
      const Eigen::Index begin = block * kBlock;
      const Eigen::Index end = std::min(n, begin + kBlock);
      if (begin > first_error_row) return;  // a lower row already failed; the rest is moot
      for (Eigen::Index i = begin; i < end; ++i) {
        try {
          const auto single = query(pose_at(r_a, q_a, i, "a"), pose_at(r_b, q_b, i, "b"));
          value(i) = single.first;
          gradient.row(i) = single.second.transpose();
        } catch (...) {
          // Every block below a failing row is still processed, so the lowest row recorded is
          // the first bad row whatever the thread timing.
          const std::lock_guard<std::mutex> lock(error_mutex);
          if (i < first_error_row) {
            first_error_row = i;
            first_error = with_row(std::current_exception(), i);
          }
          break;
        }
      }
    }
  };
  // The calling thread works beside threads - 1 helpers. A helper the system refuses (no thread
  // or no memory for its stack left) is not an error: the rows do not depend on which thread
  // computes them, so the batch goes on with the helpers that did start, or with the caller
  // alone. work() throws nothing, so every started helper is joined before this returns.
  std::vector<std::thread> helpers;
  helpers.reserve(static_cast<std::size_t>(threads - 1));
  for (Eigen::Index t = 1; t < threads; ++t) {
    try {
      helpers.emplace_back(work);
    } catch (const std::system_error&) {
      break;
    } catch (const std::bad_alloc&) {
      break;
    }
  }
  work();
  for (std::thread& helper : helpers) helper.join();
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace

void proximity_batch(const Shape& a, const Eigen::Ref<const PositionArray>& r_a,
                     const Eigen::Ref<const QuaternionArray>& q_a, const Shape& b,
                     const Eigen::Ref<const PositionArray>& r_b,
                     const Eigen::Ref<const QuaternionArray>& q_b, Eigen::Ref<Eigen::VectorXd> phi,
                     Eigen::Ref<GradientArray> gradient, const BatchOptions& options) {
  const ProximityOptions single{options.method};
  run_batch("proximity_batch", "phi", r_a, q_a, r_b, q_b, phi, gradient, options,
            [&](const Pose& pose_a, const Pose& pose_b) {
              const Proximity result = proximity(a, pose_a, b, pose_b, single);
              return std::make_pair(result.phi, result.gradient);
            });
}

void signed_distance_batch(const Shape& a, const Eigen::Ref<const PositionArray>& r_a,
                           const Eigen::Ref<const QuaternionArray>& q_a, const Shape& b,
                           const Eigen::Ref<const PositionArray>& r_b,
                           const Eigen::Ref<const QuaternionArray>& q_b,
                           Eigen::Ref<Eigen::VectorXd> distance, Eigen::Ref<GradientArray> gradient,
                           const BatchOptions& options) {
  run_batch("signed_distance_batch", "distance", r_a, q_a, r_b, q_b, distance, gradient, options,
            [&](const Pose& pose_a, const Pose& pose_b) {
              const SignedDistance result = signed_distance(a, pose_a, b, pose_b);
              return std::make_pair(result.distance, result.gradient);
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
