#include "worker_pool.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <new>
#include <system_error>

namespace diffpills::detail {

// The pool belongs to the process that made it: getpid() tells a forked child, whose copy of the
// pool lists workers that were not copied (fork copies only the calling thread) and whose mutexes
// may have been copied locked. The child leaves that copy alone for good and makes its own. No lock
// guards the swap (a lock held by another thread at the fork would stay locked in the child): a
// compare-and-swap installs the new pool, and the one it replaces stays reachable through
// `replaced` so that leak checkers stay quiet.
namespace {
struct OwnedPool {
  WorkerPool* pool;
  pid_t owner;
  const OwnedPool* replaced;
};
}  // namespace

WorkerPool& WorkerPool::instance() {
  static std::atomic<const OwnedPool*> current{nullptr};
  const pid_t self = getpid();
  const OwnedPool* seen = current.load(std::memory_order_acquire);
  while (seen == nullptr || seen->owner != self) {
    const auto* fresh = new OwnedPool{new WorkerPool, self, seen};
    if (current.compare_exchange_strong(seen, fresh, std::memory_order_acq_rel))
      return *fresh->pool;
    delete fresh->pool;  // another thread installed one first: use that
    delete fresh;
  }
  return *seen->pool;
}

void WorkerPool::start_workers(int count) {
  // Called with busy_ held, so no other thread grows workers_ at the same time; state_ is not
  // needed for workers_, which only the job's calling thread reads.
  while (static_cast<int>(workers_.size()) < count) {
    try {
      // The worker counts the job being set up as unseen, whenever its thread gets going.
      workers_.emplace_back(
          [this, seen = generation_.load(std::memory_order_relaxed)] { work_loop(seen); });
    } catch (const std::system_error&) {  // no thread (or no stack) left: fewer helpers
      return;
    } catch (const std::bad_alloc&) {
      return;
    }
  }
}

namespace {
// A spin-wait hint: lets the core run its sibling hyperthread and saves power while spinning.
void pause_while_spinning() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#else
  std::this_thread::yield();
#endif
}

// Waiting by spinning, for at most 0.2 ms, before a thread sleeps on a condition variable. Waking
// a sleeping thread costs a system call and, on a virtual machine, the wake-up of an idle virtual
// CPU: measured here 16-30 us when the other CPU was recently busy and up to 2.7 ms when it had
// halted, against 60-650 us of work per thread for 10^4 capsule pairs on two threads (vector
// kernel or scalar path). Returns whether `done` became true.
template <class Done>
bool spin_until(const Done& done) {
  constexpr auto kSpin = std::chrono::microseconds(200);
  const auto spin_end = std::chrono::steady_clock::now() + kSpin;
  for (int round = 1; !done(); ++round) {
    if (round % 16 == 0 && std::chrono::steady_clock::now() > spin_end) return false;
    pause_while_spinning();
  }
  return true;
}
}  // namespace

void WorkerPool::run(Job& job, int helpers) {
  std::unique_lock<std::mutex> busy(busy_, std::try_to_lock);
  if (!busy.owns_lock() || helpers <= 0) {
    job.run(0);
    return;
  }
  start_workers(helpers);
  const int available = std::min(helpers, static_cast<int>(workers_.size()));
  {
    const std::lock_guard<std::mutex> lock(state_);
    job_ = &job;
    wanted_ = available;
    joined_slots_ = 0;
    generation_.fetch_add(1, std::memory_order_release);
  }
  wake_.notify_all();
  job.run(0);
  {
    const std::lock_guard<std::mutex> lock(state_);
    wanted_ = 0;  // late wakers stay out: the work is done or in the hands of those inside
  }
  // The helpers inside are finishing their last block: wait for them awake, as they do for jobs.
  const auto helpers_done = [this] { return joined_.load(std::memory_order_acquire) == 0; };
  if (!spin_until(helpers_done)) {
    std::unique_lock<std::mutex> lock(state_);
    done_.wait(lock, helpers_done);
  }
  const std::lock_guard<std::mutex> lock(state_);
  job_ = nullptr;
}

// Between jobs a worker first spins (spin_until), watching generation_, so that a loop calling
// the batch again within 0.2 ms finds its helpers awake; then it sleeps on the condition variable.
// The price is a worker busy for 0.2 ms after each batch (OpenMP runtimes spin likewise: libgomp
// 300,000 rounds by default).
void WorkerPool::work_loop(std::uint64_t seen) {
  for (;;) {
    spin_until([&] { return generation_.load(std::memory_order_acquire) != seen; });
    std::unique_lock<std::mutex> lock(state_);
    wake_.wait(lock, [&] { return generation_.load(std::memory_order_relaxed) != seen; });
    seen = generation_.load(std::memory_order_relaxed);
    if (wanted_ == 0) continue;  // the job has its helpers, or its caller has finished
    --wanted_;
    ++joined_;
    const int slot = ++joined_slots_;
    Job* job = job_;
    lock.unlock();
    job->run(slot);
    lock.lock();
    if (--joined_ == 0) done_.notify_one();
  }
}

}  // namespace diffpills::detail
