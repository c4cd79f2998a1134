// The batches' threads: started once per process and reused by every batch call (issue 13),
// instead of new threads per call, and kept awake by spinning between jobs and at a job's end
// (worker_pool.cpp): on this virtual machine the wake-up of a sleeping thread, not its creation,
// held 10^4 capsule pairs at 1.7x on two threads (1.9x with the spinning; BENCHMARKS.md).
//
// Why not OpenMP or oneTBB, the runtimes issue 13 proposed: both are measured beside this pool in
// bench_proximity (Batch_CapsuleCapsule_OpenMP, _Tbb; BENCHMARKS.md) and scale the same on this
// machine (1.96-1.98x on two threads at 10^4 capsule pairs by the scalar path). But libgomp ends
// the process when the system refuses a thread ("Thread creation failed", exit status 1) and hangs
// in the first parallel region of a forked child (Python's multiprocessing, data-loader workers),
// both measured with g++ 12; oneTBB copes with both but would be one more runtime library for every
// program that links diffpills. This pool treats a refused thread as one helper fewer, and a
// forked child starts workers of its own.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

namespace diffpills::detail {

// A job is a function every participating thread calls once; it must not throw (each thread's
// exceptions are the job's to catch and carry). The work inside is shared by the job itself
// (e.g. blocks of rows taken from atomic counters), so a job done by fewer threads than asked is
// still done completely. `slot` tells the participants apart: 0 for the calling thread, 1, 2, ...
// for the workers in the order they join. A job may give each slot a share of its own to start
// with (batch.cpp), which a loop calling it again finds in the same thread's caches.
class Job {
 public:
  virtual void run(int slot) noexcept = 0;

 protected:
  ~Job() = default;
};

class WorkerPool {
 public:
  // The pool of this process (a forked child gets a new one; the parent's workers do not exist
  // there). Never destroyed: its workers wait until the process ends, so no destructor can race
  // a batch running while statics are torn down.
  static WorkerPool& instance();

  // Calls job.run(0) on the calling thread and job.run(1), job.run(2), ... on up to helpers
  // workers at once, and returns when every call has returned. Workers are started on first need,
  // up to helpers; a worker the system refuses is one helper fewer (tried again by a later call). A
  // worker that wakes only after the calling thread has finished its own run() is not given the
  // job: the shared work is then done, and waiting for it would only add its wake-up time. The pool
  // serves one job at a time: a job submitted while another runs (a batch from a second thread)
  // runs on its calling thread alone.
  void run(Job& job, int helpers);

  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

 private:
  WorkerPool() = default;
  ~WorkerPool() = default;
  void start_workers(int count);
  void work_loop(std::uint64_t seen);  // seen: the last job it need not take

  std::mutex busy_;  // held by the calling thread of the running job
  std::mutex state_;
  std::condition_variable wake_;  // a new job (generation_ moved)
  std::condition_variable done_;  // a worker left the job (joined_ went down)
  std::vector<std::thread> workers_;
  Job* job_ = nullptr;
  std::atomic<std::uint64_t> generation_{0};  // moved under state_, read while spinning
  int wanted_ = 0;                            // workers the current job may still take
  int joined_slots_ = 0;                      // workers the current job has taken so far
  std::atomic<int> joined_{0};                // workers inside the job's run(); moved under state_
};

}  // namespace diffpills::detail
