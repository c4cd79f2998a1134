// Many queries of one shape pair at once: the poses come as arrays, the work is split across
// threads, and every entry equals the single call proximity(a, pose_a[i], b, pose_b[i]) (or
// signed_distance(...) for signed_distance_batch). Bit for bit, except for two capsules (by the
// default method): their rows go through a vector kernel, several pairs per instruction (Google
// Highway, AVX-512 / AVX2 / SSE4 / plain code chosen at run time; 12-31 ns per pair and thread,
// with the machine and the batch's size, against 50-58 ns for the single call and 130-190 ns for
// its signed distance), which agrees with the single call to rounding: phi within 1e-12 S^2, the
// signed distance within 1e-12 S, gradients within the same per length and per unit of q, S the
// scene's size (the largest of the lengths, the radii's sum and the distance between the
// capsules' middles). Rows it does not cover (axes within ~5.7 degrees of parallel, cores within
// 1e-9 S of touching, 1e-2 S for the signed distance, extreme magnitudes, invalid poses) are the
// single call's.
#pragma once

#include <Eigen/Core>

#include "diffpills/proximity.hpp"
#include "diffpills/shapes.hpp"

namespace diffpills {

struct BatchOptions {
  // Threads working on the batch, the calling thread included; 0 = every hardware thread. Capped
  // at the hardware threads and at what the rows can use (at least 16 rows each), so any count is
  // safe; a negative one throws std::invalid_argument. The helpers are worker threads the process
  // starts on first need and reuses for every batch (no thread is started per call; a worker
  // spins for 0.2 ms after a batch before it sleeps, so that a loop of batches finds it awake).
  // One batch uses them at a time: a batch called while another runs, from another thread,
  // computes on its calling thread alone. A forked child starts workers of its own. If the system
  // cannot start a thread, the batch runs on those that did start (at worst on the calling thread
  // alone) with the same results: running out of threads is never an error.
  int threads = 0;
  Method method = Method::kDefault;
};

// Rows are poses: r is N x 3, q is N x 4 ([w x y z]), both row-major like NumPy's default.
using PositionArray = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using QuaternionArray = Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>;
using GradientArray = Eigen::Matrix<double, Eigen::Dynamic, 14, Eigen::RowMajor>;

struct BatchResult {
  Eigen::VectorXd phi;     // N
  GradientArray gradient;  // N x 14, the layout of Proximity::gradient
};

// phi and the 14-entry gradient for pair i = (a at (r_a[i], q_a[i]), b at (r_b[i], q_b[i])).
// Throws std::invalid_argument if the arrays differ in length or a pose is invalid; the message
// names the first bad row, e.g. "q_b[17]: quaternion must be nonzero ...". An exception of a row
// (that one, or a SolverError) is thrown to the caller after every thread has finished, whichever
// thread met it. The per-pair work allocates nothing for polygons of up to 32 vertices.
BatchResult proximity_batch(const Shape& a, const Eigen::Ref<const PositionArray>& r_a,
                            const Eigen::Ref<const QuaternionArray>& q_a, const Shape& b,
                            const Eigen::Ref<const PositionArray>& r_b,
                            const Eigen::Ref<const QuaternionArray>& q_b,
                            const BatchOptions& options = {});

// The same into caller-owned outputs (phi with N entries, gradient N x 14), for loops that call
// the batch repeatedly: no allocation at all, and no first-touch page faults, which are
// serialized in the kernel and cost 2-thread scaling (measured: 1.5x with fresh 12 MB outputs
// per call for 10^5 capsule pairs). Rows past a bad row may be left unwritten.
void proximity_batch(const Shape& a, const Eigen::Ref<const PositionArray>& r_a,
                     const Eigen::Ref<const QuaternionArray>& q_a, const Shape& b,
                     const Eigen::Ref<const PositionArray>& r_b,
                     const Eigen::Ref<const QuaternionArray>& q_b, Eigen::Ref<Eigen::VectorXd> phi,
                     Eigen::Ref<GradientArray> gradient, const BatchOptions& options = {});

struct SignedDistanceBatchResult {
  Eigen::VectorXd distance;  // N
  GradientArray gradient;    // N x 14, the layout of SignedDistance::gradient
};

// The signed distance (signed_distance.hpp) and its gradient for every pose pair, with the
// threads, errors and outputs of proximity_batch (options.method is not used: the signed distance
// has one method).
SignedDistanceBatchResult signed_distance_batch(const Shape& a,
                                                const Eigen::Ref<const PositionArray>& r_a,
                                                const Eigen::Ref<const QuaternionArray>& q_a,
                                                const Shape& b,
                                                const Eigen::Ref<const PositionArray>& r_b,
                                                const Eigen::Ref<const QuaternionArray>& q_b,
                                                const BatchOptions& options = {});
void signed_distance_batch(const Shape& a, const Eigen::Ref<const PositionArray>& r_a,
                           const Eigen::Ref<const QuaternionArray>& q_a, const Shape& b,
                           const Eigen::Ref<const PositionArray>& r_b,
                           const Eigen::Ref<const QuaternionArray>& q_b,
                           Eigen::Ref<Eigen::VectorXd> distance, Eigen::Ref<GradientArray> gradient,
                           const BatchOptions& options = {});

}  // namespace diffpills
