#pragma once
// A fixed set of worker threads that share the tasks of one call with the
// calling thread (compute_discrepancy's naming search: one task per joint;
// docs/benchmarks.md, "The hot paths"). The threads are started once, in
// the constructor, and wait on a condition variable between calls: no
// thread is made per frame.
//
// Waking a sleeping thread is slow on a virtual machine: the other vCPU has
// halted, and the wake-up goes through the hypervisor (at 30 Hz on the
// 2-core VM, compute_discrepancy on 2 threads took 2.4 ms against 1.0 ms
// back to back, about what one thread takes; docs/benchmarks.md). So a
// worker that finishes a call stays awake for `linger` (the calls of one
// frame come in quick succession), and a caller can ask the workers to be
// awake for a call it expects (expect_call_within). Awake, a worker polls
// for the call and yields its core to any other thread that wants it.
//
// A worker keeps off the caller's core (Linux: its CPU affinity, within the
// process's own, excludes the CPU the caller last called from). Woken while
// both vCPUs idle, the scheduler put the worker on the waking caller's CPU
// (it is cache-hot there), where the two took turns on one core while the
// other stayed idle: at 30 Hz on the 2-core VM compute_discrepancy on 2
// threads took 1.63 ms, what 1 thread takes (1.65), against 1.08-1.12 ms
// with the worker on the other core (discrepancy-bench,
// threads:2/pause_ms:33; docs/benchmarks.md, "The worker off the caller's
// core"). With one CPU allowed, nothing changes.
//
// Contract: run(n, task) calls task(i) exactly once for each i in [0, n)
// and returns when every call has returned. Which thread runs which task,
// and in which order, is not fixed: a task must write only its own results
// (slot i), so that what the call computes never depends on the threads.
// An exception from a task is rethrown by run (the first one), after every
// task has finished. One caller at a time (run is not reentrant).
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace tofguard {

// The CPUs the calling thread may run on (Linux: sched_getaffinity, which
// a process inherits from its parent, taskset and systemd's CPUAffinity
// included); 1 when it cannot be read.
int allowed_cpu_count();

class WorkerPool {
 public:
  // How long a worker stays awake after a call by default: the gaps
  // between the calls of one compute_discrepancy are tens of microseconds.
  static constexpr std::chrono::microseconds kDefaultLinger{500};

  // num_threads: the threads a call runs on, the caller's included (>= 1;
  // 1 = every task on the caller's thread, no worker started). linger: how
  // long a worker polls for the next call after one (0: it sleeps at once).
  explicit WorkerPool(int num_threads, std::chrono::microseconds linger = kDefaultLinger);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int num_threads() const { return static_cast<int>(workers_.size()) + 1; }

  // Wakes the workers, if they sleep, to poll for a call for `within` from
  // now (a caller that knows one is coming: a frame's inputs are
  // arriving). A lock and a notification; nothing without workers.
  void expect_call_within(std::chrono::microseconds within);

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
  static int64_t now_ns();
  // Keeps the workers awake until at least now + `for_time`.
  void stay_awake(std::chrono::microseconds for_time);
  // A worker's poll, without the lock, until a call newer than `seen` is
  // open, the pool stops, or it should no longer be awake.
  void poll_for_call(uint64_t seen) const;
  // Records the CPU the calling thread is on (a caller's, before it wakes
  // the workers).
  void note_caller_cpu();
  // A worker's: moves it off the caller's last CPU, if it is not off it
  // already (`excluded`: the CPU it keeps off now, -1 none; updated).
  void keep_off_caller_cpu(int* excluded) const;

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
  bool open_ = false;  // workers may join the call
  // Workers that joined and have not finished: changed under mutex_, read
  // without it by a caller polling for the end of its call.
  std::atomic<int> active_workers_{0};
  uint64_t generation_ = 0;
  bool stopping_ = false;
  std::exception_ptr error_;
  const std::chrono::microseconds linger_;
  // Read without mutex_ by polling threads: the generation of the open
  // call (0: none yet), whether the pool stops, and until when (steady
  // clock, ns) workers stay awake. Written under mutex_.
  std::atomic<uint64_t> open_generation_{0};
  std::atomic<bool> stopping_flag_{false};
  std::atomic<int64_t> awake_until_ns_{0};
  // The CPU the caller last woke the workers from (-1: unknown), and the
  // CPUs the process may run on when the pool was made (the workers keep
  // within them; empty: affinity is not used).
  std::atomic<int> caller_cpu_{-1};
  std::vector<int> allowed_cpus_;
};

// Work of a caller's that needs nothing from a later WorkerPool call and
// may share its threads as one more task (compute_discrepancy's pixel
// stages beside the naming search's trials), else runs where its owner
// calls run_once() after the call: either way exactly once. Not thread-safe
// by itself: run_once() is called by one task of one run, or by the owner
// after that run has returned (run's return orders the two).
// Tasks 0..num_tasks-1 on `workers`, or one after the other on the calling
// thread when there are none (nullptr).
template <typename Task>
void run_tasks(WorkerPool* workers, int num_tasks, const Task& task) {
  if (workers != nullptr) {
    workers->run(num_tasks, task);
  } else {
    for (int i = 0; i < num_tasks; ++i) task(i);
  }
}

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
