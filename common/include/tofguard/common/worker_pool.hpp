#pragma once
// A fixed set of worker threads that share the tasks of one call with the
// calling thread (compute_discrepancy's naming search: one task per joint;
// docs/benchmarks.md, "The hot paths"). The threads are started once, in
// the constructor, and wait on a condition variable between calls: no
// thread is made per frame.
//
// Contract: run(n, task) calls task(i) exactly once for each i in [0, n)
// and returns when every call has returned. Which thread runs which task,
// and in which order, is not fixed: a task must write only its own results
// (slot i), so that what the call computes never depends on the threads.
// An exception from a task is rethrown by run (the first one), after every
// task has finished. One caller at a time (run is not reentrant).
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace tofguard {

class WorkerPool {
 public:
  // num_threads: the threads a call runs on, the caller's included (>= 1;
  // 1 = every task on the caller's thread, no worker started).
  explicit WorkerPool(int num_threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int num_threads() const { return static_cast<int>(workers_.size()) + 1; }

  template <typename Task>
  void run(int num_tasks, const Task& task) {
    run_erased(
        num_tasks, [](const void* t, int i) { (*static_cast<const Task*>(t))(i); }, &task);
  }

 private:
  using Call = void (*)(const void* task, int index);
  void run_erased(int num_tasks, Call call, const void* task);
  void work();
  void worker_loop();

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_;
  std::condition_variable done_;
  // The call in progress: written under mutex_ while no worker is active,
  // read by a worker only after it joined the open call under mutex_.
  Call call_ = nullptr;
  const void* task_ = nullptr;
  int num_tasks_ = 0;
  std::atomic<int> next_task_{0};
  bool open_ = false;       // workers may join the call
  int active_workers_ = 0;  // workers that joined and have not finished
  uint64_t generation_ = 0;
  bool stopping_ = false;
  std::exception_ptr error_;
};

// Work of a caller's that needs nothing from a later WorkerPool call and
// may share its threads as one more task (compute_discrepancy's pixel
// stages beside the naming search's trials), else runs where its owner
// calls run_once() after the call: either way exactly once. Not thread-safe
// by itself: run_once() is called by one task of one run, or by the owner
// after that run has returned (run's return orders the two).
class SideTask {
 public:
  explicit SideTask(std::function<void()> work) : work_(std::move(work)) {}
  void run_once() {
    if (done_) return;
    done_ = true;
    work_();
  }
  bool done() const { return done_; }

 private:
  std::function<void()> work_;
  bool done_ = false;
};

}  // namespace tofguard
