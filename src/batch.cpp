#include "diffpills/batch.hpp"

#include <algorithm>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

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

}  // namespace

BatchResult proximity_batch(const Shape& a, const Eigen::Ref<const PositionArray>& r_a,
                            const Eigen::Ref<const QuaternionArray>& q_a, const Shape& b,
                            const Eigen::Ref<const PositionArray>& r_b,
                            const Eigen::Ref<const QuaternionArray>& q_b,
                            const BatchOptions& options) {
  const Eigen::Index n = r_a.rows();
  if (q_a.rows() != n || r_b.rows() != n || q_b.rows() != n) {
    throw std::invalid_argument(
        "proximity_batch: r_a, q_a, r_b and q_b must have the same number "
        "of rows (got " +
        std::to_string(n) + ", " + std::to_string(q_a.rows()) + ", " + std::to_string(r_b.rows()) +
        ", " + std::to_string(q_b.rows()) + ")");
  }
  if (options.threads < 0) {
    throw std::invalid_argument("threads: must be >= 0 (0 = every hardware thread)");
  }
  BatchResult result;
  result.phi.resize(n);
  result.gradient.resize(n, 14);
  const ProximityOptions single{options.method};

  // Contiguous chunks, one per thread: no shared writes, no per-pair scheduling.
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  const auto threads = static_cast<Eigen::Index>(std::min<Eigen::Index>(
      std::max<Eigen::Index>(n, 1), options.threads == 0 ? hardware : options.threads));
  std::exception_ptr first_error;
  Eigen::Index first_error_row = n;
  std::mutex error_mutex;
  const auto work = [&](Eigen::Index begin, Eigen::Index end) {
    for (Eigen::Index i = begin; i < end; ++i) {
      try {
        const Proximity single_result =
            proximity(a, pose_at(r_a, q_a, i, "a"), b, pose_at(r_b, q_b, i, "b"), single);
        result.phi(i) = single_result.phi;
        result.gradient.row(i) = single_result.gradient.transpose();
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (i < first_error_row) {  // report the lowest bad row, whatever the thread timing
          first_error_row = i;
          first_error = std::current_exception();
        }
        return;
      }
    }
  };
  if (threads <= 1) {
    work(0, n);
  } else {
    std::vector<std::thread> pool;
    pool.reserve(static_cast<std::size_t>(threads));
    for (Eigen::Index t = 0; t < threads; ++t) {
      pool.emplace_back(work, n * t / threads, n * (t + 1) / threads);
    }
    for (std::thread& thread : pool) thread.join();
  }
  if (first_error) std::rethrow_exception(first_error);
  return result;
}

}  // namespace diffpills
